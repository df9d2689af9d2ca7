"""Folded shapes of holofold against Origami Simulator's, on the same files (issue 32).

Origami Simulator (Amanda Ghassaei, github.com/amandaghassaei/OrigamiSimulator, MIT licence;
JavaScript, three.js, GPU shaders) is served from a local copy of its app (the folder with
``index.html``, ``js/``, ``dependencies/`` and ``assets/``) by Python's http.server on a free
loopback port and driven in headless Chromium (WebGL through SwiftShader). A small script
injected into the served ``index.html`` loads one file the way the app's demo menu does
(``importer.importDemoFile``), sets the fold percent, pauses the app's own animation loop and
runs the dynamic solver (its defaults: Euler, damping 0.45, axial 20, crease 0.7, face 0.2)
in chunks of 200 steps until no vertex moves more than 1e-5 (in the app's units, the flat
pattern's bounding-sphere radius = 1) over two chunks in a row, or 40,000 steps; it posts
the vertex positions, flat positions and triangles back to the server as JSON. No browser
driver or websocket package is needed: only Chromium (``--chromium`` or ``$CHROMIUM``).

holofold folds the same file as ``validation/origami_simulator_examples.py`` does (PP, 1 mm
panels, 0.2 mm creases, 1 mm wide, scaled to 200 mm, ``fold_pattern(p, fraction)``).

Comparison. Origami Simulator centres the flat pattern on its bounding-box centre and scales
it by 1 / bounding-sphere radius (``js/model.js``, ``sync``), after mapping SVG (x, y) to
(x, 0, y); it also triangulates and may merge vertices. Both flat layouts are therefore
brought to their bounding-box centre and largest side = 1 and vertices are matched to the
nearest flat vertex of the other tool (mutual nearest, within 1e-4 of the sheet size) under
each of the 8 axis flips and quarter turns; of the turns that match the most vertices (several
for a symmetric sheet) the one with the smallest RMS distance is kept. The folded positions
of the matched vertices, in units of the flat pattern's largest bounding-box side ("sheet
size"), are aligned by the best rigid motion (Kabsch); a reflection is allowed, because the
two tools' sheet normals differ (a reflection hides a complete mountain/valley swap, not a
partial one; ``mirror`` in the row says where it was used). Reported: largest and RMS
distance in % of the sheet size.

Clean: holofold's verdict is ``folds rigidly`` or ``does not fold rigidly`` at the requested
fraction with no intersecting faces; Origami Simulator settled, its largest bar strain
(|length / flat length - 1| over the edges of its triangles) at most 0.1 % and no triangles
through each other (``holofold.mechanics.intersection.intersecting_faces`` on its positions).

    python validation/origami_simulator_compare.py APP [--only Bases/] [--fractions 0.5 1]
        [--md validation/origami_simulator_compare.md] [--save-os DIR]

Each Origami Simulator run is one Chromium process, ended when it has posted (or after
``--os-timeout`` s). ``--save-os DIR`` writes Origami Simulator's result of every file as
``DIR/<name>-<percent>.json`` (how the test data in tests/data/origami-simulator were made)
and reuses those already there.
"""

from __future__ import annotations

import argparse
import functools
import http.server
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time
import urllib.parse
import warnings
from pathlib import Path

import numpy as np
from scipy.spatial import cKDTree

SECTION = dict(panel_thickness=1e-3, crease_thickness=0.2e-3, crease_width=1e-3, E=1.5e9, nu=0.42)
SIZE = 0.2  # m, largest side of the flat pattern
STRAIN_CLEAN = 1e-3  # Origami Simulator's largest bar strain for a clean state
CLEAN_VERDICTS = ("folds rigidly", "does not fold rigidly")
CURVED = ("Curved/",)  # curved creases: not straight-crease files

