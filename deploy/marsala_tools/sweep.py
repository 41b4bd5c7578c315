"""The scalability sweep (paper Fig. 5): a scenario run as real processes for every team size and seed, one CSV row per
run (resumable), statistics per team size, a table and a plot. Front end: deploy/sweep.sh (deploy/sweep.py)."""

import difflib
import hashlib
import os
import shutil
import subprocess

from . import common, runner, slurm, stats, summary, tables
from .common import ROOT, UsageError, say, warn

PROG = "sweep"
DESCRIPTION = """\
Scalability sweep (paper Fig. 5): runs a scenario as real processes (deploy/spawn.sh, loopback DDS, a fresh domain
per run) for every team size and seed, collects one CSV row per run, prints a table per team size and plots the
completion steps and the idle fraction against the team size."""
EPILOG = """\
outputs: OUT/sweep.csv, OUT/sweep_stats.csv, OUT/sweep.png, OUT/n<T>-s<S>/ (each run's outputs, logs and spawn.log).
A re-run into the same OUT runs only the (team, seed) pairs missing from sweep.csv, so an interrupted sweep resumes;
--force re-runs the requested pairs and replaces their rows.

CSV columns: team_size,seed,completed,completion_steps,wall_seconds,deposited_m3,path_length_m,idle_steps,
             idle_fraction,end_reason,sites,site_spans_m (idle_fraction = idle_steps / completion_steps; sites: the
             construction sites along the payload's final path, site_spans_m their FROM-TO [m] along it, joined
             by ';': summary.json's construction_sites), material_deposited_m3,material_needed_m3,material_ratio,
             material_off_band_m3 (summary.json's material: the deposited volume against the task's exact MARS gap,
             docs/runtime.md#material-score; 0 from a build that does not write it).
Exit codes: 0 ok, 1 a run failed (no summary) or the binaries are missing, 2 usage error (or a scenario that
            marsala-world --check rejects), 130 interrupted."""

COLUMNS = ("team_size", "seed", "completed", "completion_steps", "wall_seconds", "deposited_m3", "path_length_m",
           "idle_steps", "idle_fraction", "end_reason", "sites", "site_spans_m", "material_deposited_m3",
           "material_needed_m3", "material_ratio", "material_off_band_m3")
STATS_COLUMNS = ("team_size", "runs", "completed", "steps_mean", "steps_min", "steps_max", "wall_mean", "wall_min",
                 "wall_max", "idle_mean", "idle_min", "idle_max")
MAX_TEAM = 999999
MAX_SEEDS = 999999


def build_parser():
    """The sweep's command line."""
    p = common.ArgumentParser(prog="deploy/sweep.sh", description=DESCRIPTION, epilog=EPILOG)
    p.add_argument("--scenario", default=os.path.join(ROOT, "deploy/scenarios/path_gale.pbtxt"), metavar="FILE",
                   help="scenario file (default deploy/scenarios/path_gale.pbtxt); needs as many agent slots as the "
                        "largest team")
    p.add_argument("--teams", default="1 3 5 9 12", metavar='"T1 T2 ..."',
                   type=common.word_list(common.count_word(MAX_TEAM), "team size", "a team size (an integer >= 1)"),
                   help='team sizes (default "1 3 5 9 12")')
    seeds = p.add_mutually_exclusive_group()
    seeds.add_argument("--seeds", type=common.positive_int(MAX_SEEDS), metavar="N", help="seeds 1..N (default 2)")
    seeds.add_argument("--seed-list", metavar='"S1 S2 ..."',
                       type=common.word_list(common.seed_word, "seed", "a seed (a non-negative integer)"),
                       help="the seeds, explicitly (non-negative integers)")
    p.add_argument("--out", default=os.path.join(ROOT, "out/sweep"), metavar="DIR",
                   help="output folder (default out/sweep)")
    p.add_argument("--dds", choices=("cyclone", "fastdds"), default="cyclone",
                   help="DDS vendor of every process (default cyclone)")
    p.add_argument("--max-steps", type=common.positive_int(10 ** 12 - 1), metavar="N",
                   help="override the scenario's max_steps")
    p.add_argument("--timeout", type=common.positive_int(9999999), default=1800, metavar="S",
                   help="wall seconds per run (default 1800)")
    p.add_argument("--jobs", type=common.positive_int(64), default=1, metavar="N",
                   help="runs at a time (default 1; more share the cores, so wall times grow)")
    p.add_argument("--force", action="store_true", help="re-run the requested runs and replace their rows")
    p.add_argument("--no-plot", dest="plot", action="store_false", help="skip OUT/sweep.png")
    slurm.add_arguments(p)
    return p


def parse_arguments(argv):
    """The sweep's settings from its command line; UsageError on a bad one."""
    args = build_parser().parse_args(argv)
    args.seeds = args.seed_list or list(range(1, (args.seeds or 2) + 1))
    if not args.out:
        raise UsageError("--out needs a folder")
    if not os.path.isfile(args.scenario):
        raise UsageError(f"scenario file '{args.scenario}' not found")
    args.scenario = os.path.abspath(args.scenario)
    slurm.check(args)
    return args


