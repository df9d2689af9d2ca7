"""Writing output files: checked before any work, written atomically, strict JSON.

Every file holofold writes goes through here: :func:`check_output_path` refuses a path whose
folder is missing or whose suffix is not one the writer knows, before anything is computed;
:func:`atomic_write` writes through a temporary file of an unpredictable name in the same
folder and renames it into place, so an interrupted or failed write leaves no partial file;
:func:`write_json` writes strict JSON (NaN and infinities are refused, not written).
"""

from __future__ import annotations

import json
import os
import tempfile
from collections.abc import Callable, Sequence
from pathlib import Path

__all__ = ["check_output_path", "atomic_write", "write_json", "write_text"]


def check_output_path(path, what: str = "output", suffixes: Sequence[str] | None = None) -> Path:
    """``path`` as a Path if it can be written: its folder exists, its suffix is allowed."""
    path = Path(path)
    if suffixes is not None and path.suffix.lower() not in suffixes:
        raise ValueError(
            f"{what} {path}: unknown extension {path.suffix!r}; expected one of "
            + ", ".join(suffixes)
        )
    parent = path.resolve().parent
    if not parent.is_dir():
        raise OSError(f"{what} folder {parent} does not exist")
    return path


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def atomic_write(path, write: Callable[[str], None]) -> Path:
    """Call ``write(tmp)`` on a temporary path beside ``path``, then rename it to ``path``.

    The temporary name is unpredictable and created exclusively (``mkstemp``); the file gets
    the permissions of a normally created one (0666 less the umask), not mkstemp's 0600.
    """
    path = Path(path)
    fd, tmp = tempfile.mkstemp(prefix=".holofold-", suffix=path.suffix, dir=path.parent)
    os.close(fd)
    try:
        write(tmp)
        os.chmod(tmp, 0o666 & ~_umask())
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return path


def write_text(path, text: str) -> Path:
    """Write ``text`` (UTF-8) to ``path`` atomically."""
    return atomic_write(path, lambda tmp: Path(tmp).write_text(text, encoding="utf-8"))


def write_json(path, obj) -> Path:
    """Write ``obj`` as indented strict JSON (no NaN or Infinity) atomically."""
    return write_text(path, json.dumps(obj, indent=2, allow_nan=False) + "\n")
