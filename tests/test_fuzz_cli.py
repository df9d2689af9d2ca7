"""Fuzzing the command line: generated argument lists give a result or one clear error line,
never a traceback and never a hang (issue 15, section 6).

Every case runs ``holofold.cli.main(argv)`` in this process under a 30 s alarm. It passes when
``main`` returns 0 or 2 (or argparse exits with 2 after its usage line) and, on an error, the
last line of stderr is the command's one-line ``holofold CMD: error: ...`` (or argparse's
``holofold CMD: error: ...``). Values come from pools of valid, boundary and malformed values:
huge sizes, NaN, negative numbers, text, missing files, empty, binary and malformed files.
"""

from __future__ import annotations

import contextlib
import io
import json
import signal

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from holofold.cli import main

ALARM = 30  # s: a case running longer is a hang


class Hang(Exception):
    pass


def _files(folder):
    """Input files of every kind a user might pass by mistake, or on purpose."""
    f = {}

    def put(name, data):
        p = folder / name
        p.write_bytes(data if isinstance(data, bytes) else data.encode())
        f[name] = str(p)

    put("designs.csv", "tcrease,tpanel,W,gama\n8e-4,3e-3,2e-3,1.2\n6e-4,2e-3,3e-3,1.0\n")
    put(
        "arch.csv",
        "m,tcrease,tpanel,W,offset,stripeWidth,extrude\n12,8e-4,3e-3,2e-3,0.2,0.02,0.1\n",
    )
    put("ragged.csv", "a,b\n1,2,3\n")
    put("dup.csv", "tpanel,tpanel\n1,2\n")
    put("empty.csv", "")
    put("binary.csv", bytes(range(256)))
    put("nan.csv", "tcrease,tpanel,W,gama\nnan,inf,-1,1e300\n")
    put("points.csv", "0,0\n1,1\n2,0\n")
    put("one_point.csv", "0,0\n")
    put("rules.json", json.dumps([{"rule": "r", "bounds": {"W": {"gt": 0.002, "le": None}}}]))
    put("bad_rules.json", json.dumps([{"bounds": [1, 2]}, {"bounds": {"W": {"in": 3}}}]))
    put("notjson.json", "{nope")
    put("nan_rules.json", '[{"bounds": {"W": {"gt": NaN}}}]')
    strip = 'kind = "strip"\n[curve]\nbuiltin = "parabola"\n[[load]]\nname = "V"\nat = 0.5\n'
    put("s.toml", strip + "direction = [0, 0, -1]\nforce = 1.0\n[features]\nm = {choices = [8]}\n")
    put("bad.toml", "kind = [\n")
    put("weird.toml", 'kind = "sheet"\n[sheet]\nsize_x = -1\n')
    svg = '<svg xmlns="http://www.w3.org/2000/svg">'
    put("d.svg", svg + '<path id="p" d="M0 0 C 10 -20 30 -20 40 0"/></svg>')
    put("bad.svg", "<svg><path d='M 0 0 Q'/></svg>")
    put("deep.svg", "<svg>" + "<g>" * 3000 + "</g>" * 3000 + "</svg>")
    put("data.txt", "1,2,3\n4,5,6\n")
    import numpy as np

    rng = np.random.default_rng(0)
    x = rng.uniform([5e-4, 1e-3, 1e-3, 0.9], [1e-3, 6e-3, 4e-3, 1.4], (80, 4))
    stiff = 2e6 * x[:, 1] * (1.5 - x[:, 3])  # 200-7200 N/m: the target > 3000 splits the rows
    lines = ["tcrease,tpanel,W,gama,axialstiff30,axialstiff60,axialstiff90"]
    lines += [
        ",".join(f"{v:.6g}" for v in (*r, 2 * k, k, k / 2)) for r, k in zip(x, stiff, strict=True)
    ]
    put("db.csv", "\n".join(lines) + "\n")
    put("bad.parquet", b"PAR1garbage")
    # sizes that used to hang or recurse: each must be refused by a limit before any work
    put("canopy_huge.csv", "pattern,m,n,tcrease,tpanel,W\n1,1000000,6,8e-4,3e-3,2e-3\n")
    put("canopy_huge_n.csv", "pattern,m,n,tcrease,tpanel,W\n1,24,99999999,8e-4,3e-3,2e-3\n")
    put("arch_huge.csv", "m,tcrease,tpanel,W,offset,stripeWidth,extrude\n"
        "100000,8e-4,3e-3,2e-3,0.2,0.02,0.1\n")  # fmt: skip
    put("deep.fold", "[" * 1000 + "]" * 1000)
    put("huge_index.fold", '{"vertices_coords": [[0, 0], [1, 0]], "edges_vertices": '
        '[[0, 1000000000000000000000000000000]], "faces_vertices": []}')  # fmt: skip
    put("deeper.svg", "<svg>" + "<g>" * 50_000 + "</g>" * 50_000 + "</svg>")
    return f