def row_key(row):
    """(team, seed) of a CSV row, as integers; rows that do not spell them sort first and match no run."""
    try:
        return int(row[0]), int(row[1])
    except (ValueError, IndexError):
        return -1, -1


def csv_row(team, seed, s, end_reason):
    """The CSV row of a run of `team` robots with `seed` that ended with Summary s."""
    spans = ";".join(f"{a:.1f}-{b:.1f}" for a, b in s.sites)
    return [team, seed, "true" if s.completed else "false", s.steps, s.wall_seconds, s.deposited_m3, s.path_length_m,
            s.idle_steps, f"{s.idle_fraction:.6f}", end_reason, len(s.sites), spans,
            *(f"{v:.6f}" for v in s.material)]


def number(text):
    """A CSV field as a float, NaN when it is not a number."""
    try:
        return float(text)
    except ValueError:
        return float("nan")


def team_stats(rows):
    """Per team size over the rows: [team, runs, completed, Spread of steps, of wall seconds, of idle fraction], the
    spreads over the completed runs, sorted by team size."""
    teams = {}
    for row in rows:
        teams.setdefault(row_key(row)[0], []).append(row)
    out = []
    for team in sorted(teams):
        done = [r for r in teams[team] if r[2] == "true"]
        out.append([team, len(teams[team]), len(done)] + [stats.spread(number(r[c]) for r in done) for c in (3, 4, 8)])
    return out


def stats_rows(per_team):
    """sweep_stats.csv's rows of team_stats()."""
    return [[team, runs, done] + [tables.number_text(v) for s in spreads for v in (s.mean, s.min, s.max)]
            for team, runs, done, *spreads in per_team]


def table_lines(per_team):
    """The table printed at the end, one line per team size."""
    lines = ["%5s %9s  %10s %8s %8s  %8s %8s %8s  %6s" % ("team", "completed", "steps mean", "min", "max", "wall [s]",
                                                          "min", "max", "idle")]
    for team, runs, done, steps, wall, idle in per_team:
        if done == 0:
            lines.append("%5d %5d/%-3d  %10s" % (team, done, runs, "-"))
        else:
            lines.append("%5d %5d/%-3d  %10.1f %8d %8d  %8.2f %8.2f %8.2f  %5.1f%%"
                         % (team, done, runs, steps.mean, steps.min, steps.max, wall.mean, wall.min, wall.max,
                            100 * idle.mean))
    return lines


