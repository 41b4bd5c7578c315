"""One-parameter experiments: a scenario run as real processes for every value of one scenario field and every seed;
one CSV row per run, statistics per value (mean +- sd over the seeds), a table and a plot. Front end:
deploy/experiment.sh (deploy/experiment.py)."""

import os
import shutil
import subprocess

from . import common, runner, slurm, stats, summary, tables
from .common import UsageError, say, warn

PROG = "experiment"
DESCRIPTION = """\
One-parameter experiment: runs SCENARIO with `--set FIELD=VALUE` for every value and seed as real processes
(deploy/spawn.sh: loopback DDS, a fresh domain per run), one CSV row per run, and plots completion steps, deposited
volume and (level_site scenarios) the final level fraction against the value, mean +- sd over the seeds."""
EPILOG = """\
outputs: OUT/experiment.csv, OUT/experiment_stats.csv, OUT/experiment.png, OUT/v<value>-s<seed>/ (each run's outputs,
logs and spawn.log).

CSV columns: value,seed,completed,completion_steps,wall_seconds,deposited_m3,site_level_fraction,path_length_m,
             rejected_requests,end_reason,completion (site_level_fraction: level_site runs; path_length_m: the
             payload's constructed path, payload_path runs; the plot's third panel shows the one that applies)
Exit codes: 0 every run ended (completed or not), 1 a run failed (no summary) or the binaries are missing, 2 usage
            error or a value marsala-world --check rejects, 130 interrupted."""

COLUMNS = ("value", "seed", "completed", "completion_steps", "wall_seconds", "deposited_m3", "site_level_fraction",
           "path_length_m", "rejected_requests", "end_reason", "completion")
STATS_COLUMNS = ("value", "runs", "completed", "steps_mean", "steps_sd", "volume_mean", "volume_sd", "level_mean",
                 "level_sd", "path_mean", "path_sd")
MAX_COUNT = 999999


def build_parser():
    """The experiment's command line."""
    p = common.ArgumentParser(prog="deploy/experiment.sh", description=DESCRIPTION, epilog=EPILOG)
    p.add_argument("--scenario", required=True, metavar="FILE", help="the scenario file")
    p.add_argument("--vary", required=True, metavar="FIELD",
                   help="the scenario field that takes each value, as spawn.sh --set names it, e.g. "
                        "robot_type.body.sensing_range_m or robot_type.localisation.noise_sd_m")
    p.add_argument("--values", required=True, metavar='"V1 V2 ..."',
                   type=common.word_list(common.finite_number, "value",
                                         "a finite number (the plot needs numbers)"),
                   help="its values (each checked by marsala-world --check before anything runs)")
    p.add_argument("--agents", type=common.positive_int(MAX_COUNT), metavar="N",
                   help="team size (default: every slot of the scenario)")
    p.add_argument("--seeds", type=common.positive_int(MAX_COUNT), default=3, metavar="N",
                   help="seeds 1..N (default 3)")
    p.add_argument("--out", default="out/experiment", metavar="DIR", help="output folder (default out/experiment)")
    p.add_argument("--set", dest="sets", action="append", default=[], metavar="FIELD=VALUE",
                   help="a further fixed override for every run (repeatable)")
    p.add_argument("--max-steps", type=common.positive_int(10 ** 12 - 1), metavar="N",
                   help="override the scenario's max_steps")
    p.add_argument("--timeout", type=common.positive_int(9999999), default=1800, metavar="S",
                   help="wall seconds per run (default 1800)")
    p.add_argument("--jobs", type=common.positive_int(64), default=1, metavar="N",
                   help="runs at a time (default 1; more share the cores, so wall times grow; results do not change)")
    p.add_argument("--dds", choices=("cyclone", "fastdds"), default="cyclone",
                   help="DDS vendor of every process (default cyclone)")
    p.add_argument("--label", help="the value's name on the plot (default: FIELD)")
    p.add_argument("--no-plot", dest="plot", action="store_false", help="skip OUT/experiment.png (it needs gnuplot)")
    p.add_argument("--dump-maps", action="store_true",
                   help="every agent writes its final map into the run's maps/ (spawn.sh --dump-maps)")
    slurm.add_arguments(p)
    return p


def parse_arguments(argv):
    """The experiment's settings; UsageError on a bad command line."""
    args = build_parser().parse_args(argv)
    if not os.path.isfile(args.scenario):
        raise UsageError(f"scenario file '{args.scenario}' not found")
    args.scenario = os.path.abspath(args.scenario)
    args.label = args.label or args.vary
    slurm.check(args)
    return args


