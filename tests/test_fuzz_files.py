"""Hostile files for every reader (issue 33 item 8): a generator per format (NaN/inf, huge and
tiny numbers, truncation, index errors, expansion bombs, long files, symlinks), generated here
from clean files (no corpus committed). Each input is read, and a pattern read is passed through
the physical check a model build applies (``check_sheet``). Counted: tracebacks (an exception
that is not the project's one-line error), hangs (over 10 s, turned into an alarm), and silent
results (a mutation that must be refused, accepted).
"""

from __future__ import annotations

import math
import os
import re
import signal
import struct
import warnings
from collections import Counter
from pathlib import Path

import numpy as np

import holofold.geometry as g
from holofold.geometry.mesh_reader import read_mesh
from holofold.geometry.physical import check_sheet

HANG_S = 10
NUM = re.compile(rb"(?<![A-Za-z#_])-?\d+\.\d+(?:[eE][-+]?\d+)?")
BAD_NUMBERS = [b"nan", b"NaN", b"inf", b"-inf", b"Infinity", b"1e300", b"-1e300"]


class Hang(Exception):
    pass


def _alarm(signum, frame):
    raise Hang


def _outcome(read, path):
    """'ok', 'refused', 'traceback: ...' or 'hang'."""
    old = signal.signal(signal.SIGALRM, _alarm)
    signal.alarm(HANG_S)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            read(path)
        return "ok"
    except Hang:
        return "hang"
    except (ValueError, OSError) as exc:
        msg = str(exc)
        if "\n" in msg.strip() or not msg or "Traceback" in msg:
            return f"traceback: multi-line {type(exc).__name__}"
        return "refused"
    except Exception as exc:  # noqa: BLE001 - counted
        return f"traceback: {type(exc).__name__}: {str(exc)[:80]}"
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)


def _read_pattern(path):
    p = g.read_pattern(path)
    check_sheet(p, panel_thickness=1e-4, crease_thickness=5e-5, crease_width=1e-4)


# ------------------------------------------------------------------ clean files
def _mesh_files(d: Path) -> dict:
    V = np.array([[0, 0, 0], [10, 0, 0], [0, 10, 0], [10, 10, 5], [20, 5, 1]], float)
    F = [(0, 1, 2), (1, 3, 2), (1, 4, 3)]
    out = {}
    body = b"".join(struct.pack("<12fH", 0, 0, 1, *V[list(f)].ravel(), 0) for f in F)
    out["stl"] = b"\0" * 80 + struct.pack("<I", len(F)) + body
    lines = ["solid t"]
    for f in F:
        lines += ["facet normal 0 0 1", "outer loop"]
        lines += [f"vertex {x:.6f} {y:.6f} {z:.6f}" for x, y, z in V[list(f)]]
        lines += ["endloop", "endfacet"]
    out["ascii.stl"] = ("\n".join(lines + ["endsolid t"]) + "\n").encode()
    vs = "".join(f"v {x:.6f} {y:.6f} {z:.6f}\n" for x, y, z in V)
    out["obj"] = (vs + "".join(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in F)).encode()
    vt = "".join(f"{x:.6f} {y:.6f} {z:.6f}\n" for x, y, z in V)
    ft = "".join(f"3 {a} {b} {c}\n" for a, b, c in F)
    out["off"] = (f"OFF\n{len(V)} {len(F)} 0\n" + vt + ft).encode()
    out["ply"] = (
        f"ply\nformat ascii 1.0\nelement vertex {len(V)}\nproperty float x\nproperty float y\n"
        f"property float z\nelement face {len(F)}\nproperty list uchar int vertex_indices\n"
        "end_header\n" + vt + ft
    ).encode()
    return out


def _pattern_files(d: Path) -> dict:
    p = g.miura_sheet(3, 3, a=0.02, b=0.025, gamma=math.radians(60), ext=1.0)
    out = {}
    for kind in ("fold", "svg", "dxf"):
        path = g.export(p, d / f"clean.{kind}")
        out[kind] = path.read_bytes()
    xy = p.flat * 1000
    code = {"B": 1, "M": 2, "V": 3}
    out["cp"] = "".join(
        f"{code.get(a, 1)} {xy[i, 0]:.6f} {xy[i, 1]:.6f} {xy[j, 0]:.6f} {xy[j, 1]:.6f}\n"
        for (i, j), a in zip(p.edges, p.assignment, strict=True)
    ).encode()
    return out


