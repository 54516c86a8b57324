"""A batch on a Dask distributed cluster: the same tasks, bytes in and bytes out, checked before the first.

:class:`DaskRunner` reaches the scheduler (its address parsed and its port
tried first), waits for a worker, checks that every worker and the scheduler
have this ``patterns``, then sends each file as bytes and writes nothing on a
worker.
"""

from __future__ import annotations

import contextlib
import time

from ..errors import InputError
from ..text import printable
from .plan import BatchOptions, largest_first
from .worker import process_part

__all__ = ["DaskRunner"]


class DaskRunner:
    """The same tasks (bytes in, bytes out) on a Dask distributed cluster, checked before the first task.

    Before any work: the address parsed (``tcp://host:port``, or ``host:port``), the port reached
    (3 s; a port that answers HTTP is the dashboard's, and is named so), the client connected, at
    least one worker waited for, and ``patterns`` -- its version -- found on every worker and on the
    scheduler (workers without it, or with another version, are named).  Then every file goes as
    bytes (scattered when large), results come back as bytes and are released as they arrive.  A
    file still running after ``timeout`` is reported and its future cancelled (Dask cannot stop a
    task that runs: its worker goes on until it ends); one whose worker died is retried once by
    the client, then reported lost.
    """

    CONNECT = 3.0
    """Seconds to reach the scheduler's port, and to connect."""

    def __init__(self, opts: BatchOptions):
        self.opts = opts
        self.where = f"Dask scheduler {opts.scheduler}"
        self.client = None

    def connect(self) -> None:
        try:
            from distributed import Client
        except ImportError:
            raise InputError("--scheduler needs Dask: pip install 'patterns[dask]'") from None
        address = _scheduler_address(self.opts.scheduler, self.CONNECT)
        try:
            self.client = Client(address, timeout=f"{self.CONNECT}s")
        except (OSError, TimeoutError, ValueError) as exc:
            raise InputError(f"{self.opts.scheduler}: cannot reach the Dask scheduler ({exc})") from None
        try:
            self.client.wait_for_workers(1, timeout=self.opts.wait)
        except (TimeoutError, OSError):
            self.close()
            raise InputError(f"{self.opts.scheduler}: no Dask worker joined the scheduler within "
                             f"{self.opts.wait:g} s (start one: dask worker {address})") from None
        self._check_versions()
        # The heavy imports now, on every worker, not inside the first file's time (a builtin, as above).
        self.client.run(eval, "[__import__(m) for m in ('build123d', 'ezdxf', 'matplotlib.figure', 'trimesh', "
                              "'patterns.jobs')] and None", on_error="return")

    def _check_versions(self) -> None:
        # A builtin, so that it unpickles anywhere: the version of the patterns that imports there --
        # and here, the same probe (the package is loaded already).
        probe = (eval, "__import__('patterns').__version__")
        mine = probe[0](probe[1])
        found = self.client.run(*probe, on_error="return")
        lacking = sorted(w for w, v in found.items() if isinstance(v, ImportError))
        other = sorted(f"{w} ({v})" for w, v in found.items() if not isinstance(v, BaseException) and v != mine)
        broken = sorted(w for w, v in found.items() if isinstance(v, BaseException) and w not in lacking)
        try:  # the scheduler unpickles the tasks: it needs patterns too
            on_scheduler = self.client.run_on_scheduler(*probe)
        except ImportError:
            on_scheduler = None
        except Exception:  # noqa: BLE001 - a scheduler that refuses to run code: its workers decide
            on_scheduler = mine
        problems = []
        if lacking or broken:
            problems.append(f"workers without patterns: {', '.join(lacking + broken)} (pip install patterns there)")
        if other:
            problems.append(f"workers with another patterns than this machine's {mine}: {', '.join(other)}")
        if on_scheduler is None:
            problems.append("the scheduler has no patterns (pip install patterns there too)")
        elif on_scheduler != mine:
            problems.append(f"the scheduler has patterns {on_scheduler}, this machine {mine}")
        if problems:
            self.close()
            raise InputError(f"{self.opts.scheduler}: " + "; ".join(problems))

    def run(self, files, bundle, wanted, on_start):
        from distributed import wait

        pending = {}  # future -> (index, tries)
        seen_running = {}  # future key -> when first seen executing

        def submit(index, tries):
            path = files[index]
            data = path.read_bytes()
            payload = self.client.scatter(data, hash=False) if len(data) > 1 << 20 else data
            future = self.client.submit(process_part, path.name, payload, bundle, wanted, pure=False)
            pending[future] = (index, tries)
            if on_start is not None and tries == 1:
                on_start(printable(path.name))

        def lost(index, why):
            return index, {"file": files[index].name, "status": "lost", "reason": why}

        order = largest_first(files)  # Dask runs tasks in the order they were submitted
        for k, index in enumerate(order):
            try:
                submit(index, 1)
            except Exception as exc:  # noqa: BLE001 - the cluster went while the files were being sent
                for other in order[k:]:
                    yield lost(other, f"not sent: the cluster went away ({_said(exc)})")
                break
        alone = _Vigil(self.client, self.opts.wait)
        while pending:
            with contextlib.suppress(Exception):  # none finished in that second, or one was lost: see below
                wait(list(pending), timeout=1.0, return_when="FIRST_COMPLETED")
            done = [f for f in pending if f.done()]
            for future in done:
                index, tries = pending.pop(future)
                try:
                    row = future.result()
                except Exception as exc:  # noqa: BLE001 - KilledWorker, a lost connection, ...
                    if tries < 2:
                        try:
                            submit(index, tries + 1)  # its worker died: once more
                        except Exception as again:  # noqa: BLE001 - no worker left, no scheduler
                            yield lost(index, f"its worker died and it could not be sent again ({_said(again)})")
                        with contextlib.suppress(Exception):
                            future.release()
                        continue
                    row = {"file": files[index].name, "status": "lost",
                           "reason": f"its worker died twice ({type(exc).__name__}: killed -- out of memory, or a "
                                     f"crash)"}
                with contextlib.suppress(Exception):
                    future.release()
                yield index, row
            gone = alone.gone() if pending else None
            if gone:  # no worker, or no scheduler, for --wait seconds: what is left will not run
                for future in list(pending):
                    index, _ = pending.pop(future)
                    with contextlib.suppress(Exception):
                        future.cancel()
                    yield lost(index, gone)
                return
            # executing now -- not merely sent to a worker, where it may wait behind another task
            running = {key for keys in self._executing(pending).values() for key in keys}
            now = time.monotonic()
            for future in list(pending):
                if future.key in running:
                    started = seen_running.setdefault(future.key, now)
                    if now - started > self.opts.timeout:
                        index, _ = pending.pop(future)
                        future.cancel()
                        yield index, {"file": files[index].name, "status": "timeout",
                                      "reason": f"still running after {self.opts.timeout:g} s: given up (Dask "
                                                f"cannot stop a running task; its worker ends it)",
                                      "seconds": now - started}

    def _executing(self, pending) -> dict:
        if not pending:
            return {}
        with contextlib.suppress(Exception):  # a worker that left meanwhile: none seen this second
            return self.client.call_stack(keys=[f.key for f in pending])
        return {}

    def close(self) -> None:
        if self.client is not None:
            with contextlib.suppress(Exception):
                self.client.close()
            self.client = None