def _values(files, tmp):
    sizes = st.sampled_from(
        [
            "1",
            "2",
            "3",
            "0",
            "-1",
            "1e9",
            "2.5",
            "abc",
            "",
            "nan",
            "99999999999999999999",
            "8",
            "12",
            "-3",
        ]
    )
    # sizes whose work grows without bound: each must be refused by a limit before any work
    huge = st.sampled_from(["100000", "1000000", "100000000"])  # fmt: skip
    reals = st.sampled_from(["0.1", "0.02", "0", "-1", "nan", "inf", "1e300", "1e-300", "x", "1,2",
                             "0.2", "5", "90", "-0"])  # fmt: skip
    paths = st.sampled_from([*files.values(), str(tmp / "missing.csv"), str(tmp), "/dev/null",
                             str(tmp / "out" / "deep" / "x.csv")])  # fmt: skip
    outs = st.sampled_from([str(tmp / "o1"), str(tmp / "o2.csv"), str(tmp / "o3.parquet"),
                            str(tmp / "o4.json"), str(tmp / "nodir" / "o.csv"), files["empty.csv"],
                            str(tmp / "o5.txt"), str(tmp / "plot.png")])  # fmt: skip
    targets = st.sampled_from(["Zstiff > 10", "axialstiff60 < 6000", "Zstiff >", "((((", "x > 1",
                               "Zstiff > 1 & error < 0.1", "(" * 300 + "Zstiff > 1" + ")" * 300,
                               "axialstiff30 > 1e999", "", "Vstiff > 1"])  # fmt: skip
    scen = st.sampled_from(["single-miura", "arch", "canopy", "gripper", "nope", files["s.toml"],
                            files["bad.toml"], files["weird.toml"],
                            str(tmp / "missing.toml")])  # fmt: skip
    return sizes, huge, reals, paths, outs, targets, scen


