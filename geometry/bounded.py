"""Bounded reading: file size, line, element, point and expansion counts checked before a parser
builds anything (docs/limits.md).

Each check is one streaming pass over the file at memory independent of what the file expands
to: a ``<use>`` or DXF block ``INSERT`` is counted as the size of what it refers to, saturated
just above the limit, so a doubling bomb (2^25 elements from 2 kB) is refused in well under a
second. Every refusal is one :class:`~holofold.geometry.errors.FormatError` line naming the file
and never quoting its content.

A file is given as a *source*: a path, the file's bytes, or a binary file object
(:func:`read_source` reads at most the size limit of it, :func:`source_name` names it in
messages: the path's name, ``"<bytes>"``, or the file object's name); the checks take a path
or the bytes.
"""

from __future__ import annotations

import io
import os
import re
import stat
from pathlib import Path

from holofold.geometry.errors import FormatError

__all__ = [
    "MAX_PATTERN_BYTES",
    "MAX_PATTERN_LINES",
    "MAX_PATTERN_ELEMENTS",
    "MAX_PATTERN_POINTS",
    "MAX_NESTING",
    "check_file_size",
    "check_line_count",
    "check_token_count",
    "check_svg_pattern",
    "check_dxf_pattern",
    "expanded_size",
    "read_source",
    "source_name",
]

#: the largest crease-pattern file read (SVG, DXF, .opx, .cp, FOLD), bytes
MAX_PATTERN_BYTES = 64 * 2**20
#: the most lines of a text crease-pattern file (DXF has ~14 lines per LINE entity)
MAX_PATTERN_LINES = 2_000_000
#: the most drawing elements (SVG elements, DXF entities, .cp lines, .opx lines) once every
#: reference is expanded; a pattern at the 10,000-panel limit has about 30,000 creases
MAX_PATTERN_ELEMENTS = 50_000
#: the most coordinate pairs (SVG ``d``/``points``) once every reference is expanded
MAX_PATTERN_POINTS = 500_000
#: the deepest element nesting (SVG) or block nesting (DXF)
MAX_NESTING = 100

_NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")
_NONFINITE = re.compile(r"(?i)(?<![a-z])(?:nan|inf(?:inity)?)(?![a-z])")
_NUMERIC_ATTRS = (
    "x",
    "y",
    "x1",
    "y1",
    "x2",
    "y2",
    "cx",
    "cy",
    "r",
    "rx",
    "ry",
    "width",
    "height",
    "points",
    "d",
    "viewBox",
    "transform",
)
_PATH_TOKEN = re.compile(
    r"\s*,?\s*(?:([MmLlHhVvCcSsQqTtAaZz])|([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?))"
)
_ARITY = {"m": 2, "l": 2, "h": 1, "v": 1, "c": 6, "s": 4, "q": 4, "t": 2, "a": 7, "z": 0}


def path_data_problem(d: str) -> str | None:
    """What is wrong with the SVG path data ``d`` (a character that is neither a command nor a
    number, a command with a wrong number of numbers), or None when it is well-formed."""
    pos, cmd, n, end = 0, None, 0, len(d.rstrip())

    def bad_count():
        k = _ARITY[cmd.lower()]
        return n > 0 if k == 0 else (n == 0 or n % k != 0)

    while pos < end:
        m = _PATH_TOKEN.match(d, pos)
        if not m or m.end() == pos:
            return f"character {pos + 1} is neither a command nor a number"
        pos = m.end()
        if m.group(1):
            if cmd is not None and bad_count():
                return f"'{cmd}' has {n} numbers"
            cmd, n = m.group(1), 0
        elif cmd is None:
            return "it does not start with a command"
        else:
            n += 1
    if cmd is not None and bad_count():
        return f"'{cmd}' has {n} numbers"
    return None


#: units a root ``width``/``height`` may carry (svgelements converts them to px)
SVG_SIZE_UNITS = ("", "px", "mm", "cm", "in", "pt", "pc")