def overrides(args, value):
    """The --set overrides of a run with `value`."""
    return args.sets + [f"{args.vary}={value}"]


def check_values(args):
    """marsala-world --check on every value before anything runs; UsageError with the check's message."""
    for value in args.values:
        try:
            common.world_check(args.scenario, overrides(args, value))
        except UsageError as e:
            raise UsageError(f"{args.vary}={value}: {e}") from None


def csv_row(value, seed, s):
    """The CSV row of a run with `value` and `seed` that ended with Summary s."""
    return [value, seed, int(s.completed), s.steps, f"{s.wall_seconds:.2f}", f"{s.deposited_m3:.3f}",
            f"{s.site_level_fraction:.4f}", f"{s.path_length_m:.2f}", s.rejected_requests,
            summary.csv_word(s.end_reason), summary.csv_word(s.completion)]


def value_stats(values, results):
    """Per value, in the order given: (value, runs, completed, Spread of steps (completed runs), of volume (all), of
    level fraction (all), of path length (completed runs)); `results` maps (value, seed) to a Summary."""
    out = []
    for v in values:
        mine = [s for (value, _), s in results.items() if value == v]
        done = [s for s in mine if s.completed]
        out.append((v, len(mine), len(done), stats.spread(s.steps for s in done),
                    stats.spread(s.deposited_m3 for s in mine), stats.spread(s.site_level_fraction for s in mine),
                    stats.spread(s.path_length_m for s in done)))
    return out


def stats_row(v, runs, done, steps, volume, level, path):
    """experiment_stats.csv's row of one value."""
    return [v, runs, done, f"{steps.mean:.1f}", f"{steps.sd:.1f}", f"{volume.mean:.3f}", f"{volume.sd:.3f}",
            f"{level.mean:.4f}", f"{level.sd:.4f}", f"{path.mean:.2f}", f"{path.sd:.2f}"]


def third_measure(results):
    """What the third column and panel show: "level" (level_site), "path" (payload_path) or None."""
    kinds = {s.completion for s in results.values()}
    return {frozenset({"level_site"}): "level", frozenset({"payload_path"}): "path"}.get(frozenset(kinds))


def table_lines(label, per_value, third):
    """The markdown table printed at the end."""
    title = {"level": " site level fraction mean +- sd |", "path": " path length [m] mean +- sd (completed runs) |",
             None: ""}[third]
    lines = [f"| {label} | completed | steps mean +- sd (completed runs) | m^3 mean +- sd |{title}",
             "| --- | --- | --- | --- |" + (" --- |" if third else "")]
    for v, runs, done, steps, volume, level, path in per_value:
        steps_text = f"{steps.mean:.0f} +- {steps.sd:.0f}" if done else "-"
        extra = {"level": f" {level.mean:.3f} +- {level.sd:.3f} |",
                 "path": f" {path.mean:.1f} +- {path.sd:.1f} |" if done else " - |", None: ""}[third]
        lines.append(f"| {v} | {done} of {runs} | {steps_text} | {volume.mean:.1f} +- {volume.sd:.1f} |{extra}")
    return lines


def plot_script(out, scenario, label, third):
    """The gnuplot script of experiment.png: steps and volume against the value, and the third measure if any."""
    label = label.replace("'", "")
    stats_csv, runs_csv = f"{out}/experiment_stats.csv", f"{out}/experiment.csv"
    panels = [("completion steps", 4, "($3 == 1 ? $4 : 1/0)", "#1f77b4", ""),
              ("deposited volume [m^3]", 6, "6", "#d62728", "")]
    if third == "level":
        panels.append(("site level fraction", 8, "7", "#2ca02c", "set yrange [0:1.05]\n"))
    elif third == "path":
        panels.append(("constructed path length [m]", 10, "($3 == 1 ? $8 : 1/0)", "#2ca02c", ""))
    script = (f"set terminal pngcairo size {400 * len(panels)},450 font \",11\" noenhanced\n"
              f"set output '{out}/experiment.png'\nset datafile separator ','\n"
              f"set multiplot layout 1,{len(panels)} title '{os.path.basename(scenario)}: {label}'\n"
              "set key off\nset grid\nset offsets graph 0.08, graph 0.08, graph 0.08, graph 0.08\n"
              f"set xlabel '{label}'\n")
    for ylabel, mean_column, runs_using, colour, extra in panels:
        script += (f"set ylabel '{ylabel}'\n{extra}"
                   f"plot '{stats_csv}' using 1:{mean_column}:{mean_column + 1} with yerrorbars pt 7 lc rgb "
                   f"'{colour}', \\\n     '{runs_csv}' using 1:{runs_using} every ::1 with points pt 1 lc rgb "
                   "'#999999'\n")
    return script + "unset multiplot\n"