def _said(exc: BaseException) -> str:
    """An exception in a row: its kind and first line."""
    text = str(exc).strip().splitlines()
    return f"{type(exc).__name__}: {text[0]}" if text else type(exc).__name__


class _Vigil:
    """Whether the cluster is still there: the scheduler connected and at least one worker, checked each time
    it is asked; gone when either has been missing for ``wait`` seconds."""

    def __init__(self, client, wait: float):
        self.client, self.wait = client, wait
        self.since = None

    def gone(self) -> str | None:
        try:
            connected = self.client.status == "running"
            workers = len(self.client.scheduler_info().get("workers", {})) if connected else 0
        except Exception:  # noqa: BLE001 - a client that lost its scheduler raises anything
            connected, workers = False, 0
        if connected and workers:
            self.since = None
            return None
        now = time.monotonic()
        self.since = self.since or now
        if now - self.since < self.wait:
            return None
        what = "no worker" if connected else "no scheduler"
        return f"not run: {what} for {self.wait:g} s (the cluster went away)"


def _scheduler_address(text: str, timeout: float) -> str:
    """``tcp://host:port``, checked: parsed, the port reached, and not the dashboard's (InputError otherwise)."""
    import socket

    raw = text.strip()
    scheme, sep, rest = raw.partition("://")
    if not sep:
        scheme, rest = "tcp", raw
    if scheme in ("http", "https"):
        raise InputError(f"{text}: a web address: the Dask dashboard's? give the scheduler's, tcp://HOST:8786")
    if scheme != "tcp":
        raise InputError(f"{text}: the scheduler's address is tcp://HOST:PORT, not {scheme}://")
    host, sep, port = rest.rstrip("/").rpartition(":")
    if not sep or not host or not port.isdigit() or not 0 < int(port) < 65536:
        raise InputError(f"{text}: expected tcp://HOST:PORT (the scheduler's port, usually 8786)")
    host = host.strip("[]")
    try:
        sock = socket.create_connection((host, int(port)), timeout=timeout)
    except socket.gaierror:
        raise InputError(f"{text}: unknown host {host!r}") from None
    except TimeoutError:
        raise InputError(f"{text}: cannot reach the Dask scheduler (no answer in {timeout:g} s)") from None
    except OSError as exc:
        raise InputError(f"{text}: cannot reach the Dask scheduler ({exc.strerror or exc})") from None
    try:
        said = _first_words(sock, timeout)
    finally:
        sock.close()
    if b"compression" not in said:  # a Dask scheduler opens with its handshake (msgpack, naming "compression")
        if said.startswith(b"HTTP"):
            raise InputError(f"{text}: that port answers HTTP: it is the Dask dashboard, not the scheduler (give "
                             f"the scheduler's port, usually 8786)")
        if not said:
            raise InputError(f"{text}: that port accepts connections but says nothing in {timeout:g} s: not a Dask "
                             f"scheduler (a scheduler greets at once)")
        raise InputError(f"{text}: that port is not a Dask scheduler (it said {said[:20]!r})")
    return f"tcp://{host}:{port}" if ":" not in host else f"tcp://[{host}]:{port}"


def _first_words(sock, timeout: float) -> bytes:
    """What a server says first: a Dask scheduler its handshake, at once; else (a web server, the dashboard,
    waits to be asked) its answer to an HTTP request; ``b""`` when it says nothing within ``timeout``."""
    try:
        sock.settimeout(timeout)
        said = sock.recv(256)
        if said:
            return said
    except TimeoutError:
        pass
    except OSError:
        return b""
    try:
        sock.settimeout(1.0)
        sock.sendall(b"GET / HTTP/1.0\r\n\r\n")
        return sock.recv(256)
    except OSError:
        return b""
