"""Input files: what a path is, checked before it is opened.

:func:`check_input_file` refuses a path that is not a regular file in one line naming what it
is (a folder, a FIFO, a device, a socket, nothing), before anything opens it: reading a FIFO
would wait forever and a device has no end. Messages about an input never quote its content
(a file that is not what it should be may be anyone's secret).
"""

from __future__ import annotations

import stat
from pathlib import Path

__all__ = ["check_input_file", "path_kind"]

_KINDS = (
    (stat.S_ISDIR, "a folder"),
    (stat.S_ISFIFO, "a FIFO (named pipe)"),
    (stat.S_ISCHR, "a character device"),
    (stat.S_ISBLK, "a block device"),
    (stat.S_ISSOCK, "a socket"),
)


def path_kind(path) -> str:
    """What ``path`` is, in words: ``"a file"``, ``"a folder"``, ``"a FIFO (named pipe)"``,
    ``"a character device"``, ..., or ``"missing"``."""
    try:
        mode = Path(path).stat().st_mode
    except FileNotFoundError:
        return "missing"
    except OSError as exc:
        return f"unreadable ({exc.strerror or type(exc).__name__})"
    if stat.S_ISREG(mode):
        return "a file"
    return next((words for test, words in _KINDS if test(mode)), "not a regular file")


def check_input_file(path, what: str = "input") -> Path:
    """``path`` as a Path if it is a regular file; else ``FileNotFoundError`` (missing) or
    ``IsADirectoryError`` / ``OSError`` naming what it is, in one line."""
    path = Path(path)
    kind = path_kind(path)
    if kind == "a file":
        return path
    if kind == "missing":
        raise FileNotFoundError(f"{what} {str(path)!r} does not exist")
    if kind == "a folder":
        raise IsADirectoryError(f"{what} {str(path)!r} is a folder, not a file")
    raise OSError(f"{what} {str(path)!r} is {kind}, not a file")
