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

    def run(self, files, records, wanted, on_start):
        from distributed import wait

        pending = {}  # future -> (index, tries)
        seen_running = {}  # future key -> when first seen executing

        def submit(index, tries):
            path = files[index]
            data = path.read_bytes()
            payload = self.client.scatter(data, hash=False) if len(data) > 1 << 20 else data
            future = self.client.submit(process_part, path.name, payload, records, wanted, pure=False)
            pending[future] = (index, tries)
            if on_start is not None and tries == 1:
                on_start(printable(path.name))

        for index in largest_first(files):  # Dask runs tasks in the order they were submitted
            submit(index, 1)
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
                        submit(index, tries + 1)  # its worker died: once more
                        future.release()
                        continue
                    row = {"file": files[index].name, "status": "lost",
                           "reason": f"its worker died twice ({type(exc).__name__}: killed -- out of memory, or a "
                                     f"crash)"}
                future.release()
                yield index, row
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
    try:  # a scheduler says nothing to this; a web server (the dashboard, on 8787) answers HTTP
        sock.settimeout(1.0)
        sock.sendall(b"GET / HTTP/1.0\r\n\r\n")
        answer = sock.recv(5)
    except OSError:
        answer = b""
    finally:
        sock.close()
    if answer.startswith(b"HTTP"):
        raise InputError(f"{text}: that port answers HTTP: it is the Dask dashboard, not the scheduler (give the "
                         f"scheduler's port, usually 8786)")
    return f"tcp://{host}:{port}" if ":" not in host else f"tcp://[{host}]:{port}"
