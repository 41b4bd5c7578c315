"""marsala_tools.experiment: its command line, the values checked before any run, its CSV and statistics from fake
summaries, the table and the plot's panels."""

import math

import pytest

from marsala_tools import common, experiment
from marsala_tools.summary import Summary

VARY = "robot_type.localisation.noise_sd_m"


@pytest.fixture
def scenario(tmp_path):
    path = tmp_path / "site.pbtxt"
    path.write_text("name: 'site'\n")
    return str(path)


def parse(scenario, *more):
    return experiment.parse_arguments(["--scenario", scenario, "--vary", VARY] + list(more))


@pytest.mark.parametrize("argv, message", [
    (["--values", "0 abc"], "argument --values: 'abc' is not a finite number (the plot needs numbers)"),
    (["--values", "0 inf"], "'inf' is not a finite number"),
    (["--values", "0.1 0.1"], "'0.1 0.1' lists a value twice"),
    (["--values", "0", "--seeds", "0"], "argument --seeds: '0' is not an integer"),
    (["--values", "0", "--team", "3"], "unrecognized arguments: --team 3"),
    (["--values", "0", "--dds", "x"], "invalid choice: 'x'"),
    ([], "the following arguments are required: --values"),
])
def test_argument_errors(argv, message, scenario):
    with pytest.raises(common.UsageError) as e:
        parse(scenario, *argv)
    assert e.value.code == 2 and message in str(e.value)


def test_required_and_missing_scenario(tmp_path):
    with pytest.raises(common.UsageError, match="required: --vary"):
        experiment.parse_arguments(["--scenario", "x", "--values", "1"])
    with pytest.raises(common.UsageError, match="scenario file 'none.pbtxt' not found"):
        experiment.parse_arguments(["--scenario", "none.pbtxt", "--vary", VARY, "--values", "1"])


def test_defaults(scenario):
    a = parse(scenario, "--values", "0 0.05", "--set", "a=1", "--set", "b=2")
    assert (a.values, a.seeds, a.jobs, a.agents, a.sets, a.label, a.plot) == \
        (["0", "0.05"], 3, 1, None, ["a=1", "b=2"], VARY, True)
    assert experiment.overrides(a, "0.05") == ["a=1", "b=2", f"{VARY}=0.05"]


def test_every_value_is_checked_before_any_run(scenario, fake_build):
    experiment.check_values(parse(scenario, "--values", "0 0.1"))
    calls = (fake_build / "world-calls.txt").read_text().splitlines()
    assert calls == [f"--check {scenario} --set {VARY}=0", f"--check {scenario} --set {VARY}=0.1"]
    with pytest.raises(common.UsageError, match=rf"^{VARY}=0: scenario .*unknown robot type"):
        experiment.check_values(parse(scenario, "--values", "0 0.1", "--set", "bad.field=1"))


def result(steps, volume, completed=True, level=0.0, path=0.0, completion="level_site"):
    return Summary(completed=completed, steps=steps, wall_seconds=1.234, deposited_m3=volume, path_length_m=path,
                   idle_steps=0, site_level_fraction=level, rejected_requests=2,
                   end_reason="completed" if completed else "max_steps", completion=completion, sites=[])


def test_csv_statistics_and_table(tmp_path, scenario, capsys):
    a = parse(scenario, "--values", "0.1 0", "--out", str(tmp_path))
    e = experiment.Experiment(a)
    # value 0.1: steps 100 and 200 (mean 150, sd 70.7), volumes 1 and 3 (mean 2, sd 1.414), levels 0.5 and 0.7;
    # value 0: one run, not completed: no steps mean.
    e.results = {("0.1", 2): result(200, 3.0, level=0.7), ("0", 1): result(500, 0.5, completed=False, level=0.25),
                 ("0.1", 1): result(100, 1.0, level=0.5)}
    assert e.write_outputs() == "level"
    assert (tmp_path / "experiment.csv").read_text().splitlines() == [
        ",".join(experiment.COLUMNS),
        "0.1,1,1,100,1.23,1.000,0.5000,0.00,2,completed,level_site",
        "0.1,2,1,200,1.23,3.000,0.7000,0.00,2,completed,level_site",
        "0,1,0,500,1.23,0.500,0.2500,0.00,2,max_steps,level_site"]
    assert (tmp_path / "experiment_stats.csv").read_text().splitlines() == [
        "# " + ",".join(experiment.STATS_COLUMNS),
        "0.1,2,2,150.0,70.7,2.000,1.414,0.6000,0.1414,0.00,0.00",
        "0,1,0,nan,nan,0.500,0.000,0.2500,0.0000,nan,nan"]
    out = capsys.readouterr().out.splitlines()
    assert out[0] == f"| {VARY} | completed | steps mean +- sd (completed runs) | m^3 mean +- sd | site level " \
                     "fraction mean +- sd |"
    assert out[2:] == ["| 0.1 | 2 of 2 | 150 +- 71 | 2.0 +- 1.4 | 0.600 +- 0.141 |",
                       "| 0 | 0 of 1 | - | 0.5 +- 0.0 | 0.250 +- 0.000 |"]


def test_value_stats_against_hand_values():
    results = {("1", 1): result(10, 2.0, completion="payload_path", path=30.0),
               ("1", 2): result(14, 4.0, completion="payload_path", path=34.0),
               ("1", 3): result(99, 9.0, completed=False, completion="payload_path", path=1.0)}
    (v, runs, done, steps, volume, level, path), = experiment.value_stats(["1"], results)
    assert (v, runs, done) == ("1", 3, 2)
    assert (steps.mean, steps.sd) == (12.0, pytest.approx(math.sqrt(8)))  # deviations -2, 2: 8 / 1
    assert (volume.mean, volume.sd) == (5.0, pytest.approx(math.sqrt(13)))  # deviations -3, -1, 4: 26 / 2
    assert (path.mean, path.sd) == (32.0, pytest.approx(math.sqrt(8)))  # completed runs only
    assert experiment.third_measure(results) == "path"


def test_third_measure_needs_one_kind():
    assert experiment.third_measure({1: result(1, 1, completion="level_site")}) == "level"
    assert experiment.third_measure({1: result(1, 1, completion="level_site"),
                                     2: result(1, 1, completion="payload_path")}) is None


def test_plot_panels():
    two = experiment.plot_script("o", "/s/site.pbtxt", "noise [m]", None)
    assert "size 800,450" in two and "layout 1,2 title 'site.pbtxt: noise [m]'" in two
    assert two.count("\nplot ") == 2 and "using 1:4:5 with yerrorbars" in two and "using 1:6:7" in two
    three = experiment.plot_script("o", "s.pbtxt", "it's", "path")
    assert "size 1200,450" in three and "using 1:10:11" in three and "($3 == 1 ? $8 : 1/0)" in three
    assert "its" in three  # a quote in the label would end gnuplot's string
    assert "set yrange [0:1.05]" in experiment.plot_script("o", "s", "l", "level")


def test_job_arguments(tmp_path, scenario):
    e = experiment.Experiment(parse(scenario, "--values", "5", "--out", str(tmp_path), "--set", "a=1",
                                    "--max-steps", "9"))
    job = e.job("5", 2, 4)
    assert job.key == ("5", 2) and job.run_dir == str(tmp_path / "v5-s2")
    assert job.args == ["--scenario", scenario, "--seed", "2", "--out", job.run_dir, "--quiet", "--dds", "cyclone",
                        "--timeout", "1800", "--agents", "4", "--max-steps", "9", "--set", "a=1", "--set", f"{VARY}=5"]