# ------------------------------------------------------------------ mutations
def _coordinate_spans(kind: str, data: bytes) -> list[tuple[int, int]]:
    """Byte spans of the coordinates of a file (not header numbers, versions or styles)."""
    if kind == "stl":
        return []
    start, end = 0, len(data)
    if kind == "ply":
        start = data.find(b"end_header")
    elif kind == "fold":
        start = data.find(b'"vertices_coords"')
        end = data.find(b'"edges_vertices"', start)
    if kind == "dxf":
        found = re.finditer(rb"\n *(?:10|20|11|21)\r?\n(-?\d+(?:\.\d+)?(?:[eE][-+]?\d+)?)", data)
        lo = data.find(b"ENTITIES")
        hi = data.find(b"ENDSEC", lo)
        return [m.span(1) for m in found if lo < m.start() < hi]
    if kind == "svg":
        found = re.finditer(rb' (?:x1|y1|x2|y2)="(-?[\d.]+(?:[eE][-+]?\d+)?)"', data)
        return [m.span(1) for m in found]
    spans = [m.span() for m in re.finditer(rb"-?\d+(?:\.\d+)?(?:[eE][-+]?\d+)?", data[start:end])]
    if kind in ("off", "ply", "ascii.stl"):  # vertex numbers only: indices and counts are integers
        spans = [sp for sp in spans if b"." in data[start + sp[0] : start + sp[1]]]
    if kind == "cp":  # the type code is not a coordinate
        spans = [
            sp for sp in spans if sp[0] > 0 and data[start + sp[0] - 1 : start + sp[0]] != b"\n"
        ]
    return [(start + a, start + b) for a, b in spans]