class Experiment:
    """One experiment into one output folder."""

    def __init__(self, args):
        self.args = args
        self.results = {}  # (value, seed) -> Summary
        self.failed = 0

    def job(self, value, seed, agents):
        """The spawn.sh job of one (value, seed) with `agents` robots."""
        a = self.args
        run_dir = os.path.join(a.out, f"v{value}-s{seed}")
        args = ["--scenario", a.scenario, "--seed", str(seed), "--out", run_dir, "--quiet", "--dds", a.dds,
                "--timeout", str(a.timeout), "--agents", str(agents)]
        if a.max_steps:
            args += ["--max-steps", str(a.max_steps)]
        if a.dump_maps:
            args.append("--dump-maps")
        for override in overrides(a, value):
            args += ["--set", override]
        return runner.Job((value, seed), run_dir, args)

    def finish_run(self, job, exit_code):
        """Records a finished run (its Summary, for the outputs at the end) and prints its line."""
        value, seed = job.key
        s, problem = summary.run_summary(job.run_dir, exit_code)
        name = f"{PROG}: {self.args.vary}={value} seed {seed}"
        if s is None:
            for line in summary.failure_lines(name, job.run_dir, problem):
                say(line)
            self.failed += 1
            return
        self.results[job.key] = s
        say(f"{name}: {s.end_reason} after {s.steps} steps, {s.deposited_m3:.2f} m^3 ({len(self.results)} of "
            f"{self.total})")

    def write_outputs(self):
        """experiment.csv and experiment_stats.csv of the runs that ended, the table; returns the third measure."""
        a = self.args
        order = {v: i for i, v in enumerate(a.values)}
        keys = sorted(self.results, key=lambda k: (order[k[0]], k[1]))
        tables.write_rows(os.path.join(a.out, "experiment.csv"), COLUMNS,
                          [csv_row(v, seed, self.results[v, seed]) for v, seed in keys])
        per_value = value_stats(a.values, self.results)
        tables.write_rows(os.path.join(a.out, "experiment_stats.csv"), STATS_COLUMNS,
                          [stats_row(*row) for row in per_value], header_prefix="# ")
        third = third_measure(self.results)
        for line in table_lines(a.label, per_value, third):
            say(line)
        return third

    def plot(self, third):
        """OUT/experiment.png with gnuplot, when it is installed."""
        if shutil.which("gnuplot") is None:
            warn(PROG, "gnuplot not found: no plot (install gnuplot-nox)")
            return
        r = subprocess.run(["gnuplot"], input=plot_script(self.args.out, self.args.scenario, self.args.label, third),
                           capture_output=True, text=True)
        if r.returncode != 0:
            warn(PROG, f"gnuplot failed: {r.stderr.strip()}")
        else:
            say(f"{PROG}: plot {self.args.out}/experiment.png")

    def main(self):
        """Checks the values, runs every (value, seed), writes the outputs; returns the exit code."""
        a = self.args
        common.binary("marsala-agent")
        check_values(a)
        agents = a.agents or common.agent_slots(a.scenario)
        spawn = common.spawn_command()
        os.makedirs(a.out, exist_ok=True)
        jobs = [self.job(v, s, agents) for v in a.values for s in range(1, a.seeds + 1)]
        self.total = len(jobs)
        try:
            slurm.make_runner(a, spawn, a.jobs, self.finish_run, os.path.abspath(a.out),
                              "marsala-experiment").run(jobs)
        except runner.Interrupted:
            if self.results:
                self.write_outputs()
            warn(PROG, f"interrupted; the runs under way were stopped ({len(self.results)} of {self.total} ended)")
            return common.EXIT_INTERRUPTED
        third = self.write_outputs() if self.results else None
        if a.plot and self.results:
            self.plot(third)
        if self.failed:
            warn(PROG, f"{self.failed} run(s) failed (no summary); their lines above name their logs")
            return common.EXIT_FAILED
        return common.EXIT_OK


def main(argv):
    """deploy/experiment.sh: returns the exit code."""
    return common.run_main(PROG, lambda a: Experiment(parse_arguments(a)).main(), argv)