class Sweep:
    """One sweep into one output folder."""

    def __init__(self, args):
        self.args = args
        self.failed = 0
        self.rows = {}

    def prepare(self):
        """Checks the build and the scenario before anything is written."""
        common.binary("marsala-world")
        common.binary("marsala-agent")
        self.slots = common.agent_slots(self.args.scenario)
        if self.slots < max(self.args.teams):
            raise UsageError(f"scenario '{self.args.scenario}' has {self.slots} agent slots, fewer than the largest "
                             f"team ({max(self.args.teams)}); use smaller --teams")
        self.spawn = common.spawn_command()

    def conf_text(self):
        """What makes rows comparable: a re-run into the same OUT with other settings would mix them."""
        with open(self.args.scenario, "rb") as f:
            digest = hashlib.sha256(f.read()).hexdigest()
        return (f"scenario={self.args.scenario}\nscenario_sha256={digest}\ndds={self.args.dds}\n"
                f"max_steps={self.args.max_steps or 'scenario'}\nseeds_passed=1\n")

    def open_output(self):
        """Makes OUT, keeps or refuses its rows (sweep.conf), reads them."""
        os.makedirs(self.args.out, exist_ok=True)
        self.out = os.path.abspath(self.args.out)
        self.csv = os.path.join(self.out, "sweep.csv")
        conf = os.path.join(self.out, "sweep.conf")
        now = self.conf_text()
        if os.path.isfile(self.csv) and os.path.isfile(conf):
            with open(conf, encoding="utf-8") as f:
                there = f.read()
            if there != now:
                if not self.args.force:
                    warn(PROG, f"{self.out} holds a sweep with other settings:")
                    for line in difflib.unified_diff(there.splitlines(), now.splitlines(), "there", "now", lineterm="",
                                                     n=0):
                        if line[:1] in "+-" and line[:3] not in ("---", "+++"):
                            warn(PROG, f"  {'there' if line[0] == '-' else 'now'}: {line[1:]}")
                    raise UsageError("use another --out, or --force to start over (the old CSV is kept as "
                                     "sweep.csv.old)")
                os.replace(self.csv, self.csv + ".old")
        if os.path.isfile(self.csv):
            try:
                self.rows = {row_key(r): r for r in tables.read_rows(self.csv, COLUMNS)}
            except ValueError as e:
                raise UsageError(f"{e}; use another --out") from None
        else:
            tables.write_rows(self.csv, COLUMNS, [])
        with open(conf, "w", encoding="utf-8") as f:
            f.write(now)

    def job(self, team, seed):
        """The spawn.sh job of one (team, seed)."""
        a = self.args
        run_dir = os.path.join(self.out, f"n{team}-s{seed}")
        args = ["--scenario", a.scenario, "--agents", str(team), "--dds", a.dds, "--out", run_dir, "--quiet",
                "--timeout", str(a.timeout), "--seed", str(seed)]
        if a.max_steps:
            args += ["--max-steps", str(a.max_steps)]
        return runner.Job((team, seed), run_dir, args)

    def finish_run(self, job, exit_code):
        """Records a finished run: its CSV row (the CSV written whole) and its line."""
        team, seed = job.key
        s, problem = summary.run_summary(job.run_dir, exit_code)
        if s is None:
            for line in summary.failure_lines(f"  team {team}, seed {seed}", job.run_dir, problem):
                say(line)
            self.failed += 1
            return
        reason = summary.csv_word(s.end_reason)
        with open(os.path.join(job.run_dir, "spawn.log"), encoding="utf-8", errors="replace") as f:
            if "no end after" in f.read():  # spawn.sh's --timeout stopped the world
                reason = "timeout"
        self.rows[(team, seed)] = [str(v) for v in csv_row(team, seed, s, reason)]
        tables.write_rows(self.csv, COLUMNS, [self.rows[k] for k in sorted(self.rows)])
        state = "completed" if s.completed else f"NOT completed ({reason})"
        say("  team %3d, seed %s: %s in %d steps, %.2f s wall, %.3f m^3 deposited, idle %.1f%%"
            % (team, seed, state, s.steps, s.wall_seconds, s.deposited_m3, 100 * s.idle_fraction))

    def run_all(self):
        """Runs the (team, seed) pairs to do, `--jobs` at a time."""
        a = self.args
        todo = [(t, s) for t in a.teams for s in a.seeds if a.force or (t, s) not in self.rows]
        say(f"{PROG}: {os.path.basename(a.scenario)} ({self.slots} slots), teams {' '.join(map(str, a.teams))}, "
            f"seeds {' '.join(map(str, a.seeds))}, {a.dds}; {len(todo)} of {len(a.teams) * len(a.seeds)} runs to do; "
            f"CSV {self.csv}")
        if a.jobs != 1 and not a.slurm:
            warn(PROG, f"{a.jobs} runs at a time share the cores: wall times are not comparable to --jobs 1")
        slurm.make_runner(a, self.spawn, a.jobs, self.finish_run, self.out, "marsala-sweep").run(
            self.job(t, s) for t, s in todo)

    def report(self):
        """sweep_stats.csv, the table and the plot, over every row of the CSV."""
        per_team = team_stats(self.rows.values())
        self.stats = os.path.join(self.out, "sweep_stats.csv")
        tables.write_rows(self.stats, STATS_COLUMNS, stats_rows(per_team), header_prefix="# ")
        say()
        say(f"Completion per team size (completed runs; all rows of {self.csv}):")
        for line in table_lines(per_team):
            say(line)
        if self.args.plot:
            self.plot()

    def plot(self):
        """OUT/sweep.png with gnuplot and deploy/plot_sweep.gp, when gnuplot is installed."""
        if shutil.which("gnuplot") is None:
            say(f"{PROG}: note: gnuplot is not installed (deploy/install-deps.sh or apt-get install gnuplot-nox): "
                "no sweep.png")
            return
        if not self.rows:
            say(f"{PROG}: note: no rows yet, no plot")
            return
        stem = os.path.splitext(os.path.basename(self.args.scenario))[0]
        png = os.path.join(self.out, "sweep.png")
        with open(os.path.join(self.out, "plot.log"), "wb") as log:
            rc = subprocess.run(["gnuplot", "-c", os.path.join(ROOT, "deploy/plot_sweep.gp"), self.csv, self.stats,
                                 png, f"{stem}, {self.args.dds}, {len(self.rows)} runs"], stdin=subprocess.DEVNULL,
                                stdout=log, stderr=subprocess.STDOUT).returncode
        if rc == 0:
            say(f"Plot: {png}")
        else:
            warn(PROG, f"gnuplot failed (see {self.out}/plot.log)")
            self.failed += 1

    def main(self):
        """Checks, opens OUT, runs, reports; returns the exit code."""
        self.prepare()
        self.open_output()
        try:
            self.run_all()
        except runner.Interrupted:
            warn(PROG, "interrupted; the runs under way were stopped (their rows are not written)")
            warn(PROG, f"{len(self.rows)} rows in {self.csv}; the same command resumes the sweep")
            return common.EXIT_INTERRUPTED
        self.report()
        if self.failed:
            warn(PROG, f"{self.failed} run(s) failed and have no row; the same command retries them")
            return common.EXIT_FAILED
        return common.EXIT_OK


def main(argv):
    """deploy/sweep.sh: returns the exit code."""
    return common.run_main(PROG, lambda a: Sweep(parse_arguments(a)).main(), argv)
