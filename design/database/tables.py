"""Tables of designs and performances: the one reader and writer, and what columns mean.

:func:`read_table` reads CSV / Parquet with a header, or the published headerless
comma-separated ``.txt`` files of Zhu & Filipov (2022) whose column names live in a sibling
``dataN_FeatureName.txt``; :func:`write_table` writes CSV or Parquet atomically (a temporary
file in the same folder, then a rename); :func:`column_roles` tells design features from
performance columns (a holofold database's ``meta.json``, or the published column sets).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from holofold.geometry.inputs import check_input_file
from holofold.geometry.outputs import atomic_write, check_output_path

__all__ = [
    "ColumnRoles",
    "PUBLISHED",
    "TABLE_SUFFIXES",
    "read_table",
    "write_table",
    "check_table_path",
    "column_roles",
    "table_columns",
    "feature_name_file",
]

#: suffixes :func:`write_table` writes (and :func:`read_table` reads, with .txt / .dat)
TABLE_SUFFIXES = (".csv", ".parquet", ".pq")


@dataclass(frozen=True)
class ColumnRoles:
    """Roles of the columns of one database.

    Attributes
    ----------
    features : tuple of str
        Design features (inputs of the simulator).
    performance : tuple of str
        Performance columns (outputs); never to be used as features.
    categorical : tuple of str
        The features that are categorical (pattern type, cell counts).
    """

    features: tuple[str, ...]
    performance: tuple[str, ...]
    categorical: tuple[str, ...] = ()


#: the canopy sheets' performance columns (data1 and data4)
_SHEET_PERFORMANCE = tuple(f"{k}stiff{e}" for k in ("bend", "axial") for e in (30, 60, 90))

PUBLISHED: dict[str, ColumnRoles] = {
    "data0": ColumnRoles(
        ("tcrease", "tpanel", "W", "gama"),
        ("axialstiff30", "axialstiff60", "axialstiff90"),
    ),
    "data1": ColumnRoles(
        ("pattern", "m", "n", "tcrease", "tpanel", "W"),
        _SHEET_PERFORMANCE,
        ("pattern", "m", "n"),
    ),
    "data2": ColumnRoles(
        ("Pattern", "L1", "L2", "t1", "t2", "tpanel", "rate", "W"),
        ("freqFinal", "finalQ", "Tmax", "stiff"),
        ("Pattern",),
    ),
    "data3": ColumnRoles(
        ("m", "tcrease", "tpanel", "W", "offset", "stripeWidth", "extrude"),
        ("Zstiff", "Zsnap", "Xstiff", "error"),
        ("m",),
    ),
    "data4": ColumnRoles(
        ("pattern", "m", "n", "tcrease", "tpanel", "W", "creaseE", "panelE"),
        _SHEET_PERFORMANCE,
        ("pattern", "m", "n"),
    ),
}


#: the shipped scenario each published database was made with (its columns' units)
PUBLISHED_SCENARIOS = {
    "data0": "single-miura",
    "data1": "canopy",
    "data2": "gripper",
    "data3": "arch",
    "data4": "canopy",
}


def feature_name_file(path) -> Path | None:
    """The sibling ``<prefix>_FeatureName.txt`` of a published ``<prefix>_<name>.txt``."""
    path = Path(path)
    prefix = path.stem.split("_", 1)[0]
    cand = path.with_name(f"{prefix}_FeatureName.txt")
    return cand if cand.is_file() and cand != path else None


def read_table(path, columns=None) -> pd.DataFrame:
    """Read a database into a DataFrame with named columns.

    Parameters
    ----------
    path : str or Path
        ``.csv`` (header row), ``.parquet`` / ``.pq``, or a headerless comma-separated
        ``.txt`` / ``.dat``.
    columns : sequence of str, optional
        Names of the columns of a headerless file. When omitted, a sibling
        ``*_FeatureName.txt`` (whitespace-separated names) is used if present; a file with
        fewer columns than it names takes the first names (a table of design features only).
        For files with a header, selects these columns.

    Returns
    -------
    pandas.DataFrame

    Raises
    ------
    ValueError
        Unknown suffix, no column names for a headerless file, a count mismatch, non-numeric
        values in a headerless file, or a requested column that does not exist.
    OSError
        The file cannot be read.
    """
    path = check_input_file(path, "table")
    suffix = path.suffix.lower()
    if suffix == ".csv":
        _check_csv_shape(path)
        try:
            frame = pd.read_csv(path)
        except (pd.errors.ParserError, pd.errors.EmptyDataError, UnicodeDecodeError) as exc:
            raise ValueError(f"{path.name} is not a readable CSV table: {exc}") from None
    elif suffix in (".parquet", ".pq"):
        try:
            frame = pd.read_parquet(path)
        except Exception as exc:  # noqa: BLE001 - pyarrow raises several types
            raise ValueError(f"{path.name} is not a readable Parquet file: {exc}") from None
    elif suffix in (".txt", ".dat"):
        names = list(columns) if columns is not None else None
        sibling_names = names is None
        if names is None:
            sib = feature_name_file(path)
            if sib is None:
                raise ValueError(
                    f"{path.name} has no header: give its column names (e.g. --columns), or put "
                    "a <prefix>_FeatureName.txt beside it"
                )
            names = sib.read_text().split()
        try:
            data = np.loadtxt(path, delimiter=",", ndmin=2)
        except ValueError as exc:
            raise ValueError(f"{path.name}: not a comma-separated numeric table ({exc})") from exc
        if sibling_names and data.shape[1] < len(names):
            names = names[: data.shape[1]]  # a table of the leading (feature) columns only
        if data.shape[1] != len(names):
            raise ValueError(
                f"{path.name} has {data.shape[1]} columns but {len(names)} names were given: "
                f"{' '.join(names)}"
            )
        if len(set(names)) != len(names):
            raise ValueError(f"duplicate column names: {' '.join(names)}")
        return pd.DataFrame(data, columns=names)
    else:
        raise ValueError(
            f"unknown database type {suffix!r} for {path.name}; expected .csv, .parquet, .txt"
        )
    if columns is not None:
        missing = [c for c in columns if c not in frame.columns]
        if missing:
            raise ValueError(
                f"column {missing[0]!r} not in {path.name}; columns: {', '.join(frame.columns)}"
            )
        frame = frame[list(columns)]
    return frame


def _check_csv_shape(path: Path) -> None:
    """Refuse a CSV whose header names a column twice or whose rows have another field count
    than the header (pandas would rename the copy or shift every later column silently)."""
    import csv

    try:
        with open(path, newline="", encoding="utf-8-sig") as fh:
            rows = csv.reader(fh)
            header = next(rows, None)
            if header is None:
                raise ValueError(f"{path.name} is empty: expected a header row of column names")
            seen = set()
            for name in header:
                if name in seen:
                    raise ValueError(f"{path.name}: the header names column {name!r} twice")
                seen.add(name)
            for line, row in enumerate(rows, start=2):
                if row and len(row) != len(header):
                    raise ValueError(
                        f"{path.name} line {line}: {len(row)} fields, but the header has "
                        f"{len(header)} columns"
                    )
    except UnicodeDecodeError:
        raise ValueError(f"{path.name} is not a UTF-8 text file") from None
    except csv.Error as exc:
        raise ValueError(f"{path.name} is not a readable CSV table: {exc}") from None


def check_table_path(path, what: str = "output") -> Path:
    """``path`` as a Path if :func:`write_table` can write it (known suffix, existing folder)."""
    return check_output_path(path, what, TABLE_SUFFIXES)


def write_table(frame: pd.DataFrame, path) -> Path:
    """Write ``frame`` as CSV (12 significant digits) or Parquet, by the suffix, atomically."""
    path = check_table_path(path)
    if path.suffix.lower() == ".csv":
        return atomic_write(path, lambda tmp: frame.to_csv(tmp, index=False, float_format="%.12g"))
    return atomic_write(path, lambda tmp: frame.to_parquet(tmp, index=False))


_BOOKKEEPING = {"sample", "status", "state", "reason", "origin", "meets_target"}


def column_roles(columns, path=None) -> ColumnRoles | None:
    """Recognise the roles of a database's columns.

    A holofold database folder (``holofold generate``) has a ``meta.json`` beside its Parquet
    file naming the scenario's features, performance columns and categorical features; that is
    used first when ``path`` is given (without it, the ``designs.parquet`` beside names the
    features; none is then categorical). Otherwise a published column set is recognised (in any
    order). Returns None when neither applies.
    """
    cols = {str(c) for c in columns}
    if path is not None:
        meta = Path(path).with_name("meta.json")
        if meta.is_file():
            import json

            try:
                info = json.loads(meta.read_text())
                feats = tuple(f for f in info["features"] if f in cols)
                perf = tuple(f for f in info["performance"] if f in cols)
                cat = tuple(f for f in info.get("categorical", ()) if f in feats)
            except (ValueError, KeyError, TypeError):
                info = None
            if info is not None and feats:
                return ColumnRoles(feats, perf, cat)
        designs = Path(path).with_name("designs.parquet")
        if designs.is_file():  # meta.json lost: the design table names the features
            try:
                import pyarrow.parquet as pq

                names = pq.read_schema(designs).names
            except Exception:  # noqa: BLE001 - pyarrow raises several types
                names = []
            feats = tuple(c for c in names if c in cols and c != "sample")
            if feats:
                perf = tuple(c for c in columns if c not in feats and c not in _BOOKKEEPING)
                return ColumnRoles(feats, tuple(map(str, perf)), ())
    for roles in PUBLISHED.values():
        if cols == set(roles.features + roles.performance):
            return roles
    return None


def table_columns(columns, path=None) -> dict:
    """The :class:`~holofold.design.scenarios.Column` records of a table's columns, where
    known: name -> Column (unit, display unit, description), for showing values and rules in
    the units people read.

    A holofold database's ``meta.json`` names its scenario (its file when it still exists, else
    a shipped scenario of that name; else its stored SI units); a published column set gives the
    scenario it was made with (:data:`PUBLISHED_SCENARIOS`). Columns of neither are left out
    (shown as bare numbers).
    """
    from holofold.design.scenarios import Column, load_scenario

    cols = [str(c) for c in columns]
    scenario, units = None, {}
    if path is not None:
        meta = Path(path).with_name("meta.json")
        if meta.is_file():
            import json

            try:
                info = json.loads(meta.read_text(encoding="utf-8"))
                units = {**info.get("features", {}), **info.get("performance", {})}
                units = {str(k): str(v) for k, v in units.items()}
                spec = info.get("scenario_file") or info.get("scenario")
                if spec and (not str(spec).endswith(".toml") or Path(spec).is_file()):
                    scenario = load_scenario(spec)
            except (ValueError, KeyError, TypeError, AttributeError, OSError):
                scenario = None
    if scenario is None and not units:
        names = set(cols)
        for key, roles in PUBLISHED.items():
            if names == set(roles.features + roles.performance):
                from holofold.design.scenarios import get_scenario

                scenario = get_scenario(PUBLISHED_SCENARIOS[key])
                break
    known = {} if scenario is None else {c.name: c for c in (*scenario.features,
                                                             *scenario.performance)}  # fmt: skip
    out = {}
    for name in cols:
        if name in known:
            out[name] = known[name]
        elif name in units:
            out[name] = Column(name, units[name])
    return out
