"""A stray text cell in a long numeric column is refused before the chunks are joined
(so the error path does not turn 10^7 numbers into Python objects; measured in
benchmarks/bad_cell_memory.py), while a real text column is still read as text."""

import pytest

from inertialab.errors import InputError
from inertialab.io.formats import text


@pytest.fixture
def small_chunks(monkeypatch):
    monkeypatch.setattr(text, "_CHUNK_ROWS", 100)


def _write(path, n, last=None, first=None):
    rows = [f"{i / 100:.2f},{(i * 37) % 11 / 10:.1f},U{i % 3}" for i in range(n)]
    if last is not None:
        rows[-1] = rows[-1].rsplit(",", 2)[0] + f",{last},U0"
    if first is not None:
        rows[4] = rows[4].rsplit(",", 2)[0] + f",{first},U0"
    path.write_text("t_s,rate_dph,unit\n" + "\n".join(rows) + "\n")


@pytest.mark.parametrize("where, row", [("last", 1000), ("first", 5)])
def test_stray_text_cell_names_column_and_row(small_chunks, tmp_path, where, row):
    f = tmp_path / "g.csv"
    _write(f, 1000, **{where: "abc"})
    with pytest.raises(InputError, match=rf"column 'rate_dph', row {row}: non-numeric value "
                                         "'abc'"):
        text.load_text(f)


def test_empty_and_nan_cells_are_not_text(small_chunks, tmp_path):
    f = tmp_path / "g.csv"
    _write(f, 1000, last="nan")
    assert text.load_text(f).frame["rate_dph"].isna().sum() == 1


def test_a_text_column_numeric_in_its_first_chunk_stays_text(small_chunks, tmp_path):
    f = tmp_path / "ids.csv"
    ids = [str(i) for i in range(100)] + [f"QA-{i}" for i in range(300)]
    f.write_text("unit_id,x\n" + "\n".join(f"{u},{i}" for i, u in enumerate(ids)) + "\n")
    df = text.load_text(f).frame
    assert df["unit_id"].iloc[-1] == "QA-299" and len(df) == 400
