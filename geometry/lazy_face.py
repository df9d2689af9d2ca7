"""A layer's lazy face: the names its ``__init__`` gives, each imported on first use.

A face lists, per submodule, the names it takes from it, or :data:`ALL` for every name of the
submodule's ``__all__`` (read from the submodule's source, not imported, so that the face stays
lazy; the ``__all__`` must then be a literal list).
"""

from __future__ import annotations

import os

import lazy_loader

__all__ = ["ALL", "attach", "source_all"]

#: in a face's table: every name of the submodule's ``__all__``
ALL = "__all__"


def source_all(package_file: str, module: str) -> list[str]:
    """The literal ``__all__ = [...]`` of submodule ``module`` (dotted, below the package whose
    ``__init__.py`` is ``package_file``), read from its source without importing it."""
    base = os.path.join(os.path.dirname(package_file), *module.split("."))
    path = base + ".py" if os.path.isfile(base + ".py") else os.path.join(base, "__init__.py")
    with open(path, encoding="utf-8") as fh:
        text = "\n" + fh.read()  # a line break before the first line too
    start = text.find("\n__all__ = [")
    if start < 0:
        raise ImportError(f"{path} has no literal '__all__ = [...]' for its package's face")
    start += len("\n__all__ = [")
    items = [w.strip() for w in text[start : text.index("]", start)].split(",")]
    items = [w for w in items if w]
    if not all(len(w) > 2 and w[0] == w[-1] == '"' and w[1:-1].isidentifier() for w in items):
        raise ImportError(f"{path}: its '__all__' is not a list of quoted names")
    return [w[1:-1] for w in items]


def attach(name: str, package_file: str, submodules=None, submod_attrs=None):
    """``lazy_loader.attach`` with :data:`ALL` in ``submod_attrs`` read by :func:`source_all`:
    the package's ``(__getattr__, __dir__, __all__)``."""
    attrs = {
        m: source_all(package_file, m) if names == ALL else names
        for m, names in (submod_attrs or {}).items()
    }
    return lazy_loader.attach(name, submodules=submodules, submod_attrs=attrs)
