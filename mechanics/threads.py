"""One BLAS thread while simulating: the default of every public entry point that simulates.

The models' linear algebra is small (dense solves of tens to hundreds of DOFs, banded ones of
a few thousand): several BLAS threads only contend for the cores and make it 8-60x slower on
a busy machine. The solvers, analyses, thermal stages and scenario evaluations therefore run
inside :func:`single_thread` (as a decorator: :func:`single_threaded`); parallelism comes from
evaluating designs on several processes (:mod:`holofold.design.database.runner`).

The limit is re-entrant and cheap: the outermost entry reads and sets the thread count of each
BLAS/OpenMP library once (about 10 us, nothing when it already is 1; measured in
benchmarks/bench_floor.py), nested entries only count. Set ``HOLOFOLD_BLAS_THREADS=keep`` to
leave the libraries' thread counts alone.
"""

from __future__ import annotations

import functools
import os
import threading

__all__ = ["single_thread", "single_threaded"]

_LOCK = threading.Lock()
_DEPTH = 0
_RESTORE: list = []
_LIBS = None


def _libraries():
    global _LIBS
    if _LIBS is None:
        from threadpoolctl import ThreadpoolController

        # every BLAS/OpenMP library loaded by now (numpy's and scipy's OpenBLAS: the
        # mechanics modules import both before anything simulates)
        _LIBS = ThreadpoolController().lib_controllers
    return _LIBS


class _SingleThread:
    """Re-entrant context: BLAS limited to one thread until the outermost exit."""

    __slots__ = ()

    def __enter__(self):
        global _DEPTH
        with _LOCK:
            if _DEPTH == 0 and os.environ.get("HOLOFOLD_BLAS_THREADS") != "keep":
                for lib in _libraries():
                    n = lib.get_num_threads()
                    if n is not None and n != 1:
                        lib.set_num_threads(1)
                        _RESTORE.append((lib, n))
            _DEPTH += 1
        return self

    def __exit__(self, *exc):
        global _DEPTH
        with _LOCK:
            _DEPTH -= 1
            if _DEPTH == 0:
                while _RESTORE:
                    lib, n = _RESTORE.pop()
                    lib.set_num_threads(n)
        return False


_CONTEXT = _SingleThread()


def single_thread() -> _SingleThread:
    """Context manager limiting BLAS/OpenMP to one thread (re-entrant, cheap when nested)."""
    return _CONTEXT


def single_threaded(fn):
    """Decorator: run ``fn`` inside :func:`single_thread`."""

    @functools.wraps(fn)
    def wrapper(*args, **kwargs):
        with _CONTEXT:
            return fn(*args, **kwargs)

    return wrapper
