"""The two kernel paths of the assembly, and which one runs.

``numpy`` (:mod:`~holofold.mechanics._numpy_kernels`) is the reference: numpy and scipy only,
always available. ``compiled`` (:mod:`~holofold.mechanics._compiled`, numba) is an accelerator
over it: the same functions, signatures and layouts, agreeing to round-off (forces, tangents and
energies to 1e-12 relative to their scale; tests/test_kernel_paths.py). Which one runs is set by
the environment variable ``HOLOFOLD_KERNELS``:

``auto`` (default)
    compiled where its machine code is ready in the kernel cache; otherwise numpy, while one
    background process (``python -m holofold.mechanics.kernel_compile``, niced) compiles the
    kernels into the cache, and every process switches to them once they are ready. So a fresh
    environment's first result is not held up by compilation (about 30 s of numba work), and a
    machine without numba, or where it fails to compile, runs on numpy (one warning says why).
``compiled``
    compile in this process if needed (blocking); a missing or broken numba is an
    :class:`~holofold.geometry.errors.EnvironmentFault`.
``numpy``
    never compile.

A one-shot run of a small model (:func:`small_model`: under :data:`SMALL_MODEL_PANELS` panels,
``holofold simulate`` of one pattern) runs on numpy in ``auto`` unless this process has loaded
the compiled kernels already: numba's import and loading its machine code (0.45-0.6 s CPU) cost
such a run more than the numpy kernels do (issue 37 item 4; benchmarks/speed_targets.md).

The kernel cache is a folder keyed on a hash of the kernels' sources (every file the compiled
code is built from), the numba, llvmlite, numpy and Python versions and the CPU, so an edited
kernel can never run stale machine code (numba alone keys each cached function on its own file
only). It lives under ``HOLOFOLD_KERNEL_CACHE``, else ``NUMBA_CACHE_DIR``, else the user's
cache folder (``$XDG_CACHE_HOME`` or ``~/.cache``)/holofold, else the temporary folder.
"""

from __future__ import annotations

import hashlib
import importlib
import os
import platform
import shutil
import subprocess
import sys
import tempfile
import time
import warnings
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from functools import cache
from pathlib import Path
from types import ModuleType

from holofold.geometry.errors import EnvironmentFault

__all__ = [
    "EnvironmentFault",
    "KERNEL_PATHS",
    "KernelPath",
    "KernelWarning",
    "active",
    "requested",
    "kernel_path",
    "cache_folder",
    "check_environment",
    "small_model",
    "SMALL_MODEL_PANELS",
]

#: the kernel paths, reference first
KERNEL_PATHS = ("numpy", "compiled")
ENV = "HOLOFOLD_KERNELS"
#: the modules the compiled kernels are built from (their sources key the cache)
COMPILED_SOURCES = ("_jit.py", "_compiled.py", "_spring_loop.py", "supernodal.py")
#: below this many panels a one-shot run in ``auto`` mode skips numba (:func:`small_model`):
#: whole ``holofold simulate --no-contact`` processes, numpy vs compiled kernels, CPU s: 24
#: panels 1.57 vs 2.19, 156 panels 6.05 vs 5.80, 330 panels 5.59 vs 2.69 (load 8-10)
SMALL_MODEL_PANELS = 100
#: how often (s) a process on the numpy path looks whether the compiled kernels are ready
POLL_SECONDS = 2.0


class KernelWarning(RuntimeWarning):
    """The compiled kernels cannot be used here; the numpy path runs instead."""


@dataclass(frozen=True)
class KernelPath:
    """A kernel path: its name and the module of its functions (``bar_elements``,
    ``spring_elements``, ``scatter``, ``assemble_batch``, ``band_newton_step``,
    ``small_newton_step``, ``lapack_addresses``)."""

    name: str
    module: ModuleType

    @property
    def compiled(self) -> bool:
        return self.name == "compiled"


def requested() -> str:
    """The path asked for by ``HOLOFOLD_KERNELS``: ``auto``, ``numpy`` or ``compiled``."""
    value = os.environ.get(ENV, "auto").strip().lower() or "auto"
    if value not in ("auto", *KERNEL_PATHS):
        raise EnvironmentFault(
            f"{ENV}={os.environ.get(ENV)!r} is not a kernel path; use auto, numpy or compiled"
        )
    return value


# ------------------------------------------------------------------------------ cache folder
def _base_folder() -> Path:
    for var in ("HOLOFOLD_KERNEL_CACHE", "NUMBA_CACHE_DIR"):
        if os.environ.get(var):
            return Path(os.environ[var]).expanduser()
    xdg = os.environ.get("XDG_CACHE_HOME")
    return (Path(xdg) if xdg else Path.home() / ".cache") / "holofold"


