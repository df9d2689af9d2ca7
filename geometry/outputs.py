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

from holofold.geometry.fault_points import fault_point

__all__ = [
    "check_output_path",
    "check_writable_folder",
    "check_output_folder",
    "atomic_write",
    "write_json",
    "write_text",
]


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
    if path.is_dir():
        raise IsADirectoryError(f"{what} {path} is a folder, not a file")
    check_writable_folder(parent, f"{what} {path}")
    return path


def check_output_folder(folder, what: str = "output folder") -> Path:
    """``folder`` as a Path if it can be written, or created: the folder itself if it exists
    (and is a folder), else its nearest existing parent (:func:`check_writable_folder`)."""
    folder = Path(folder)
    if folder.exists() and not folder.is_dir():
        raise NotADirectoryError(f"{what} {folder} exists and is not a folder")
    probe = folder
    while not probe.exists():
        probe = probe.parent
    check_writable_folder(probe, f"{what} {folder}")
    return folder


def check_writable_folder(folder, what: str = "output folder") -> Path:
    """``folder`` as a Path if a file can be created in it, tried by creating (and removing)
    an empty temporary file: permissions, a read-only file system and an immutable folder
    are all seen, whoever runs. Raises ``PermissionError`` naming ``what`` otherwise."""
    folder = Path(folder)
    try:
        fd, tmp = tempfile.mkstemp(prefix=".holofold-", dir=folder)
    except OSError as exc:
        why = exc.strerror or type(exc).__name__
        raise PermissionError(f"{what}: cannot write in {folder} ({why})") from None
    os.close(fd)
    os.unlink(tmp)
    return folder


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def _refuse_linked_subfolder(path: Path) -> None:
    """Refuse writing into a folder that is a symbolic link inside a locked output folder (a
    ``chunks`` link to another directory would be written through). A file that is a link is
    safe already: the rename replaces the link, never its target."""
    parent = path.parent
    if parent.is_symlink() and (parent.parent / ".holofold.lock").exists():
        raise OSError(
            f"{parent} is a symbolic link inside the output folder {parent.parent}; files are "
            "never written through one: remove it"
        )


def atomic_write(path, write: Callable[[str], None]) -> Path:
    """Call ``write(tmp)`` on a temporary path beside ``path``, then rename it to ``path``.

    The temporary name is unpredictable and created exclusively (``mkstemp``); the file gets
    the permissions of a normally created one (0666 less the umask), not mkstemp's 0600.
    """
    path = Path(path)
    _refuse_linked_subfolder(path)
    fd, tmp = tempfile.mkstemp(prefix=".holofold-", suffix=path.suffix, dir=path.parent)
    os.close(fd)
    try:
        write(tmp)
        os.chmod(tmp, 0o666 & ~_umask())
        fault_point("write")  # test-only (HOLOFOLD_TEST_FAULT); nothing when unset
        os.replace(tmp, path)
        fault_point("written")
    except OSError as exc:  # a full disk named no path (the write fails on an open file)
        Path(tmp).unlink(missing_ok=True)
        if exc.filename is not None and str(path) in str(exc):
            raise
        why = exc.strerror or type(exc).__name__
        raise OSError(exc.errno, f"cannot write {path}: {why}") from None
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