def _argv(draw, files, tmp):
    """A valid command line of one command with 1-3 of its arguments replaced, added or
    dropped (so that each bad value is met on its own, not behind another one)."""
    sizes, huge, reals, paths, outs, targets, scen = _values(files, tmp)
    grow = st.one_of(sizes, huge)
    curves = st.sampled_from(["half-circle:radius=2", "parabola:span=4,height=1", "nope",
                              "half-circle:radius=-1", files["points.csv"], files["one_point.csv"],
                              files["d.svg"], files["d.svg"] + "#p", files["d.svg"] + "#q",
                              files["bad.svg"], files["deep.svg"], files["deeper.svg"],
                              files["binary.csv"]])  # fmt: skip
    ranges = st.sampled_from(["W=0.001:0.002", "W=2:1", "nope=1:2", "W", "gama=1:1.2",
                              "W=nan:1", "W=0.001,0.002"])  # fmt: skip
    out = str(tmp / "out")
    # (valid base command line, pools of every argument: positionals are "0", "1")
    spec = {
        "fit": ({"--curve": "half-circle:radius=2", "--m": "8", "--offset": "0.2",
                 "--strip-width": "0.02", "--extrude": "0.1", "-o": out},
                {"--curve": curves, "--m": grow, "--offset": reals, "--strip-width": reals,
                 "--extrude": reals, "--auto": None, "--tolerance": reals,
                 "--m-range": st.sampled_from(["4:12", "12:4", "1:100000", "a:b", "8"]),
                 "--panel-thickness": reals, "--crease-width": reals, "-o": outs}),
        "pattern": ({"0": "miura", "--m": "4", "--n": "4", "--ext": "0.6", "--gamma": "60",
                     "--a": "0.02", "--b": "0.02", "-o": out},
                    {"0": st.sampled_from(["miura", "tmp", "nope"]), "--m": grow, "--n": grow,
                     "--ext": reals, "--gamma": reals, "--a": reals, "--b": reals,
                     "--size": reals, "--thickness": reals, "--crease-width": reals, "-o": outs}),
        "evaluate": ({"0": "single-miura", "1": files["designs.csv"], "-o": str(tmp / "r.csv")},
                     {"0": scen, "1": paths, "-o": outs, "--workers": sizes}),
        "generate": ({"0": "single-miura", "-n": "3", "-o": out},
                     {"0": scen, "-n": sizes, "-o": outs, "--seed": sizes, "--range": ranges,
                      "--chunk-size": sizes, "--method": st.sampled_from(["lhs", "grid"])}),
        "mine": ({"0": files["db.csv"], "--target": "axialstiff60 > 3000"},
                 {"0": paths, "--target": targets, "--trees": grow, "--depth": grow,
                  "--rules": sizes, "--min-support": sizes, "--precision-min": reals,
                  "--json": outs, "--plot": outs, "--test-size": reals}),
        "verify": ({"0": "single-miura", "--rules": files["rules.json"],
                    "--target": "axialstiff60 > 3000", "-n": "2"},
                   {"0": scen, "--rules": paths, "--target": targets, "-n": sizes,
                    "--top": sizes, "-o": outs}),
        "design": ({"0": "single-miura", "--target": "axialstiff60 > 3000", "-o": out,
                    "-n": "20", "--verify": "2", "--top": "1", "--workers": "1"},
                   {"0": scen, "--target": targets, "-o": outs, "-n": sizes, "--rounds": sizes,
                    "--budget": sizes, "--verify": sizes, "--top": sizes, "--db": paths}),
        "scenarios": ({"0": "show", "1": "arch"},
                      {"0": st.sampled_from(["list", "show", "nope"]),
                       "1": st.sampled_from(["arch", "canopy", "x", ""])}),
        "demo": ({"-n": "5", "-o": out},
                 {"-n": sizes, "--verify": sizes, "--target": targets, "--workers": sizes,
                  "--rounds": sizes, "-o": outs}),
    }  # fmt: skip
    cmd = draw(st.sampled_from(sorted(spec)))
    base, pools = spec[cmd]
    args = dict(base)
    for _ in range(draw(st.integers(1, 3))):
        key = draw(st.sampled_from(sorted(pools)))
        if pools[key] is None:
            args[key] = None
        elif draw(st.integers(0, 9)) == 0 and key in args:
            del args[key]
        else:
            args[key] = draw(pools[key])
    if cmd == "demo":  # the whole demo is a minute of real work: only its refusals here
        args["-n"] = draw(st.sampled_from(["5", "0", "-1", "x", "99999999999999999999"]))
    argv = [cmd] + [args[k] for k in ("0", "1") if k in args]
    for k, v in args.items():
        if k not in ("0", "1"):
            argv += [k] if v is None else [k, v]
    return argv


