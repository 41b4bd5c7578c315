"""marsala_tools.sweep: its command line, its CSV from fake summary.json files, its statistics, table and resume."""

import json
import os
import re

import pytest

from marsala_tools import common, runner, sweep

HEADER = ("team_size,seed,completed,completion_steps,wall_seconds,deposited_m3,path_length_m,idle_steps,"
          "idle_fraction,end_reason,sites,site_spans_m,material_deposited_m3,material_needed_m3,material_ratio,"
          "material_off_band_m3")
NO_MATERIAL = "0.000000,0.000000,0.000000,0.000000"  # a summary without its material block


@pytest.fixture
def scenario(tmp_path):
    path = tmp_path / "ramp.pbtxt"
    path.write_text("name: 'ramp'\n")
    return str(path)


@pytest.mark.parametrize("argv, message", [
    (["--bogus"], "unrecognized arguments: --bogus"),
    (["--teams"], "argument --teams: expected one argument"),
    (["--teams", "1 x"], "argument --teams: 'x' is not a team size (an integer >= 1)"),
    (["--teams", "0 1"], "'0' is not a team size"),
    (["--teams", "2 1 2"], "'2 1 2' lists a team size twice"),
    (["--teams", " "], "needs at least one team size"),
    (["--seeds", "0"], "argument --seeds: '0' is not an integer in [1, 999999]"),
    (["--seeds", "2", "--seed-list", "1 2"], "not allowed with argument --seeds"),
    (["--seed-list", "1 -3"], "'-3' is not a seed (a non-negative integer)"),
    (["--seed-list", "4 04"], "lists a seed twice"),
    (["--dds", "opensplice"], "invalid choice: 'opensplice'"),
    (["--max-steps", "1.5"], "argument --max-steps: '1.5' is not an integer"),
    (["--jobs", "65"], "argument --jobs: '65' is not an integer in [1, 64]"),
    (["--jobs", "\u00b2"], "argument --jobs: '\u00b2' is not an integer"),  # a digit to str.isdigit, not to int()
    (["--tea", "1"], "unrecognized arguments: --tea 1"),  # no abbreviations
    (["--scenario", "/none/x.pbtxt"], "scenario file '/none/x.pbtxt' not found"),
])
def test_argument_errors(argv, message, scenario):
    with pytest.raises(common.UsageError) as e:
        sweep.parse_arguments(["--scenario", scenario] + argv)
    assert e.value.code == common.EXIT_USAGE
    assert message in str(e.value)


def test_defaults_and_seed_list(scenario):
    a = sweep.parse_arguments(["--scenario", scenario])
    assert (a.teams, a.seeds, a.dds, a.jobs, a.timeout, a.max_steps, a.force, a.plot) == \
        ([1, 3, 5, 9, 12], [1, 2], "cyclone", 1, 1800, None, False, True)
    a = sweep.parse_arguments(["--scenario", scenario, "--seed-list", "7 3", "--teams", "2", "--no-plot"])
    assert (a.teams, a.seeds, a.plot) == ([2], [7, 3], False)


def test_main_prints_the_error_and_writes_nothing(tmp_path, scenario, capsys):
    assert sweep.main(["--scenario", scenario, "--out", str(tmp_path / "out"), "--jobs", "0"]) == 2
    assert capsys.readouterr().err.startswith("sweep: argument --jobs: ")
    assert not (tmp_path / "out").exists()


def test_too_few_slots_and_a_rejected_scenario(tmp_path, scenario, fake_build):
    s = sweep.Sweep(sweep.parse_arguments(["--scenario", scenario, "--teams", "1 4"]))
    with pytest.raises(common.UsageError, match=r"has 3 agent slots, fewer than the largest team \(4\)"):
        s.prepare()
    bad = tmp_path / "bad.pbtxt"
    bad.write_text("")
    s = sweep.Sweep(sweep.parse_arguments(["--scenario", str(bad), "--teams", "1"]))
    with pytest.raises(common.UsageError, match="unknown robot type"):
        s.prepare()


def opened(tmp_path, scenario, *more):
    s = sweep.Sweep(sweep.parse_arguments(["--scenario", scenario, "--out", str(tmp_path / "out")] + list(more)))
    s.open_output()
    return s


def finish(s, team, seed, doc, code=0, log=""):
    """A fake run of (team, seed): its folder with summary.json (doc, unless None) and spawn.log, then finish_run."""
    job = s.job(team, seed)
    os.makedirs(job.run_dir, exist_ok=True)
    if doc is not None:
        with open(os.path.join(job.run_dir, "summary.json"), "w") as f:
            json.dump(doc, f)
    with open(os.path.join(job.run_dir, "spawn.log"), "w") as f:
        f.write(log)
    s.finish_run(job, code)


def run_doc(steps, idle, completed=True, reason="completed", sites=(), material=None):
    doc = {"completed": completed, "end_reason": reason, "steps": steps, "wall_seconds": 2.5,
           "deposited_volume_m3": 4.25, "path_length_m": 31.5, "idle_steps": idle,
           "construction_sites": [{"from_m": a, "to_m": b} for a, b in sites]}
    if material:
        doc["material"] = dict(zip(("deposited_m3", "needed_m3", "ratio", "off_band_m3"), material))
    return doc