@cache
def _fingerprint() -> str:
    """Hash of the compiled kernels' sources, the compiler stack's versions and the CPU."""
    import llvmlite
    import llvmlite.binding as llvm
    import numba
    import numpy

    h = hashlib.sha256()
    here = Path(__file__).resolve().parent
    for name in COMPILED_SOURCES:
        h.update(name.encode() + b"\0" + (here / name).read_bytes() + b"\0")
    cpu = f"{llvm.get_host_cpu_name()}|{llvm.get_host_cpu_features().flatten()}"
    for part in (numba.__version__, llvmlite.__version__, numpy.__version__, sys.version, cpu):
        h.update(part.encode() + b"\0")
    h.update(platform.machine().encode())
    return h.hexdigest()[:16]


@cache
def cache_folder() -> Path:
    """The folder of the compiled kernels' machine code for these sources, this compiler stack
    and this CPU (created; the first writable of the candidates in the module docstring)."""
    name = f"kernels-{_fingerprint()}"
    tmp = Path(tempfile.gettempdir()) / f"holofold-{os.getuid() if hasattr(os, 'getuid') else 0}"
    for base in (_base_folder(), tmp):
        folder = base / name
        try:
            folder.mkdir(parents=True, exist_ok=True)
            probe = folder / f".probe-{os.getpid()}"
            probe.write_bytes(b"")
            probe.unlink()
            return folder
        except OSError:
            continue
    raise EnvironmentFault(
        f"no writable folder for the compiled kernels ({_base_folder()} nor {tmp}); "
        f"set HOLOFOLD_KERNEL_CACHE to a writable folder or {ENV}=numpy"
    )


def _ready_marker() -> Path:
    return cache_folder() / "ready"


def _failed_marker() -> Path:
    return cache_folder() / "failed"


# ------------------------------------------------------------------------------ the paths
@cache
def _numpy_path() -> KernelPath:
    return KernelPath("numpy", importlib.import_module("holofold.mechanics._numpy_kernels"))


_COMPILED_MODULE: ModuleType | None = None


def _import_compiled() -> ModuleType:
    """``_compiled``, its functions cached in :func:`cache_folder` (numba reads the cache folder
    when a function is decorated, so it is set for the import only)."""
    global _COMPILED_MODULE
    if _COMPILED_MODULE is None:
        from numba.core import config

        folder = str(cache_folder())
        before = config.CACHE_DIR
        config.CACHE_DIR = folder
        try:
            _COMPILED_MODULE = importlib.import_module("holofold.mechanics._compiled")
        finally:
            config.CACHE_DIR = before
    return _COMPILED_MODULE


def _numba_missing() -> str | None:
    """Why numba cannot be imported here, or None."""
    try:
        import numba  # noqa: F401
    except Exception as exc:  # ImportError, or a broken llvmlite shared library (OSError)
        return f"{type(exc).__name__}: {exc}"
    return None


def _require_numba() -> None:
    """:class:`EnvironmentFault` (cause and fix) where numba cannot be imported."""
    why = _numba_missing()
    if why:
        raise EnvironmentFault(
            f"the compiled kernels need numba, which cannot be imported ({why}); "
            f"pip install numba, or set {ENV}=numpy"
        )


def kernel_path(name: str) -> KernelPath:
    """The path ``name`` (``numpy`` or ``compiled``); the compiled one is compiled in this
    process if its cache is cold. Raises :class:`EnvironmentFault` where numba is missing or
    its kernels fail to compile."""
    if name == "numpy":
        return _numpy_path()
    if name != "compiled":
        raise ValueError(f"kernel path must be one of {KERNEL_PATHS}, got {name!r}")
    _require_numba()
    try:
        return KernelPath("compiled", _import_compiled())
    except EnvironmentFault:
        raise
    except Exception as exc:
        raise EnvironmentFault(
            f"the compiled kernels failed to load ({type(exc).__name__}: {exc}); "
            f"set {ENV}=numpy to run on the numpy kernels"
        ) from exc


class _Auto:
    """The state of ``auto``: numpy until the compiled kernels are ready, then compiled."""

    def __init__(self):
        self.path: KernelPath | None = None
        self.next_poll = 0.0
        self.warned = False
        self.settled = False  # numpy for good: numba missing, failed to load or compile

    def resolve(self) -> KernelPath:
        if self.path is not None and self.path.compiled:
            return self.path
        now = time.monotonic()
        if self.path is not None and now < self.next_poll:
            return self.path
        self.next_poll = now + POLL_SECONDS
        self.path = self._choose()
        return self.path

    def _choose(self) -> KernelPath:
        why = _numba_missing()
        if why:
            return self._numpy(f"numba cannot be imported ({why}); pip install numba")
        try:
            ready, failed = _ready_marker(), _failed_marker()
        except EnvironmentFault as exc:
            return self._numpy(str(exc))
        if ready.exists():
            try:
                return KernelPath("compiled", _import_compiled())
            except Exception as exc:
                return self._numpy(f"the compiled kernels failed to load ({exc})")
        if failed.exists():
            reason = failed.read_text(errors="replace").strip().splitlines()[-1:] or ["?"]
            return self._numpy(f"the compiled kernels failed to compile ({reason[0]})")
        _start_background_compile()
        return _numpy_path()

    def _numpy(self, why: str) -> KernelPath:
        self.settled = True
        if not self.warned:
            self.warned = True
            warnings.warn(
                f"holofold runs on its numpy kernels (3-5x slower assembly): {why}",
                KernelWarning,
                stacklevel=4,
            )
        return _numpy_path()