_BYTES = (bytes, bytearray, memoryview)


def source_name(source) -> str:
    """The name of a source in messages: a path's file name, ``"<bytes>"``, or a file
    object's name (``"<file>"`` if it has none)."""
    if isinstance(source, _BYTES):
        return "<bytes>"
    if isinstance(source, str | os.PathLike):
        return Path(source).name
    name = getattr(source, "name", None)
    return Path(name).name if isinstance(name, str) and name else "<file>"


def _is_path(source) -> bool:
    return isinstance(source, str | os.PathLike)


def read_source(source, limit: int = MAX_PATTERN_BYTES, what: str = "file") -> bytes:
    """The bytes of a source (a path, bytes, or a binary file object read from where it
    stands), refused over ``limit`` bytes before more than ``limit + 1`` of them are read."""
    name = source_name(source)
    if isinstance(source, _BYTES):
        data = bytes(source)
    elif _is_path(source):
        check_file_size(source, limit, what)
        try:
            return Path(source).read_bytes()
        except OSError as exc:
            raise FormatError(f"cannot read {what} {name!r}: {exc.strerror}") from None
    elif callable(getattr(source, "read", None)):
        size = _stream_size(source)  # an open file: refused before any of it is read
        if size is not None and size > limit:
            raise FormatError(
                f"{what} {name!r} is {size:,} bytes; at most {limit:,} are read (docs/limits.md)"
            )
        try:
            data = source.read(limit + 1)
        except OSError as exc:
            raise FormatError(f"cannot read {what} {name!r}: {exc.strerror}") from None
        if not isinstance(data, _BYTES):
            raise FormatError(
                f"{what} {name!r}: a file object opened as text; open it in binary mode ('rb')"
            )
        data = bytes(data)
    else:
        raise FormatError(
            f"{what}: expected a path, bytes or a binary file object, got {type(source).__name__}"
        )
    if len(data) > limit:
        size = f"{len(data):,}" if isinstance(source, _BYTES) else f"over {limit:,}"
        raise FormatError(
            f"{what} {name!r} is {size} bytes; at most {limit:,} are read (docs/limits.md)"
        )
    return data


def _stream_size(stream) -> int | None:
    """The bytes left in an open regular file from where it stands, None for other streams."""
    try:
        st = os.fstat(stream.fileno())
        return st.st_size - stream.tell() if stat.S_ISREG(st.st_mode) else None
    except (AttributeError, OSError, ValueError, io.UnsupportedOperation):
        return None


def _open(source):
    """A binary stream of a path or of bytes."""
    return io.BytesIO(source) if isinstance(source, _BYTES) else open(source, "rb")


def check_file_size(path, limit: int = MAX_PATTERN_BYTES, what: str = "file", name=None) -> int:
    """The size of ``path`` (or of bytes) in bytes, refused over ``limit`` before any of it is
    read."""
    name = name or source_name(path)
    if isinstance(path, _BYTES):
        size = len(path)
    else:
        try:
            size = os.stat(path).st_size
        except OSError as exc:
            raise FormatError(f"cannot read {what} {name!r}: {exc.strerror}") from None
    if size > limit:
        raise FormatError(
            f"{what} {name!r} is {size:,} bytes; at most {limit:,} are read (docs/limits.md)"
        )
    return size


def check_line_count(path, limit: int = MAX_PATTERN_LINES, what: str = "file", name=None) -> int:
    """The number of lines of ``path`` (or of bytes), refused over ``limit`` (counted in 1 MiB
    blocks)."""
    name = name or source_name(path)
    check_file_size(path, what=what, name=name)
    n = 0
    with _open(path) as fh:
        while block := fh.read(1 << 20):
            n += block.count(b"\n")
            if n > limit:
                raise FormatError(
                    f"{what} {name!r} has over {limit:,} lines; at most {limit:,} "
                    "are read (docs/limits.md)"
                )
    return n


