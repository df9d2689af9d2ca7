import math

import pytest

from holofold.geometry.errors import ParameterError, check_range


def test_check_range_accepts_and_returns_float():
    assert check_range("ext", 1, 0, 1, low_open=True) == 1.0


@pytest.mark.parametrize(
    "value, kw, fragment",
    [
        (0.0, dict(low=0, high=1, low_open=True), "ext = 0.0 is outside the allowed range (0, 1]"),
        (1.2, dict(low=0, high=1, low_open=True), "(0, 1]"),
        (math.nan, dict(low=0, high=1), "must be finite"),
        ("abc", dict(low=0), "must be a number"),
    ],
)
def test_check_range_names_argument_and_range(value, kw, fragment):
    with pytest.raises(ParameterError, match="ext") as exc:
        check_range("ext", value, **kw)
    assert fragment in str(exc.value)
    assert isinstance(exc.value, ValueError)


def test_atomically_written_files_get_normal_permissions(tmp_path):
    import os

    from holofold.geometry import write_text

    old = os.umask(0o022)
    try:
        p = write_text(tmp_path / "a.txt", "x")
    finally:
        os.umask(old)
    assert p.stat().st_mode & 0o777 == 0o644  # not mkstemp's 0600
    assert not list(tmp_path.glob(".holofold-*"))
