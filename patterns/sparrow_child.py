"""Sparrow in a process of its own: :mod:`patterns.nesting` runs this file as a script.

It reads one strip-packing task as JSON on stdin (``items``: outlines,
``strip``: the strip's height, ``orientations``, ``gap``, ``time`` seconds,
``seed``) and writes one JSON object on stdout: ``{"placed": [[rotation deg,
tx, ty], ...]}`` in the items' order, or ``{"error": "..."}`` when sparrow
gives up or panics.  It imports nothing of ``patterns`` (it starts in a
fraction of a second), and it dies with the process that started it.

Why a process: sparrow's search holds its thread until its time is spent
(Ctrl-C and SIGTERM would wait for it, or be taken by it), its set-up is not
bounded by its time, and a panic prints Rust's backtrace on stderr.  Here the
parent waits with a deadline, kills it on a signal or past the deadline, and
keeps its stderr from the user.
"""

import json
import signal
import sys


def _die_with_parent() -> None:
    try:
        import ctypes

        ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG: Linux
    except (OSError, AttributeError):
        pass


def main() -> int:
    _die_with_parent()
    task = json.load(sys.stdin)
    import spyrrow

    items = [spyrrow.Item(str(k), [tuple(p) for p in pts], demand=1, allowed_orientations=task["orientations"])
             for k, pts in enumerate(task["items"])]
    instance = spyrrow.StripPackingInstance("patterns", strip_height=task["strip"], items=items)
    config = spyrrow.StripPackingConfig(early_termination=True, total_computation_time=task["time"],
                                        min_items_separation=task["gap"] if task["gap"] > 0 else None,
                                        seed=task["seed"], num_workers=1)
    try:
        solution = instance.solve(config)
    except BaseException as exc:  # noqa: BLE001 -- a panic reaches Python as pyo3's PanicException, a BaseException
        message = " ".join(str(exc).split()) or type(exc).__name__
        json.dump({"error": message}, sys.stdout)
        return 3
    placed = [None] * len(items)
    for item in solution.placed_items:
        placed[int(item.id)] = [float(item.rotation), *map(float, item.translation)]
    json.dump({"placed": placed}, sys.stdout)
    return 0


if __name__ == "__main__":
    sys.exit(main())