# Injected into the served index.html: loads one file like the demo menu, folds, posts.
DRIVER = r"""
(function () {
  var q = new URLSearchParams(location.search);
  var file = q.get('file'), percent = parseFloat(q.get('percent'));
  var chunk = parseInt(q.get('chunk') || '200'), maxSteps = parseInt(q.get('max_steps') || '40000');
  var tol = parseFloat(q.get('tol') || '1e-5');
  var sent = false, warnings = [], t0 = Date.now();
  function post(o) {
    if (sent) return; sent = true;
    o.warnings = warnings; o.seconds = (Date.now() - t0) / 1000;
    var x = new XMLHttpRequest(); x.open('POST', '/__result', true);
    x.setRequestHeader('Content-Type', 'application/json'); x.send(JSON.stringify(o));
  }
  window.addEventListener('error', function (e) { post({error: 'script error: ' + e.message}); });
  function waitApp() {
    if (typeof globals === 'undefined' || !globals.importer || !globals.model ||
        !globals.dynamicSolver) {
      if (Date.now() - t0 > 60000) return post({error: 'the app did not start'});
      return setTimeout(waitApp, 50);
    }
    var gl = document.createElement('canvas').getContext('webgl');
    if (!gl) return post({error: 'no WebGL'});
    globals.threeView.pauseSimulation();
    globals.warn = function (m) { warnings.push(String(m).replace(/<[^>]*>/g, ' ')); };
    globals.importer.importDemoFile(file);
    waitModel();
  }
  function waitModel() {
    var n = globals.model.getNodes().length;
    if (!n || globals.needsSync || globals.simNeedsSync) {
      if (Date.now() - t0 > 120000) return post({error: 'the model did not load'});
      return setTimeout(waitModel, 50);
    }
    globals.setCreasePercent(percent);
    globals.shouldChangeCreasePercent = true;
    setTimeout(stepChunk, 0);
  }
  var steps = 0, prev = null, quiet = 0, d = Infinity;
  function stepChunk() {
    globals.model.step(chunk); steps += chunk;
    var pos = globals.model.getPositionsArray();
    d = 0;
    if (prev) { for (var i = 0; i < pos.length; i++) d = Math.max(d, Math.abs(pos[i] - prev[i])); }
    else d = Infinity;
    prev = Float32Array.from(pos);
    quiet = d < tol ? quiet + 1 : 0;
    if (quiet >= 2 || steps >= maxSteps) return finish();
    setTimeout(stepChunk, 0);
  }
  function finish() {
    var nodes = globals.model.getNodes(), flat = [];
    for (var i = 0; i < nodes.length; i++) {
      var o = nodes[i].getOriginalPosition(); flat.push([o.x, o.y, o.z]);
    }
    post({positions: Array.from(prev), flat: flat, faces: globals.model.getFaces(),
          steps: steps, last_move: d, settled: quiet >= 2, scale: globals.scale});
  }
  waitApp();
})();
"""


class _Handler(http.server.SimpleHTTPRequestHandler):
    """The app's files, its index.html with the driver injected, extra files under
    /assets/__given/, and POST /__result."""

    def __init__(self, *a, state=None, **k):
        self.state = state
        super().__init__(*a, **k)

    def log_message(self, *args):  # quiet
        pass

    def do_GET(self):  # noqa: N802 (http.server's name)
        path = urllib.parse.urlparse(self.path).path
        if path in ("/", "/index.html"):
            html = (Path(self.directory) / "index.html").read_text(encoding="utf-8")
            # no analytics from outside; the driver last
            html = html.replace("https://www.googletagmanager.com/gtag/js", "/__none.js")
            html = html.replace("</body>", '<script src="/__driver.js"></script></body>')
            return self._send(html.encode(), "text/html")
        if path == "/__driver.js":
            return self._send(DRIVER.encode(), "application/javascript")
        if path == "/__none.js":
            return self._send(b"", "application/javascript")
        if path.startswith("/assets/__given/"):
            f = self.state["given"].get(urllib.parse.unquote(path.rsplit("/", 1)[1]))
            if f is None:
                return self.send_error(404)
            return self._send(Path(f).read_bytes(), "image/svg+xml")
        return super().do_GET()

    def do_POST(self):  # noqa: N802
        n = int(self.headers.get("Content-Length", 0))
        body = self.rfile.read(n)
        self._send(b"ok", "text/plain")
        self.state["result"] = json.loads(body)
        self.state["event"].set()

    def _send(self, data: bytes, ctype: str):
        self.send_response(200)
        self.send_header("Content-Type", ctype)
        self.send_header("Content-Length", str(len(data)))
        self.end_headers()
        self.wfile.write(data)