def check_token_count(
    path, token: bytes, what: str, items: str, limit: int = MAX_PATTERN_ELEMENTS, name=None
) -> int:
    """How often ``token`` occurs in ``path`` or bytes (one per crease line of .cp/.opx),
    refused over ``limit`` while counting (1 MiB blocks, the size checked first)."""
    name = name or source_name(path)
    check_file_size(path, what=what, name=name)
    n, tail = 0, b""
    with _open(path) as fh:
        while block := fh.read(1 << 20):
            chunk = tail + block
            n += chunk.count(token) - tail.count(token)
            tail = chunk[-(len(token) - 1) :] if len(token) > 1 else b""
            if n > limit:
                raise FormatError(
                    f"{what} {name!r} has over {limit:,} {items}; at "
                    f"most {limit:,} are read (docs/limits.md)"
                )
    return n


def expanded_size(own: dict, refs: dict, root, caps: tuple, name: str, what: str) -> tuple:
    """Totals (one per cap) of ``root`` with every reference expanded, saturated at ``caps``.

    ``own[k]`` is a tuple of counts of node ``k`` itself and ``refs[k]`` a dict {node: times}
    of what it refers to; a reference cycle is refused, a dangling one counts nothing.
    """
    memo: dict = {}

    def size(k, seen):
        if k in memo:
            return memo[k]
        if k in seen:
            raise FormatError(f"{what} {name!r}: {k!s:.40} refers to itself (a reference cycle)")
        if k not in own:
            return tuple(0 for _ in caps)
        tot = list(own[k])
        for j, c in refs.get(k, {}).items():
            sub = size(j, seen | {k})
            tot = [min(cap, t + c * s) for cap, t, s in zip(caps, tot, sub, strict=True)]
        memo[k] = tuple(tot)
        return memo[k]

    return size(root, frozenset())


