"""SVG curve files that are deep, huge or ambiguous (issue 15, sections 3 and 6): one line of
the curve error, never a RecursionError, and never several lines silently joined."""

from __future__ import annotations

import warnings

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from holofold.fitting import (
    MAX_SVG_NESTING,
    CurveError,
    CurveSelectionWarning,
    read_svg_curve,
)

HEAD = '<svg xmlns="http://www.w3.org/2000/svg">'


def _write(tmp_path, body, name="d.svg"):
    f = tmp_path / name
    f.write_text(HEAD + body + "</svg>")
    return f


def _refused(ref, match):
    with pytest.raises(CurveError, match=match) as info:
        read_svg_curve(ref, check_size=False)
    assert "\n" not in str(info.value)
    return str(info.value)


@pytest.mark.parametrize("depth", [50_000, 3000, MAX_SVG_NESTING])
def test_deeply_nested_groups_are_one_line_of_the_curve_error(tmp_path, depth):
    path = '<path id="p" d="M 0 0 C 10 -20 30 -20 40 0"/>'
    f = _write(tmp_path, "<g>" * depth + path + "</g>" * depth)  # 50 000 levels: 350 kB
    msg = _refused(f"{f}#p", rf"nested over {MAX_SVG_NESTING} deep \(line 1, <g>\)")
    assert msg.startswith(f"cannot read SVG file {str(f)!r}")


def test_nesting_within_the_limit_reads(tmp_path):
    depth = MAX_SVG_NESTING - 2  # <svg> and the <path> are levels too
    f = _write(tmp_path, "<g>" * depth + '<path d="M 0 0 L 1 1"/>' + "</g>" * depth)
    assert read_svg_curve(f, check_size=False).length == pytest.approx(2**0.5, rel=1e-9)


def test_deep_nesting_in_a_deep_stack_is_the_curve_error(tmp_path):
    depth = MAX_SVG_NESTING - 2
    f = _write(tmp_path, "<g>" * depth + '<path d="M 0 0 L 1 1"/>' + "</g>" * depth)

    def nest(n):
        if n == 0:
            try:
                read_svg_curve(f, check_size=False)
            except CurveError as exc:  # the recursion limit reached: converted
                assert "nested too deeply" in str(exc) or "recursion" in str(exc)
            return
        nest(n - 1)

    nest(900)


def test_disjoint_subpaths_are_refused_with_how_to_select_one(tmp_path):
    d = " ".join(f"M {3 * i} 0 L {3 * i + 1} 1" for i in range(2000))
    f = _write(tmp_path, f'<path id="many" d="{d}"/>')
    msg = _refused(f, r"SVG path 'd' has 2000 subpaths \(M commands\)")
    assert "file.svg#id" in msg


def test_several_paths_without_an_id_warn_and_name_the_ids(tmp_path):
    f = _write(tmp_path, "".join(f'<path id="p{i}" d="M {i} 0 L {i + 1} 1"/>' for i in range(2000)))
    with pytest.warns(CurveSelectionWarning, match=r"has 2000 paths \(ids p0, p1, p2, p3, p4, "
                      r"\.\.\.\); read the first \('p0'\): choose one with d\.svg#id"):  # fmt: skip
        c = read_svg_curve(f, check_size=False)
    assert c.length == pytest.approx(2**0.5, rel=1e-9)  # p0 alone, not the 2000 joined
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert read_svg_curve(f"{f}#p7", check_size=False).length == pytest.approx(2**0.5)


def test_not_xml_and_missing_files(tmp_path):
    f = tmp_path / "bad.svg"
    f.write_bytes(b"<svg><path d='M 0 0 L 1 1'/>")
    _refused(f, r"not well-formed XML: no element found \(line 1, column 28\)")
    f.write_bytes(bytes(range(256)))
    _refused(f, "not well-formed XML")
    _refused(tmp_path / "missing.svg", r"SVG file .*missing.svg' does not exist")
    _refused(tmp_path, r"SVG file .* is a folder, not a file")  # named as what it is