def find_chromium(given: str | None = None) -> str | None:
    """The Chromium executable: ``given``, $CHROMIUM, or chromium / chromium-browser /
    google-chrome on the PATH (None: none found)."""
    for c in (given, os.environ.get("CHROMIUM"), "chromium", "chromium-browser", "google-chrome"):
        if c and shutil.which(c):
            return shutil.which(c)
    return None


def run_origami_simulator(
    app: Path,
    file: str | Path,
    percent: float,
    *,
    chromium: str | None = None,
    timeout: float = 600.0,
    max_steps: int = 40000,
) -> dict:
    """Fold one file in Origami Simulator to ``percent`` (0-1) and return its result:
    ``positions`` (3 n), ``flat`` (n, 3), ``faces``, ``steps``, ``settled``, ``last_move``,
    ``warnings`` (or ``error``). ``file``: a path under the app's assets/ ("Bases/x.svg") or
    a file on disk (served as an extra asset). Raises RuntimeError when Chromium is missing,
    does not answer within ``timeout`` s or the app reports an error."""
    exe = find_chromium(chromium)
    if exe is None:
        raise RuntimeError("no Chromium found (give --chromium or set $CHROMIUM)")
    state = {"event": threading.Event(), "result": None, "given": {}}
    if Path(file).is_file():
        state["given"][Path(file).name] = str(file)
        rel = "__given/" + Path(file).name
    else:
        rel = str(file)
    handler = functools.partial(_Handler, directory=str(app), state=state)
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    query = urllib.parse.urlencode(
        {"model": "none", "file": rel, "percent": percent, "max_steps": max_steps}
    )
    url = f"http://127.0.0.1:{server.server_port}/index.html?{query}"
    profile = tempfile.mkdtemp(prefix="os-chromium-")
    cmd = [exe, "--headless=new", "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
           "--no-sandbox", "--disable-extensions", "--no-first-run", "--mute-audio",
           "--disable-background-networking", "--window-size=320,240",
           f"--user-data-dir={profile}", url]  # fmt: skip
    proc = subprocess.Popen(
        cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True
    )
    try:
        if not state["event"].wait(timeout):
            raise RuntimeError(f"Origami Simulator did not answer within {timeout:.0f} s")
    finally:
        try:
            os.killpg(proc.pid, signal.SIGTERM)  # the group of the process started here
        except ProcessLookupError:
            pass
        try:
            proc.wait(10)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
        server.shutdown()
        server.server_close()
        shutil.rmtree(profile, ignore_errors=True)
    res = state["result"]
    if "error" in res:
        raise RuntimeError(f"Origami Simulator: {res['error']} ({'; '.join(res['warnings'])})")
    return res


def os_arrays(res: dict) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Origami Simulator's flat (n, 2) layout (its x and z), folded (n, 3) positions and
    (m, 3) triangles, in its units."""
    flat3 = np.asarray(res["flat"], float)
    X = np.asarray(res["positions"], float).reshape(-1, 3)
    return flat3[:, [0, 2]], X, np.asarray(res["faces"], np.intp)


def os_strain(res: dict) -> float:
    """Largest |length / flat length - 1| over the edges of Origami Simulator's triangles."""
    flat3 = np.asarray(res["flat"], float)
    X = np.asarray(res["positions"], float).reshape(-1, 3)
    T = np.asarray(res["faces"], np.intp)
    E = np.unique(np.sort(np.concatenate([T[:, [0, 1]], T[:, [1, 2]], T[:, [2, 0]]]), 1), axis=0)
    L0 = np.linalg.norm(flat3[E[:, 0]] - flat3[E[:, 1]], axis=1)
    L = np.linalg.norm(X[E[:, 0]] - X[E[:, 1]], axis=1)
    return float(np.max(np.abs(L / L0 - 1.0)))


def _normalised(flat: np.ndarray) -> tuple[np.ndarray, float]:
    lo, hi = flat.min(0), flat.max(0)
    side = float((hi - lo).max())
    return (flat - (lo + hi) / 2) / side, side


_DIHEDRAL = [np.array(m, float) for m in (
    [[1, 0], [0, 1]], [[-1, 0], [0, 1]], [[1, 0], [0, -1]], [[-1, 0], [0, -1]],
    [[0, 1], [1, 0]], [[0, -1], [1, 0]], [[0, 1], [-1, 0]], [[0, -1], [-1, 0]],
)]  # fmt: skip


