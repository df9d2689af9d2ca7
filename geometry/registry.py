"""One registry behaviour for every extension point (readers, formats, pattern families,
scenario kinds, sheet families, cutter profiles, refinement strategies).

A :class:`Registry` is a read-only mapping name -> entry whose names are computed on every
call, so nothing derived from it freezes at import:

- **built-ins** (given when the registry is made, or added by the module that defines them with
  ``builtin=True``) cannot be replaced;
- :meth:`Registry.register` refuses a taken name unless ``replace=True`` (``ValueError``);
- an **entry-point group** (optional) is read lazily: its names are listed without loading, an
  entry is loaded when it is asked for (a broken plug-in: one line naming it);
- an unknown name raises the registry's error class (a ``ValueError`` or ``KeyError``
  subclass the CLI prints) naming the known ones.
"""

from __future__ import annotations

from collections.abc import Callable, Hashable, Iterator, Mapping
from contextlib import contextmanager
from typing import Generic, TypeVar

__all__ = ["Registry"]

T = TypeVar("T")


def _as_is(name, value):
    return value


def _same(name):
    return name


class _Lazy:
    def __init__(self, load):
        self.load = load


class Registry(Mapping, Generic[T]):
    """name -> entry (a :class:`~collections.abc.Mapping`; see the module docstring).

    Parameters
    ----------
    what : str
        What an entry is, for messages ("pattern family", "reader").
    builtins : mapping, optional
        Built-in entries (protected).
    group : str, optional
        Entry-point group of plug-ins (``importlib.metadata``), read on every call.
    check : callable(name, value) -> entry, optional
        Validates (and may convert) a registered or loaded value; raises ``TypeError`` or
        ``ValueError``.
    key : callable(name) -> name, optional
        Normalises a name (e.g. ``str.lower`` for file suffixes).
    error : exception class
        Raised for an unknown name or a plug-in that fails to load (default ``KeyError``).
    """

    def __init__(
        self,
        what: str,
        builtins: Mapping | None = None,
        *,
        group: str | None = None,
        check: Callable[[Hashable, object], T] | None = None,
        key: Callable[[Hashable], Hashable] | None = None,
        error: type[Exception] = KeyError,
    ):
        self.what, self.group, self.error = what, group, error
        self._check = check or _as_is
        self._key = key or _same
        self._builtin: dict = {}
        self._added: dict = {}
        for name, value in (builtins or {}).items():
            self.register(value, name, builtin=True)

    # ------------------------------------------------------------------ adding
    def register(self, value, name: Hashable | None = None, *, replace: bool = False,
                 builtin: bool = False) -> T:  # fmt: skip
        """Add ``value`` under ``name`` (default ``value.name``); returns the entry.

        A built-in name is never replaced; another taken name only with ``replace=True``.
        """
        name = self._key(getattr(value, "name", None) if name is None else name)
        if name is None:
            raise ValueError(f"a {self.what} needs a name")
        entry = value if isinstance(value, _Lazy) else self._check(name, value)
        if name in self._builtin:
            raise ValueError(f"{self.what} {name!r} is built in; choose another name")
        if name in self._added and not replace:
            raise ValueError(
                f"{self.what} {name!r} is already registered; pass replace=True to replace it"
            )
        (self._builtin if builtin else self._added)[name] = entry
        return entry

    def register_lazy(self, name: Hashable, load: Callable[[], object]) -> None:
        """A built-in entry made by ``load()`` the first time it is asked for (its module is
        imported only when used)."""
        self.register(_Lazy(load), name, builtin=True)

    def unregister(self, name: Hashable) -> None:
        """Remove a registered (not built-in) entry; a name not registered is ignored."""
        name = self._key(name)
        if name in self._builtin:
            raise ValueError(f"{self.what} {name!r} is built in and cannot be removed")
        self._added.pop(name, None)

    @contextmanager
    def saved(self):
        """Registrations made inside the ``with`` block are undone on leaving it (for tests)."""
        kept = dict(self._added)
        try:
            yield self
        finally:
            self._added.clear()
            self._added.update(kept)

    # ------------------------------------------------------------------ reading
    def _entry_points(self) -> dict:
        if self.group is None:
            return {}
        from importlib.metadata import entry_points

        return {self._key(ep.name): ep for ep in entry_points(group=self.group)}

    def names(self) -> tuple:
        """Every name, built-in first, then registered, then entry points (not loaded)."""
        names = [*self._builtin, *(n for n in self._added if n not in self._builtin)]
        names += [n for n in self._entry_points() if n not in names]
        return tuple(names)

    def builtin_names(self) -> tuple:
        return tuple(self._builtin)

    def get(self, name, default=None):
        """The entry of ``name``, or ``default`` when there is none (a broken plug-in raises)."""
        return self[name] if name in self else default

    def __getitem__(self, name) -> T:
        try:
            name = self._key(name)
            hit = self._builtin.get(name, self._added.get(name))
        except TypeError:  # an unhashable name
            hit = None
        if isinstance(hit, _Lazy):
            hit = self._builtin[name] = self._check(name, hit.load())
        if hit is not None:
            return hit
        eps = self._entry_points()
        if name in eps:
            try:
                return self._check(name, eps[name].load())
            except Exception as exc:  # noqa: BLE001 - a broken plug-in: say which
                raise self.error(
                    f"{self.what} {name!r} (entry point {eps[name].value}) cannot be loaded: "
                    f"{type(exc).__name__}: {exc}"
                ) from None
        known = ", ".join(map(str, self.names()))
        raise self.error(f"unknown {self.what} {name!r}; known: {known}")

    def loaded(self) -> dict:
        """name -> entry of every entry that loads (a broken plug-in is left out)."""
        out = {}
        for n in self.names():
            try:
                out[n] = self[n]
            except (self.error, KeyError, TypeError, ValueError, ImportError):
                continue
        return out

    def __iter__(self) -> Iterator:
        return iter(self.names())

    def __len__(self) -> int:
        return len(self.names())

    def __contains__(self, name) -> bool:
        try:
            name = self._key(name)
            return name in self._builtin or name in self._added or name in self._entry_points()
        except TypeError:
            return False

    def __repr__(self) -> str:
        return f"Registry({self.what!r}, names={list(self.names())!r})"
