"""A database that guards itself: fixed chunk layout, checksums, damaged chunks re-simulated."""

from __future__ import annotations

import json
import warnings

import numpy as np
import pandas as pd
import pytest

import holofold.design.database.store as store
from holofold.design import Column, Scenario, column_roles, mine_rules
from holofold.design.database.sampling import sample_designs
from holofold.mechanics import CONVERGED

CALLS: list = []


def _evaluate(row):
    CALLS.append(row["a"])
    return {"double": 2.0 * row["a"], "square": row["a"] ** 2, "status": CONVERGED}


CHEAP = Scenario(
    name="cheap",
    description="a cheap scenario for the store's tests",
    features=(Column("a", "m", "a length", 0.0, 1.0), Column("k", "-", "a level", choices=(1, 2))),
    performance=(Column("double", "m"), Column("square", "m^2")),
    check=lambda row: [],
    evaluate=_evaluate,
    categorical=("k",),
)
N = 30


@pytest.fixture
def designs():
    return sample_designs(CHEAP, N, seed=2)


@pytest.fixture
def reference(designs, tmp_path):
    return store.build_database(CHEAP, designs, tmp_path / "ref", chunk_size=10)


def _chunks(folder):
    return sorted((folder / "chunks").glob("part-*.parquet"))


def _rebuild(designs, folder, chunk_size=10):
    CALLS.clear()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        db = store.build_database(CHEAP, designs, folder, chunk_size=chunk_size)
    return db, [str(w.message) for w in caught], len(CALLS)


def test_chunks_are_named_by_their_checksum(reference, tmp_path):
    names = [p.name for p in _chunks(tmp_path / "ref")]
    assert [n[:10] for n in names] == ["part-00000", "part-00001", "part-00002"]
    import hashlib

    for p in _chunks(tmp_path / "ref"):
        assert p.name[11:27] == hashlib.sha256(p.read_bytes()).hexdigest()[:16]
    meta = json.loads((tmp_path / "ref" / "meta.json").read_text())
    assert meta["chunk_size"] == 10 and meta["rows"] == N