def match_vertices(flat_a: np.ndarray, flat_b: np.ndarray, tol: float = 1e-4) -> list:
    """Candidate pairings (i, j) of the vertices of two flat layouts (n, 2): both centred on
    their bounding box and scaled to largest side 1, ``b`` turned by each of the 8 axis flips /
    quarter turns, mutual nearest neighbours within ``tol`` (vertices that share their flat
    place with another, split along a cut, left out); every turn that matches the most
    vertices (several for a symmetric sheet)."""
    A, _ = _normalised(flat_a)
    B0, _ = _normalised(flat_b)
    # vertices split along a cut share a flat position: ambiguous, left out
    lone_a = np.array([len(x) == 1 for x in cKDTree(A).query_ball_point(A, tol)])
    lone_b = np.array([len(x) == 1 for x in cKDTree(B0).query_ball_point(B0, tol)])
    found = []
    for M in _DIHEDRAL:
        B = B0 @ M.T
        da, ja = cKDTree(B).query(A)
        _, ib = cKDTree(A).query(B)
        ok = (da < tol) & (ib[ja] == np.arange(len(A))) & lone_a & lone_b[ja]
        i = np.flatnonzero(ok)
        found.append((i, ja[i]))
    most = max(len(i) for i, _ in found)
    return [(i, j) for i, j in found if len(i) == most]


def kabsch_distances(P: np.ndarray, Q: np.ndarray) -> tuple[np.ndarray, bool]:
    """Distances between matched points P and Q (n, 3) after the best rigid motion of Q onto
    P (a reflection allowed), and whether a reflection was used."""
    p, q = P - P.mean(0), Q - Q.mean(0)
    U, _, Vt = np.linalg.svd(q.T @ p)
    best = None
    for s in (1.0, -1.0):
        R = U @ np.diag([1.0, 1.0, s]) @ Vt
        d = np.linalg.norm(q @ R - p, axis=1)
        if best is None or np.sqrt(np.mean(d**2)) < np.sqrt(np.mean(best[0] ** 2)) - 1e-15:
            best = (d, np.linalg.det(R) < 0)
    return best


def shape_distance(flat_h, X_h, flat_o, X_o) -> dict:
    """Largest and RMS distance, % of the sheet size (largest side of the flat bounding box),
    between two folded states whose vertices are matched by flat position (of several
    pairings of a symmetric sheet, the one with the smallest RMS distance)."""
    _, side_h = _normalised(flat_h)
    _, side_o = _normalised(flat_o)
    best = None
    for i, j in match_vertices(flat_h, flat_o):
        if len(i) < 3:
            raise ValueError(f"only {len(i)} vertices match by flat position")
        d, mirror = kabsch_distances(X_h[i] / side_h, X_o[j] / side_o)
        rms = float(np.sqrt(np.mean(d**2)))
        if best is None or rms < best["rms_pct"] / 100 - 1e-15:
            best = {
                "matched": int(len(i)),
                "of": (len(flat_h), len(flat_o)),
                "max_pct": 100 * float(d.max()),
                "rms_pct": 100 * rms,
                "mirror": bool(mirror),
            }
    return best


def fold_holofold(path: Path, fractions, limit: float = 300.0):
    """holofold's folds of ``path`` (scaled to 200 mm, PP section): {fraction: (flat (n, 2),
    coords (n, 3), verdict, clean)}; one fold to the largest fraction, the smaller ones taken
    from its path where it passes through them exactly, else folded on their own."""
    from holofold.geometry import read_pattern
    from holofold.mechanics import fold_pattern, scaled_pattern
    from holofold.mechanics.intersection import intersecting_faces

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        p = read_pattern(path)
    p = scaled_pattern(p, SIZE / float(np.ptp(p.flat, axis=0).max()))
    out = {}
    results = {}
    for f in sorted(fractions, reverse=True):
        r = next((r for r in results.values() if np.any(np.abs(r.fractions - f) < 1e-9)), None)
        if r is None:
            r = fold_pattern(p, f, time_limit=limit, **SECTION)
            results[f] = r
        k = np.flatnonzero(np.abs(r.fractions - f) < 1e-9)
        if k.size:
            X = r.coords[k[0]]
            crossed = len(intersecting_faces(X, p.faces)) > 0
            last = k[0] == len(r.fractions) - 1
            verdict = r.verdict if last else "passes (on the path to " + f"{r.requested:g})"
            wrong = bool(r.wrong_at <= f + 1e-12)  # NaN: never
            clean = (r.verdict in CLEAN_VERDICTS or not last) and not crossed and not wrong
            if crossed:
                verdict += "; faces intersect"
            if wrong and not last:
                verdict += f"; a crease turned against its assignment at {100 * r.wrong_at:.0f} %"
            out[f] = (p.flat, X, verdict, clean)
        else:
            out[f] = (p.flat, r.coords[-1], f"{r.verdict} at {100 * r.reached:.0f} %", False)
    return out