def check_svg_pattern(path, name: str | None = None) -> None:
    """Refuse an SVG crease pattern (a path or bytes; ``name`` in messages) that is too big,
    too deep, expands to too many elements or points through ``<use>``, has a non-finite
    coordinate (``nan``, ``inf``), or a root size in an unknown unit (``100km``, ``100%``): one
    streaming pass of expat."""
    from xml.parsers import expat

    name = name or source_name(path)
    check_file_size(path, what="SVG file", name=name)
    parser = expat.ParserCreate()
    caps = (10 * MAX_PATTERN_ELEMENTS + 1, 10 * MAX_PATTERN_POINTS + 1)
    stack: list = [["#root", 0, 0, {}]]
    own: dict = {}
    refs: dict = {}
    seen_root = [False]
    counter = [0]

    class Stop(Exception):
        pass

    def start(tag, attrs):
        if len(stack) > MAX_NESTING:
            raise Stop(f"elements nested over {MAX_NESTING} deep (line {parser.CurrentLineNumber})")
        for k in _NUMERIC_ATTRS:
            v = attrs.get(k)
            if v is not None and _NONFINITE.search(v):
                raise Stop(
                    f"<{tag[:20]}> {k} is not a finite number (line "
                    f"{parser.CurrentLineNumber}); coordinates must be finite"
                )
        if not seen_root[0]:
            seen_root[0] = True
            if tag.rsplit("}", 1)[-1] != "svg":
                raise Stop("its root element is not <svg>")
            for k in ("width", "height"):
                v = attrs.get(k, "").strip()
                m = re.fullmatch(r"[-+0-9.eE]+\s*([A-Za-z%]*)", v) if v else None
                if v and (m is None or m.group(1).lower() not in SVG_SIZE_UNITS):
                    raise Stop(
                        f'root {k}="{v[:20]}" is not a length in px, mm, cm, in, pt or '
                        "pc; give the drawing's size in one of them"
                    )
        if "d" in attrs and (why := path_data_problem(attrs["d"])):
            raise Stop(
                f"<{tag[:20]}> path data cannot be read: {why} (line {parser.CurrentLineNumber})"
            )
        points = sum(len(_NUMBER.findall(attrs.get(k, ""))) // 2 for k in ("d", "points"))
        href = attrs.get("xlink:href") or attrs.get("href") or ""
        counter[0] += 1  # a key per element: ids may repeat or be absent
        key = counter[0]
        if attrs.get("id"):
            alias = "id:" + attrs["id"]
            if alias not in own:
                own[alias], refs[alias] = (0, 0), {key: 1}
        node = [key, 1, points, {}]
        if href.startswith("#"):
            node[3]["id:" + href[1:]] = 1
        stack.append(node)

    def end(tag):
        key, n, p, r = stack.pop()
        own[key], refs[key] = (n, p), r
        parent = stack[-1]
        parent[3][key] = 1

    parser.StartElementHandler, parser.EndElementHandler = start, end
    try:
        with _open(path) as fh:
            parser.ParseFile(fh)
    except Stop as exc:
        raise FormatError(f"SVG file {name!r}: {exc}") from None
    except expat.ExpatError as exc:
        raise FormatError(
            f"SVG file {name!r} is not a readable SVG file (not well-formed XML: "
            f"{expat.errors.messages[exc.code]}, line {exc.lineno})"
        ) from None
    own["#root"], refs["#root"] = (0, 0), stack[0][3]
    n, p = expanded_size(own, refs, "#root", caps, name, "SVG file")
    for count, limit, what in (
        (n, MAX_PATTERN_ELEMENTS, "elements"),
        (p, MAX_PATTERN_POINTS, "path points"),
    ):
        if count > limit:
            raise FormatError(
                f"SVG file {name!r} has {'over ' if count >= 10 * limit else ''}"
                f"{min(count, 10 * limit):,} {what} once its <use> references are expanded; "
                f"at most {limit:,} (docs/limits.md)"
            )


def check_dxf_pattern(path, name: str | None = None) -> None:
    """Refuse a DXF crease pattern (a path or bytes; ``name`` in messages) that is too big, too
    long, or whose block ``INSERT``\\ s expand to too many entities (a block inserting the
    previous one twice, 30 deep): one pass over its group-code pairs, before ezdxf loads it."""
    name = name or source_name(path)
    check_line_count(path, what="DXF file", name=name)
    cap = 10 * MAX_PATTERN_ELEMENTS + 1
    own: dict = {"#model": (0,)}
    refs: dict = {"#model": {}}
    section = block = None
    current = "#model"
    expect = None  # the group code whose value is awaited
    entity = None
    with _open(path) as fh:
        lines = iter(fh)
        for code in lines:
            value = next(lines, b"").strip().decode("latin-1")
            code = code.strip()
            if code == b"0":
                entity = value
                if value == "SECTION":
                    expect = "section"
                    continue
                if value == "ENDSEC":
                    section, current = None, "#model"
                    continue
                if section == "BLOCKS" and value == "BLOCK":
                    expect, block = "block", None
                    continue
                if section == "BLOCKS" and value == "ENDBLK":
                    current = "#model"
                    continue
                if section in ("ENTITIES", "BLOCKS") and value not in ("EOF",):
                    n = own.get(current, (0,))[0]
                    own[current] = (min(cap, n + 1),)
            elif code == b"2":
                if expect == "section":
                    section, expect = value, None
                    current = "#model"
                elif expect == "block":
                    block, expect = value, None
                    current = "B:" + block
                    own.setdefault(current, (0,))
                    refs.setdefault(current, {})
                elif entity == "INSERT" and section in ("ENTITIES", "BLOCKS"):
                    r = refs.setdefault(current, {})
                    r["B:" + value] = r.get("B:" + value, 0) + 1
    n = expanded_size(own, refs, "#model", (cap,), name, "DXF file")[0]
    if n > MAX_PATTERN_ELEMENTS:
        raise FormatError(
            f"DXF file {name!r} has {'over ' if n >= cap else ''}{min(n, cap - 1):,} entities "
            f"once its block INSERTs are expanded; at most {MAX_PATTERN_ELEMENTS:,} "
            "(docs/limits.md)"
        )
