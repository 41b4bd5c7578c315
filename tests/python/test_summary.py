"""marsala_tools.summary: a summary.json read into the values of the CSV rows, and failed runs."""

import json

import pytest

from marsala_tools import summary

FULL = {"completed": True, "end_reason": "completed", "steps": 200, "wall_seconds": 12.5, "deposited_volume_m3": 3.25,
        "path_length_m": 40.0, "idle_steps": 50, "site_level_fraction": 0.0, "rejected_requests": 7,
        "completion": "payload_path",
        "construction_sites": [{"from_m": 1.04, "to_m": 2.5, "volume_m3": 1}, {"from_m": 10, "to_m": 12.25}],
        "material": {"deposited_m3": 3.25, "needed_m3": 2.5, "ratio": 1.3, "off_band_m3": 0.5}}


def write(tmp_path, doc):
    path = tmp_path / "summary.json"
    path.write_text(json.dumps(doc))
    return str(path)


def test_every_field(tmp_path):
    s = summary.read_summary(write(tmp_path, FULL))
    assert (s.completed, s.steps, s.wall_seconds, s.deposited_m3, s.path_length_m) == (True, 200, 12.5, 3.25, 40.0)
    assert (s.idle_steps, s.rejected_requests, s.end_reason, s.completion) == (50, 7, "completed", "payload_path")
    assert s.sites == [(1.04, 2.5), (10.0, 12.25)]
    assert s.idle_fraction == 0.25
    assert s.material == (3.25, 2.5, 1.3, 0.5)


def test_missing_fields_read_as_zero_or_none(tmp_path):
    s = summary.read_summary(write(tmp_path, {"steps": 0}))
    assert (s.completed, s.steps, s.idle_steps, s.end_reason, s.sites) == (False, 0, 0, "", [])
    assert s.material == (0.0, 0.0, 0.0, 0.0)
    assert s.idle_fraction == 0.0


def test_protobuf_json_strings_for_special_doubles(tmp_path):
    s = summary.read_summary(write(tmp_path, {"wall_seconds": "NaN", "steps": "12"}))
    assert s.wall_seconds != s.wall_seconds and s.steps == 12


@pytest.mark.parametrize("doc", [[], {"end_reason": 3}, {"steps": "many"}, {"construction_sites": [1]},
                                 {"material": 3}, {"material": {"ratio": "x"}}])
def test_not_a_summary(tmp_path, doc):
    with pytest.raises(ValueError):
        summary.read_summary(write(tmp_path, doc))


def test_run_summary_needs_an_ended_exit_code_and_the_file(tmp_path):
    write(tmp_path, FULL)
    assert summary.run_summary(str(tmp_path), 3)[0].steps == 200
    s, problem = summary.run_summary(str(tmp_path), 1)
    assert s is None and problem == "spawn.sh exit 1, no summary"
    assert summary.run_summary(str(tmp_path / "none"), 0)[1] == "spawn.sh exit 0, no summary"


def test_failure_lines_end_with_the_log_tail(tmp_path):
    (tmp_path / "spawn.log").write_text("".join(f"line {i}\n" for i in range(8)))
    lines = summary.failure_lines("run 1", str(tmp_path), "spawn.sh exit 1, no summary", tail=2)
    assert lines[0].startswith("run 1: FAILED (spawn.sh exit 1, no summary; see ")
    assert lines[1:] == ["    line 6", "    line 7"]


def test_csv_word():
    assert summary.csv_word("no end, after\t5 s") == "no_end__after_5_s"