def compare(app: Path, file: str | Path, fractions, *, chromium=None, limit=300.0,
            os_timeout=600.0, save_os: Path | None = None):  # fmt: skip
    """One row per fraction for one file (``file`` under ``app/assets`` or on disk)."""
    from holofold.mechanics.intersection import intersecting_faces

    path = Path(file) if Path(file).is_file() else app / "assets" / file
    rows = []
    try:
        hf = fold_holofold(path, fractions, limit)
    except (ValueError, RuntimeError, ArithmeticError) as exc:
        hf = {f: None for f in fractions}
        herr = f"{type(exc).__name__}: {exc}"
    for f in fractions:
        row = {"file": str(file), "fraction": f}
        if hf[f] is None:
            row.update(holofold=herr, holofold_clean=False)
        else:
            flat_h, X_h, verdict, clean = hf[f]
            row.update(holofold=verdict, holofold_clean=bool(clean))
        try:
            saved = save_os / f"{path.stem}-{round(100 * f)}.json" if save_os else None
            if saved is not None and saved.is_file():  # an earlier run's
                res = json.loads(saved.read_text(encoding="utf-8"))
            else:
                res = run_origami_simulator(app, path if Path(file).is_file() else file, f,
                                            chromium=chromium, timeout=os_timeout)  # fmt: skip
                if saved is not None:
                    save_os_result(res, saved, str(file), f)
            flat_o, X_o, T_o = os_arrays(res)
            strain = os_strain(res)
            crossed = len(intersecting_faces(X_o, T_o))
            row.update(
                os_steps=res["steps"], os_settled=res["settled"], os_strain_pct=100 * strain,
                os_crossing=crossed,
                os_clean=bool(res["settled"] and strain <= STRAIN_CLEAN and crossed == 0),
            )  # fmt: skip
        except (RuntimeError, ValueError) as exc:
            row.update(os_error=str(exc), os_clean=False)
            rows.append(row)
            continue
        if hf[f] is not None:
            try:
                row.update(shape_distance(flat_h, X_h, flat_o, X_o))
            except ValueError as exc:
                row["note"] = str(exc)
        rows.append(row)
    return rows


def save_os_result(res: dict, out: Path, source: str, fraction: float) -> None:
    """Origami Simulator's result, rounded to 1e-7 of its unit (float32 precision)."""
    data = {
        "source": f"Origami Simulator (MIT), assets/{source}, folded to {100 * fraction:g} % by "
        "validation/origami_simulator_compare.py (headless Chromium, SwiftShader WebGL)",
        "fraction": fraction,
        "steps": res["steps"],
        "settled": res["settled"],
        "last_move": res["last_move"],
        "flat": np.round(np.asarray(res["flat"], float), 7).tolist(),
        "positions": np.round(np.asarray(res["positions"], float), 7).tolist(),
        "faces": res["faces"],
    }
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps(data, separators=(",", ":")) + "\n", encoding="utf-8")


def _f(v, nd=2):
    return "-" if v is None or v == "" else (f"{v:.{nd}f}" if isinstance(v, float) else str(v))