_AUTO = _Auto()


_FIXED: dict[str, KernelPath] = {}

#: inside :func:`small_model` of a small model (``auto`` runs numpy there)
_SMALL = False


@contextmanager
def small_model(panels: int) -> Iterator[bool]:
    """Within: a one-shot run of a model of ``panels`` panels; where they are fewer than
    :data:`SMALL_MODEL_PANELS` and this process has not loaded the compiled kernels, ``auto``
    runs the numpy kernels (no numba import, no background compile started). Yields whether
    it does; ``HOLOFOLD_KERNELS=numpy`` or ``compiled`` are obeyed as always."""
    global _SMALL
    before = _SMALL
    _SMALL = int(panels) < SMALL_MODEL_PANELS and _COMPILED_MODULE is None
    try:
        yield _SMALL
    finally:
        _SMALL = before


def active() -> KernelPath:
    """The kernel path this process runs now (see the module docstring). Cheap: called once
    per evaluation."""
    mode = os.environ.get(ENV, "auto")
    path = _FIXED.get(mode)
    if path is not None:
        return path
    mode = requested()
    if mode == "auto":
        return _numpy_path() if _SMALL else _AUTO.resolve()
    path = _FIXED[os.environ.get(ENV, "auto")] = kernel_path(mode)
    return path


# ------------------------------------------------------------------------------ compiling
def _start_background_compile() -> None:
    """Start one niced process that compiles the kernels into the cache, unless one runs."""
    folder = cache_folder()
    lock = folder / "compiling"
    try:
        fd = os.open(lock, os.O_CREAT | os.O_EXCL | os.O_WRONLY)
    except FileExistsError:
        if not _stale(lock):
            return
        lock.unlink(missing_ok=True)
        try:
            fd = os.open(lock, os.O_CREAT | os.O_EXCL | os.O_WRONLY)
        except FileExistsError:
            return
    try:
        env = dict(os.environ, **{ENV: "compiled", "HOLOFOLD_KERNEL_CACHE": str(folder.parent)})
        log = open(folder / "compile.log", "ab")  # noqa: SIM115 - the child owns it
        cmd = [sys.executable, "-m", "holofold.mechanics.kernel_compile", "compile", "--marker"]
        nice = shutil.which("nice")
        if nice:  # the compiler yields the cores to the work it is compiling for
            cmd = [nice, "-n", "10", *cmd]
        kwargs = {"start_new_session": True} if os.name == "posix" else {}
        proc = subprocess.Popen(
            cmd, stdin=subprocess.DEVNULL, stdout=log, stderr=log, env=env, **kwargs
        )
        log.close()
        os.write(fd, f"{proc.pid}\n".encode())
    finally:
        os.close(fd)


def _stale(lock: Path) -> bool:
    """A compile lock whose process is gone (killed before it could remove it)."""
    try:
        pid = int(lock.read_text().split()[0])
    except (OSError, ValueError, IndexError):
        return time.time() - lock.stat().st_mtime > 60 if lock.exists() else True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return True
    except PermissionError:
        return False
    return False


def check_environment() -> KernelPath:
    """The kernel path a run will use, checked before any work: the requested path loads and
    scipy's LAPACK answers. Raises :class:`EnvironmentFault` with the cause and the fix.

    Where ``auto`` settles on numpy for good (no numba, or its kernels failed), the warning
    is given here once and ``HOLOFOLD_KERNELS=numpy`` is set for the worker processes this
    run starts, so they do not each say it again."""
    try:
        from scipy.linalg.lapack import dgetrf, dgetrs, dpbtrf, dpbtrs  # noqa: F401
        from scipy.sparse.linalg import splu  # noqa: F401
    except Exception as exc:
        raise EnvironmentFault(
            f"scipy's LAPACK cannot be loaded ({type(exc).__name__}: {exc}); "
            "reinstall scipy (pip install --force-reinstall scipy)"
        ) from exc
    path = active()
    if requested() == "auto" and _AUTO.settled:
        os.environ[ENV] = "numpy"
    return path