@pytest.mark.parametrize("damage", ["truncated", "empty", "garbage", "foreign name", "duplicate"])
def test_a_damaged_chunk_is_moved_aside_and_its_rows_simulated_again(
    designs, reference, tmp_path, damage
):
    db = tmp_path / "db"
    store.build_database(CHEAP, designs, db, chunk_size=10)
    victim = _chunks(db)[1]
    if damage == "truncated":
        victim.write_bytes(victim.read_bytes()[: victim.stat().st_size // 2])
    elif damage == "empty":
        victim.write_bytes(b"")
    elif damage == "garbage":
        victim.write_bytes(b"PAR1 not really")
    elif damage == "foreign name":
        victim.rename(victim.with_name("part-00001-copy.parquet"))
    else:
        (db / "chunks" / "part-00001-0123456789abcdef.parquet").write_bytes(victim.read_bytes())
    (db / "database.parquet").unlink()
    out, said, simulated = _rebuild(designs, db)
    pd.testing.assert_frame_equal(out, reference, check_exact=True)
    assert any("damaged chunk" in w for w in said), said
    assert simulated == (0 if damage == "duplicate" else 10)  # only the lost chunk's rows
    assert len(list((db / "chunks" / "damaged").iterdir())) == 1
    assert len(_chunks(db)) == 3


def test_flipping_any_byte_of_a_chunk_is_detected_or_harmless(designs, reference, tmp_path):
    """40 single-byte flips across a chunk: each either gives the uninterrupted database back
    (the chunk moved aside and re-simulated) or was never read as data; never a silently
    different database."""
    db = tmp_path / "db"
    store.build_database(CHEAP, designs, db, chunk_size=10)
    good = {p.name: p.read_bytes() for p in _chunks(db)}
    name = sorted(good)[2]
    data = good[name]
    detected = 0
    for pos in np.linspace(0, len(data) - 1, 40).astype(int):
        for p in _chunks(db):
            p.unlink()
        for n, b in good.items():
            (db / "chunks" / n).write_bytes(b)
        bad = bytearray(data)
        bad[pos] ^= 0xFF
        (db / "chunks" / name).write_bytes(bytes(bad))
        out, said, simulated = _rebuild(designs, db)
        pd.testing.assert_frame_equal(out, reference, check_exact=True)
        detected += simulated == 10
    assert detected == 40  # the checksum catches every flip


@pytest.mark.parametrize("first, second", [(10, 5), (5, 10)])
def test_resume_with_another_chunk_size_uses_the_stored_layout(
    designs, reference, tmp_path, monkeypatch, first, second
):
    db = tmp_path / "db"
    real = store.iter_results
    calls = []

    def interrupted(scenario, rows, **kw):
        calls.append(len(rows))
        if len(calls) == 2:
            raise KeyboardInterrupt
        return real(scenario, rows, **kw)

    monkeypatch.setattr(store, "iter_results", interrupted)
    with pytest.raises(KeyboardInterrupt):
        store.build_database(CHEAP, designs, db, chunk_size=first)
    monkeypatch.setattr(store, "iter_results", real)
    out, said, simulated = _rebuild(designs, db, chunk_size=second)
    assert len(out) == N and out["sample"].tolist() == list(range(N))  # none lost or doubled
    pd.testing.assert_frame_equal(out, reference, check_exact=True)
    assert any(f"created with {first} rows per chunk" in w for w in said)
    assert simulated == N - first  # the first chunk was kept


def test_a_lost_meta_json_is_rebuilt_and_the_database_can_be_mined(designs, tmp_path):
    db = tmp_path / "db"
    big = sample_designs(CHEAP, 120, seed=5)
    store.build_database(CHEAP, big, db, chunk_size=40)
    (db / "meta.json").unlink()
    out, said, simulated = _rebuild(big, db, chunk_size=40)
    assert simulated == 0 and (db / "meta.json").is_file()
    meta = json.loads((db / "meta.json").read_text())
    assert meta["chunk_size"] == 40 and list(meta["features"]) == ["a", "k"]
    roles = column_roles(out.columns, db / "database.parquet")
    assert roles.features == ("a", "k") and roles.categorical == ("k",)
    mined = mine_rules(out, "double > 1.2", roles=roles, seed=0, min_support=5, n_rules=1)
    assert mined.features == ("a", "k")


def test_an_older_chunk_without_checksum_is_kept_and_renamed(designs, reference, tmp_path):
    db = tmp_path / "db"
    store.build_database(CHEAP, designs, db, chunk_size=10)
    for p in _chunks(db):
        p.rename(p.with_name(p.name[:10] + ".parquet"))  # the layout before checksums
    out, said, simulated = _rebuild(designs, db)
    pd.testing.assert_frame_equal(out, reference, check_exact=True)
    assert simulated == 0 and all(len(p.name) == 35 for p in _chunks(db))


def test_a_database_without_meta_json_can_still_be_mined(tmp_path):
    db = tmp_path / "db"
    out = store.build_database(CHEAP, sample_designs(CHEAP, 60, seed=1), db, chunk_size=30)
    (db / "meta.json").unlink()
    roles = column_roles(out.columns, db / "database.parquet")
    assert roles.features == ("a", "k") and roles.performance == ("double", "square")


@pytest.mark.parametrize(
    "text, match",
    [("a,k,a\n0.1,1,0.2\n", "names column 'a' twice"),
     ("a,k\n0.1,1\n0.2,1,5\n", "line 3: 3 fields"),
     ("a,k\n0.1\n", "line 2: 1 fields"), ("", "is empty")],
)  # fmt: skip
def test_a_malformed_csv_table_is_refused_in_one_line(tmp_path, text, match):
    from holofold.design import read_table

    p = tmp_path / "t.csv"
    p.write_text(text)
    with pytest.raises(ValueError, match=match):
        read_table(p)


def test_chunks_without_a_column_the_scenario_now_has_are_simulated_again(designs, tmp_path):
    # a strip-kind folder written before its 'thick' column existed made the resumed design
    # loop stop with KeyError: 'thick' (validation/last_mile's arch)
    from dataclasses import replace

    db = tmp_path / "db"
    older = replace(CHEAP, performance=CHEAP.performance[:1])  # 'double' only
    store.build_database(older, designs, db, chunk_size=10)
    CALLS.clear()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        out = store.build_database(CHEAP, designs, db, chunk_size=10)
    said = [str(w.message) for w in caught]
    assert len(CALLS) == N and len(said) == 3  # every chunk, each said once
    assert all("without the column(s) square that the scenario now has" in w for w in said)
    assert np.allclose(out["square"], out["a"] ** 2) and out["sample"].tolist() == list(range(N))
