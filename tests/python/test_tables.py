"""marsala_tools.tables: CSV files written whole through the csv module, read back with their header checked."""

import os

import pytest

from marsala_tools import tables


def test_rows_round_trip_with_unix_line_ends(tmp_path):
    path = tmp_path / "t.csv"
    tables.write_rows(str(path), ("a", "b"), [[1, "x"], [2.5, ""]])
    assert path.read_bytes() == b"a,b\n1,x\n2.5,\n"
    assert tables.read_rows(str(path), ("a", "b")) == [["1", "x"], ["2.5", ""]]
    assert os.listdir(tmp_path) == ["t.csv"]  # no temporary file left


def test_header_prefix(tmp_path):
    path = tmp_path / "s.csv"
    tables.write_rows(str(path), ("team", "runs"), [[1, 2]], header_prefix="# ")
    assert path.read_text() == "# team,runs\n1,2\n"


def test_a_foreign_header_is_refused(tmp_path):
    path = tmp_path / "t.csv"
    path.write_text("x,y\n1,2\n")
    with pytest.raises(ValueError, match="does not start with the header a,b"):
        tables.read_rows(str(path), ("a", "b"))


@pytest.mark.parametrize("value, text", [(120.0, "120"), (2.5, "2.5"), (0.35, "0.35"), (0.0, "0"),
                                         (1234567.0, "1.23457e+06"), (float("nan"), "NaN")])
def test_number_text(value, text):
    assert tables.number_text(value) == text