def _run(argv) -> tuple[int | None, str, str]:
    out, err = io.StringIO(), io.StringIO()

    def alarm(signum, frame):
        raise Hang(" ".join(argv))

    old = signal.signal(signal.SIGALRM, alarm)
    signal.alarm(ALARM)
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            try:
                code = main(argv)
            except SystemExit as exc:  # argparse
                code = exc.code
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)
    return code, out.getvalue(), err.getvalue()


def _check(argv, code, err):
    """Exit 0, or exit 2 with the command's error line (argparse's or holofold's); ``design``
    also exits 1 when its answer is the nearest design, which misses the target."""
    assert code in ((0, 1, 2) if argv[:1] == ["design"] else (0, 2)), (argv, code, err[-2000:])
    assert "Traceback" not in err, (argv, err[-2000:])
    if code == 2:
        heads = (f"holofold {argv[0]}: error: ", "holofold: error: ")
        if len(argv) > 1:  # a command with sub-commands (pattern KIND)
            heads += (f"holofold {argv[0]} {argv[1]}: error: ",)
        assert any(line.startswith(heads) for line in err.splitlines()), (argv, err[-2000:])


@pytest.fixture
def inputs(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # default output folders land here, not in the checkout
    return _files(tmp_path), tmp_path


def _fuzz(inputs, n):
    files, tmp = inputs

    @settings(max_examples=n, deadline=None, derandomize=True, database=None,
              suppress_health_check=list(HealthCheck))  # fmt: skip
    @given(st.data())
    def case(data):
        argv = _argv(data.draw, files, tmp)
        code, _, err = _run(argv)
        _check(argv, code, err)

    case()


@pytest.mark.parametrize(
    "argv",
    [
        ["mine", "db.csv", "--target", "axialstiff60 > 3000", "--trees", "1000000"],
        ["mine", "db.csv", "--target", "axialstiff60 > 3000", "--trees", "100000"],
        ["mine", "db.csv", "--target", "axialstiff60 > 3000", "--depth", "99999999999999999999"],
        ["mine", "db.csv", "--target", "axialstiff60 > 3000", "--jobs", "100000"],
        ["evaluate", "canopy", "canopy_huge.csv", "-o", "r.csv"],
        ["evaluate", "canopy", "canopy_huge_n.csv", "-o", "r.csv"],
        ["evaluate", "arch", "arch_huge.csv", "-o", "r.csv"],
        ["fit", "--curve", "deeper.svg", "--m", "8", "--offset", "0.2", "--strip-width", "0.02",
         "--extrude", "0.1", "-o", "out"],
        ["evaluate", "single-miura", "deep.fold", "-o", "r.csv"],
    ],
    ids=["trees-1e6", "trees-1e5", "depth-1e20", "jobs-1e5", "canopy-m-1e6", "canopy-n-1e8",
         "arch-m-1e5", "svg-50000-groups", "fold-as-table"],
)  # fmt: skip
def test_former_hangs_and_recursions_are_one_clear_line(inputs, argv):
    """The cases of the issue that hung or raised RecursionError, each on its own: exit 2 with
    one error line within a few seconds."""
    files, _ = inputs
    argv = [files.get(a, a) for a in argv]
    code, _, err = _run(argv)
    _check(argv, code, err)
    assert code == 2, (argv, err[-2000:])


def test_cli_fuzz_fast_subset(inputs):
    _fuzz(inputs, 150)


@pytest.mark.slow
def test_cli_fuzz_800_cases(inputs):
    """Measured on 2026-12-01: 800 cases, 662 clear errors, 138 results, 0 tracebacks, 0 hangs.
    Again after the limits of docs/limits.md, with db.csv's stiffness scaled so that the mine
    target splits its rows (before, every mine case stopped at 'met by 0 of 80 rows' and no
    forest was trained): 800 cases, 694 clear errors, 106 results, 0 tracebacks, 0 hangs, 55 s."""
    _fuzz(inputs, 800)