TAGS = ["<g>", "</g>", "<svg>", "</svg>", '<path d="M 0 0 L 1 1"/>', '<path id="a" d="M 0 0"/>',
        '<path d="M 0 0 Q"/>', '<path d="M 0 0 L 1 1 M 2 2 L 3 3"/>', '<circle r="1"/>',
        '<line x2="1" y2="1"/>', "<rect/>", 'transform="scale(0)"', "&amp;", "&nope;", "<", ">",
        '<g transform="scale(1e308)">', '<path d="M 0 0 L 1e400 1"/>',
        '<path d="M nan 0"/>']  # fmt: skip


@settings(
    max_examples=200, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(st.lists(st.sampled_from(TAGS), max_size=20), st.sampled_from(["", "#a", "#b"]))
def test_any_tag_soup_gives_a_curve_or_the_curve_error(tmp_path, tags, ref):
    f = tmp_path / "fuzz.svg"
    f.write_text(HEAD + "".join(tags) + "</svg>")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            read_svg_curve(f"{f}{ref}")
        except CurveError as exc:
            assert "\n" not in str(exc)


# ---------------------------------------------------------------- expansion (issue 23 item 4)
def _doubling(levels: int) -> str:
    """<use> doubling: level i uses level i-1 twice, so the last level is 2^levels paths."""
    defs = ['<path id="l0" d="M0,0 L1,1"/>']
    defs += [f'<g id="l{i}"><use href="#l{i - 1}"/><use xlink:href="#l{i - 1}" '
             'transform="translate(1,0)"/></g>' for i in range(1, levels + 1)]  # fmt: skip
    return (
        '<svg xmlns="http://www.w3.org/2000/svg" xmlns:xlink="http://www.w3.org/1999/xlink">'
        f'<defs>{"".join(defs)}</defs><use href="#l{levels}"/>'
        '<path id="arc" d="M 0 0 C 10 -20 30 -20 40 0"/></svg>'
    )


def test_a_use_doubling_bomb_is_refused_in_one_line_within_a_second(tmp_path, capsys):
    from holofold.cli import main

    f = tmp_path / "bomb.svg"
    f.write_text(_doubling(25))
    assert f.stat().st_size < 2500  # 2 kB that svgelements would expand to 2^25 elements
    # refused from a count before expanding (2^25 elements would take minutes and GiBs)
    _refused(f"{f}#arc", r"over 20,000 elements once its <use> references are expanded")
    # the commands that read curves: one line, exit 2
    assert main(["fit", "--curve", f"{f}#arc", "--m", "8", "--offset", "0.2", "--strip-width",
                 "0.02", "--extrude", "0.1", "-o", str(tmp_path / "fit")]) == 2  # fmt: skip
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "references are expanded" in err


def test_expansion_within_the_limits_reads_and_cycles_are_refused(tmp_path):
    f = tmp_path / "ok.svg"
    f.write_text(_doubling(8))  # 256 copies: a drawing may use <use>
    assert read_svg_curve(f"{f}#arc", check_size=False).length > 0
    f = _write(tmp_path, '<g id="a"><use href="#b"/></g><g id="b"><use href="#a"/></g>'
               '<path id="p" d="M 0 0 L 1 1"/>', "cycle.svg")  # fmt: skip
    _refused(f"{f}#p", r"refers to itself \(a reference cycle\)")


def test_path_points_after_expansion_are_bounded(tmp_path):
    from holofold.fitting import MAX_SVG_POINTS

    d = "M0,0 " + " ".join(f"L{i},{i % 3}" for i in range(1, 2001))  # 2001 points
    body = f'<defs><path id="long" d="{d}"/></defs>' + '<use href="#long"/>' * 120
    f = _write(tmp_path, body + '<path id="p" d="M 0 0 L 1 1"/>', "long.svg")
    msg = _refused(f"{f}#p", r"path points once its <use> references are expanded")
    assert f"at most {MAX_SVG_POINTS:,}" in msg