def test_csv_rows_from_summaries(tmp_path, scenario, capsys):
    s = opened(tmp_path, scenario)
    finish(s, 10, 1, run_doc(200, 50, sites=[(0.04, 2.46), (10.0, 12.25)], material=(4.25, 3.4, 1.25, 0.125)))
    finish(s, 9, 2, run_doc(4000, 1000, completed=False, reason="max_steps"))
    finish(s, 9, 1, run_doc(300, 0), code=5, log="spawn.sh: no end after 1800 s\n")
    finish(s, 3, 1, None, code=1, log="boom\n")
    lines = (tmp_path / "out" / "sweep.csv").read_text().splitlines()
    assert lines == [HEADER,  # sorted by team and seed as numbers (10 after 9)
                     "9,1,true,300,2.5,4.25,31.5,0,0.000000,timeout,0,," + NO_MATERIAL,
                     "9,2,false,4000,2.5,4.25,31.5,1000,0.250000,max_steps,0,," + NO_MATERIAL,
                     "10,1,true,200,2.5,4.25,31.5,50,0.250000,completed,2,0.0-2.5;10.0-12.2,"
                     "4.250000,3.400000,1.250000,0.125000"]
    assert s.failed == 1
    out = capsys.readouterr().out
    assert "  team  10, seed 1: completed in 200 steps, 2.50 s wall, 4.250 m^3 deposited, idle 25.0%" in out
    assert "  team   9, seed 2: NOT completed (max_steps) in 4000 steps" in out
    assert "  team 3, seed 1: FAILED (spawn.sh exit 1, no summary; see " in out and "\n    boom\n" in out
    # A run again replaces its row; the folder keeps no temporary file.
    finish(s, 9, 2, run_doc(100, 10))
    assert (tmp_path / "out" / "sweep.csv").read_text().splitlines()[2] == \
        "9,2,true,100,2.5,4.25,31.5,10,0.100000,completed,0,," + NO_MATERIAL
    assert not [n for n in os.listdir(tmp_path / "out") if ".tmp." in n]


HAND = [["1", "1", "true", "100", "2.0", "4", "0", "50", "0.500000", "completed", "0", ""],
        ["1", "2", "true", "140", "3.0", "4", "0", "28", "0.200000", "completed", "0", ""],
        ["3", "1", "true", "60", "1.5", "12", "0", "0", "0.000000", "completed", "1", "0.0-2.5"],
        ["3", "2", "false", "4000", "9.5", "7", "0", "900", "0.225000", "max_steps", "0", ""],
        ["5", "1", "false", "4000", "9.5", "7", "0", "900", "0.225000", "max_steps", "0", ""]]


def test_statistics_and_table_of_a_hand_made_csv(tmp_path, scenario, capsys):
    # team 1: steps 100, 140 -> mean 120 [100, 140]; wall 2, 3 -> 2.5; idle 0.5, 0.2 -> 0.35 [0.2, 0.5]. team 3: the
    # completed run only. team 5: no completed run, NaN.
    s = opened(tmp_path, scenario, "--no-plot")
    s.rows = {sweep.row_key(r): r for r in HAND}
    s.report()
    assert (tmp_path / "out" / "sweep_stats.csv").read_text().splitlines() == [
        "# team_size,runs,completed,steps_mean,steps_min,steps_max,wall_mean,wall_min,wall_max,idle_mean,idle_min,"
        "idle_max",
        "1,2,2,120,100,140,2.5,2,3,0.35,0.2,0.5",
        "3,2,1,60,60,60,1.5,1.5,1.5,0,0,0",
        "5,1,0,NaN,NaN,NaN,NaN,NaN,NaN,NaN,NaN,NaN"]
    out = capsys.readouterr().out
    assert re.search(r"^ +1 +2/2 +120\.0 +100 +140 +2\.50 +2\.00 +3\.00 +35\.0%$", out, re.M)
    assert re.search(r"^ +3 +1/2 +60\.0 +60 +60 ", out, re.M)
    assert re.search(r"^ +5 +0/1 +-$", out, re.M)


def test_resume_keeps_rows_and_other_settings_are_refused(tmp_path, scenario, capsys):
    s = opened(tmp_path, scenario)
    finish(s, 1, 1, run_doc(200, 50))
    again = opened(tmp_path, scenario)
    assert list(again.rows) == [(1, 1)]
    with pytest.raises(common.UsageError, match="use another --out, or --force"):
        opened(tmp_path, scenario, "--dds", "fastdds")
    assert "  there: dds=cyclone" in capsys.readouterr().err
    forced = opened(tmp_path, scenario, "--dds", "fastdds", "--force")
    assert forced.rows == {}
    assert (tmp_path / "out" / "sweep.csv.old").read_text().count("\n") == 2


def test_a_csv_of_another_kind_is_refused(tmp_path, scenario):
    (tmp_path / "out").mkdir()
    (tmp_path / "out" / "sweep.csv").write_text("a,b\n")
    with pytest.raises(common.UsageError, match="does not start with the header"):
        opened(tmp_path, scenario)


def test_job_arguments(tmp_path, scenario):
    s = opened(tmp_path, scenario, "--max-steps", "500", "--timeout", "60", "--dds", "fastdds")
    job = s.job(5, 7)
    assert isinstance(job, runner.Job) and job.key == (5, 7)
    assert job.run_dir == str(tmp_path / "out" / "n5-s7")
    assert job.args == ["--scenario", scenario, "--agents", "5", "--dds", "fastdds", "--out", job.run_dir, "--quiet",
                        "--timeout", "60", "--seed", "7", "--max-steps", "500"]