def _mutations(kind: str, data: bytes, rng) -> list[tuple[str, bytes, bool]]:
    """(label, bytes, must_refuse) hostile variants of a clean file."""
    out = []
    nums = _coordinate_spans(kind, data)
    for bad in BAD_NUMBERS:
        for _ in range(3):
            if not nums:
                break
            a, b = nums[rng.integers(len(nums))]
            # a huge number in an SVG/DXF/.cp pattern is refused by the sheet check
            out.append((f"number {bad.decode()}", data[:a] + bad + data[b:], True))
    for _ in range(4):
        if nums:
            a, b = nums[rng.integers(len(nums))]
            out.append(("tiny number", data[:a] + b"1e-300" + data[b:], False))
    if kind == "stl":
        n = (len(data) - 84) // 50
        for bad in (np.nan, np.inf, 1e300):
            for k in range(n):
                mutated = bytearray(data)
                at = 84 + 50 * k + 12 + 4 * int(rng.integers(9))
                # 1e300 is no float32: written as the largest float32 times 10 (inf), quietly
                with np.errstate(over="ignore"):
                    struct.pack_into("<f", mutated, at, np.float32(min(bad, np.inf)))
                out.append((f"binary {bad}", bytes(mutated), True))
        big = bytearray(data)
        struct.pack_into("<I", big, 80, 2_200_000)
        out.append(("declared 2.2M triangles", bytes(big), True))
    # truncation: refused where the format has counts or an end (not OBJ, .cp, DXF)
    counted = kind in ("stl", "ascii.stl", "off", "ply", "svg", "fold")
    for frac in (0.1, 0.35, 0.5, 0.75, 0.9, 0.97):
        out.append((f"truncated {frac}", data[: int(frac * len(data))], counted))
    out.append(("empty", b"", True))
    out.append(("garbage", bytes(rng.integers(0, 256, 3000, dtype=np.uint8)), True))
    if kind == "obj":
        out.append(("index 0", data.replace(b"f 1 ", b"f 0 ", 1), True))
        out.append(("index 99", data.replace(b"f 1 ", b"f 99 ", 1), True))
        out.append(("index -99", data.replace(b"f 1 ", b"f -99 ", 1), True))
    if kind in ("off", "ply"):
        out.append(("index 99", data[: data.rfind(b"3 ")] + b"3 0 1 99\n", True))
        out.append(("count +5", re.sub(rb"(\n)(\d+) (\d+) 0\n", rb"\1\2 8 0\n", data, count=1)
                    if kind == "off" else data.replace(b"element face 3", b"element face 8"),
                    True))  # fmt: skip
    if kind == "svg":
        out.append(("html", b"<html><body>x</body></html>", True))
        out.append(("width 100km", re.sub(rb'width="[^"]*"', b'width="100km"', data, count=1),
                    True))  # fmt: skip
        out.append(("width 100%", re.sub(rb'width="[^"]*"', b'width="100%"', data, count=1), True))
        bomb = b'<defs><line id="l0" x1="0" y1="0" x2="1" y2="1" stroke="#f00"/>'
        for i in range(1, 26):
            bomb += f'<g id="l{i}"><use href="#l{i - 1}"/><use href="#l{i - 1}"/></g>'.encode()
        bomb += b'</defs><use href="#l25"/>'
        out.append(("use bomb", data.replace(b"</svg>", bomb + b"</svg>"), True))
        many = b'<line x1="0" y1="0" x2="1" y2="1" stroke="#f00"/>' * 60_000
        out.append(("60k elements", data.replace(b"</svg>", many + b"</svg>"), True))
        bad_path = b'<path d="M 0 0 L 5 Q" stroke="#f00"/></svg>'
        out.append(("bad path", data.replace(b"</svg>", bad_path), True))
    if kind == "dxf":
        d = [b"0", b"SECTION", b"2", b"BLOCKS", b"0", b"BLOCK", b"2", b"B0", b"0", b"LINE", b"8",
             b"0", b"10", b"0", b"20", b"0", b"11", b"1", b"21", b"1", b"0", b"ENDBLK"]  # fmt: skip
        for i in range(1, 31):
            d += [b"0", b"BLOCK", b"2", b"B%d" % i, b"0", b"INSERT", b"2", b"B%d" % (i - 1), b"0",
                  b"INSERT", b"2", b"B%d" % (i - 1), b"0", b"ENDBLK"]  # fmt: skip
        d += [b"0", b"ENDSEC", b"0", b"SECTION", b"2", b"ENTITIES", b"0", b"INSERT", b"2",
              b"B30", b"0", b"ENDSEC", b"0", b"EOF"]  # fmt: skip
        out.append(("insert bomb", b"\n".join(d) + b"\n", True))
    if kind == "cp":
        out.append(("60k lines", data * (60_000 // max(1, data.count(b"\n")) + 1), True))
        out.append(("secret", b"root:$6$saltsalt$hash:19000:0:99999:7:::\n", True))
    if kind == "fold":
        import json

        d = json.loads(data)
        d["vertices_coords"] = [[x * 1e300 for x in v] for v in d["vertices_coords"]]
        out.append(("x1e300", json.dumps(d).encode(), True))
        d = json.loads(data)
        d["vertices_coords"] = [[x * 1e-300 for x in v] for v in d["vertices_coords"]]
        out.append(("x1e-300", json.dumps(d).encode(), True))
        d = json.loads(data)
        d["frame_unit"] = "in"  # metre numbers read as inches: 2.5 mm, warned not refused
        out.append(("unit in", json.dumps(d).encode(), False))
    return out


def test_hostile_files_give_no_traceback_hang_or_silent_result(tmp_path, capsys):
    rng = np.random.default_rng(33)
    totals, bad = Counter(), []
    cases = [(k, v, read_mesh) for k, v in _mesh_files(tmp_path).items()]
    cases += [(k, v, _read_pattern) for k, v in _pattern_files(tmp_path).items()]
    i = 0
    for kind, clean, read in cases:
        suffix = "stl" if kind.endswith("stl") else kind
        path = tmp_path / f"clean-{kind}.{suffix}"
        path.write_bytes(clean)
        assert _outcome(read, path) == "ok", kind  # the clean file reads
        for label, data, must_refuse in _mutations(kind, clean, rng):
            i += 1
            path = tmp_path / f"f{i}.{suffix}"
            path.write_bytes(data)
            got = _outcome(read, path)
            totals["inputs"] += 1
            if got.startswith("traceback") or got == "hang":
                totals["tracebacks" if got != "hang" else "hangs"] += 1
                bad.append((kind, label, got))
            elif got == "ok" and must_refuse:
                totals["silent"] += 1
                bad.append((kind, label, "accepted"))
            else:
                totals[got] += 1
    # symlinks: a pattern or mesh name pointing elsewhere is read as what it points to (the
    # user's choice) and never quoted
    for kind in ("cp", "svg", "stl"):
        link = tmp_path / f"link.{kind}"
        link.symlink_to("/etc/passwd" if os.path.exists("/etc/passwd") else tmp_path)
        got = _outcome(read_mesh if kind == "stl" else _read_pattern, link)
        totals["inputs"] += 1
        totals["refused" if got == "refused" else "tracebacks"] += 1
        if got != "refused":
            bad.append((kind, "symlink", got))
    with capsys.disabled():
        print(f"\nfuzz files: {dict(totals)}")
    assert totals["inputs"] >= 300
    assert bad == [], "\n".join(map(str, bad))