def table(rows: list[dict]) -> str:
    out = [
        "| file | fraction | holofold verdict | holofold clean | OS steps | OS settled | "
        "OS max strain % | OS crossing pairs | OS clean | matched | max % | RMS % | mirror |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        os_ = (f"error: {r['os_error']}", "-", "-", "-", "no") if "os_error" in r else (
            r["os_steps"], r["os_settled"], _f(r["os_strain_pct"], 3), r["os_crossing"],
            "yes" if r["os_clean"] else "no")  # fmt: skip
        out.append(
            f"| {r['file']} | {r['fraction']:g} | {r['holofold']} | "
            f"{'yes' if r['holofold_clean'] else 'no'} | {os_[0]} | {os_[1]} | {os_[2]} | "
            f"{os_[3]} | {os_[4]} | {r.get('matched', '-')} | {_f(r.get('max_pct'))} | "
            f"{_f(r.get('rms_pct'))} | {r.get('mirror', '-')} |"
        )
    return "\n".join(out)


def summary(rows: list[dict]) -> str:
    """Totals: how many comparisons both tools fold cleanly, how many of them within 1 %;
    the same with Origami Simulator's crossing test left out (its flat-folded states stack
    layers at zero distance, where float32 round-off reads as crossing)."""

    def line(sel: list[dict], what: str) -> str:
        within = [r for r in sel if r["max_pct"] <= 1.0]
        s = f"{what}: {len(sel)}; of them within 1 % of the sheet size (largest distance): "
        s += f"{len(within)}"
        if sel:
            worst = max(sel, key=lambda r: r["max_pct"])
            s += f"; worst {worst['max_pct']:.2f} % ({worst['file']} at {worst['fraction']:g})"
        return s

    compared = [r for r in rows if "max_pct" in r]
    both = [r for r in compared if r["holofold_clean"] and r["os_clean"]]
    loose = [
        r for r in compared
        if r["holofold_clean"] and r["os_settled"] and r["os_strain_pct"] <= 100 * STRAIN_CLEAN
    ]  # fmt: skip
    return "\n".join([
        f"{len(rows)} comparisons ({len({r['file'] for r in rows})} files)",
        line(both, "both fold cleanly"),
        line(loose, "both fold cleanly, Origami Simulator's crossing test left out"),
    ])  # fmt: skip


def straight_files(app: Path, only: str = "") -> list[str]:
    assets = app / "assets"
    files = sorted(
        p.relative_to(assets).as_posix()
        for p in assets.rglob("*")
        if p.suffix.lower() in (".svg", ".fold")
    )
    return [f for f in files if only in f and not f.startswith(CURVED)]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("app", type=Path, help="Origami Simulator's app folder (index.html, assets/)")
    ap.add_argument("--only", default="", help="only files whose path contains this")
    ap.add_argument("--files", nargs="*", help="these files (under assets/) instead")
    ap.add_argument("--fractions", nargs="+", type=float, default=[0.5, 1.0])
    ap.add_argument("--limit", type=float, default=300.0, help="holofold: seconds per fold")
    ap.add_argument("--os-timeout", type=float, default=600.0, help="seconds per OS run")
    ap.add_argument("--chromium", help="Chromium executable")
    ap.add_argument("--json", type=Path, help="append every row to this JSON-lines file")
    ap.add_argument(
        "--save-os", type=Path,
        help="write Origami Simulator's results here (and reuse those already there)",
    )  # fmt: skip
    ap.add_argument("--from-json", type=Path, help="only print the table of these rows")
    args = ap.parse_args(argv)
    if args.from_json:
        rows = [json.loads(x) for x in args.from_json.read_text(encoding="utf-8").splitlines()]
        print(table(rows) + "\n\n" + summary(rows))
        return 0
    if find_chromium(args.chromium) is None:
        print("no Chromium found (give --chromium or set $CHROMIUM)", file=sys.stderr)
        return 2
    files = args.files or straight_files(args.app, args.only)
    rows = []
    for f in files:
        t0 = time.perf_counter()
        new = compare(args.app, f, args.fractions, chromium=args.chromium, limit=args.limit,
                      os_timeout=args.os_timeout, save_os=args.save_os)  # fmt: skip
        rows += new
        for r in new:
            print(json.dumps(r, default=str), file=sys.stderr, flush=True)
            if args.json:
                with open(args.json, "a", encoding="utf-8") as fh:
                    fh.write(json.dumps(r, default=str) + "\n")
        print(f"{f}: {time.perf_counter() - t0:.0f} s", file=sys.stderr, flush=True)
    print(table(rows))
    print()
    print(summary(rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
