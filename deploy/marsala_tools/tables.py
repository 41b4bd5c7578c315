"""CSV files of the run tools through the csv module: one header line, rows written whole to a temporary file and
renamed into place, so that an interrupted tool never leaves a partial row."""

import csv
import os

NAN_TEXT = "NaN"  # what gnuplot and awk read as not-a-number


def number_text(value):
    """A statistic as the stats files hold it: 6 significant digits (120, 2.5, 0.35), NaN as NaN."""
    return NAN_TEXT if value != value else f"{value:.6g}"


def read_rows(path, columns):
    """The rows of a CSV file as lists of fields; ValueError when its first line is not `columns`."""
    with open(path, newline="", encoding="utf-8") as f:
        reader = csv.reader(f)
        header = next(reader, None)
        if header != list(columns):
            raise ValueError(f"{path} does not start with the header {','.join(columns)}")
        return [row for row in reader if row]


def write_rows(path, columns, rows, header_prefix=""):
    """Writes the header (`header_prefix` before its first column, e.g. '# ') and the rows, atomically."""
    tmp = f"{path}.tmp.{os.getpid()}"
    try:
        with open(tmp, "w", newline="", encoding="utf-8") as f:
            writer = csv.writer(f, lineterminator="\n")
            writer.writerow([header_prefix + columns[0]] + list(columns[1:]))
            writer.writerows(rows)
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.remove(tmp)
