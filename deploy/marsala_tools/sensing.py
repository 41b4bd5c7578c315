"""The sensing experiment (issue 24, as the paper would print it): robots that read exact heights (ground_truth), an
RGB-D camera or a laser, each with localisation noise of 0, 5 and 10 cm, on the ramp (3 robots) and path_generated
(5 robots), seeds 1..3: completion steps, deposited volume, refused requests and how good the robots' own maps are
(marsala-terrain compare of each robot's final map against the run's terrain_final.asc). For each scenario and
sensor it runs the one-parameter experiment over the noise (experiment.py: real processes over loopback DDS,
spawn.sh --dump-maps). Front end: deploy/experiments/sensing.sh."""

import json
import os
import shutil
import statistics
import subprocess
import sys

from . import common, experiment, stats, tables
from .common import say, warn

PROG = "sensing"
DESCRIPTION = """\
The sensing experiment: for every scenario and sensor, the scenario's robots with `robot_type.sensor.name=SENSOR`
and `robot_type.localisation.noise_sd_m` at every noise value, seeds 1..N, as real processes (deploy/experiment.sh
with --dump-maps); then each robot's final map is compared with the run's final terrain (marsala-terrain compare)."""
EPILOG = """\
outputs: OUT/sensing.csv (one row per run), OUT/sensing_stats.csv (mean over the seeds), OUT/sensing.png, and
OUT/<scenario>-<sensor>/ (each experiment's outputs and runs, with the robots' maps in v<noise>-s<seed>/maps).

CSV columns: scenario,sensor,noise_sd_m,seed,completed,completion_steps,deposited_m3,rejected_requests,end_reason,
             robots,known_cells,median_error_m,p95_error_m,believed_passable_not (map columns over the robots' maps:
             known cells and median error are the robots' medians, p95 the largest robot's, believed passable cells
             that are not the sum; empty when a run left no map)
Exit codes: 0 every run ended (completed or not), 1 a run failed or a map could not be compared, 2 usage error,
            130 interrupted."""

SCENARIOS = {"ramp": 3, "path_generated": 5}  # shipped scenario -> its team in the experiment
SENSORS = ("ground_truth", "rgbd", "laser")
COLUMNS = ("scenario", "sensor", "noise_sd_m", "seed", "completed", "completion_steps", "deposited_m3",
           "rejected_requests", "end_reason", "robots", "known_cells", "median_error_m", "p95_error_m",
           "believed_passable_not")
STATS_COLUMNS = ("scenario", "sensor", "noise_sd_m", "runs", "completed", "steps_mean", "volume_mean",
                 "refused_mean", "median_error_mm", "p95_error_mm", "passable_not_mean")
NOISE_FIELD = "robot_type.localisation.noise_sd_m"


def choice_list(names, noun):
    """An argparse type: a space-separated list of names out of `names`."""
    def one(word):
        if word not in names:
            raise ValueError(word)
        return word
    return common.word_list(one, noun, f"one of {', '.join(names)}")


def build_parser():
    """The experiment's command line."""
    p = common.ArgumentParser(prog="deploy/experiments/sensing.sh", description=DESCRIPTION, epilog=EPILOG)
    p.add_argument("--scenarios", type=choice_list(tuple(SCENARIOS), "scenario"), default=list(SCENARIOS),
                   metavar='"S1 ..."', help="shipped scenarios (default: ramp path_generated)")
    p.add_argument("--sensors", type=choice_list(SENSORS, "sensor"), default=list(SENSORS), metavar='"S1 ..."',
                   help="sensors (default: ground_truth rgbd laser)")
    p.add_argument("--noises", type=common.word_list(common.finite_number, "noise", "a finite number"),
                   default=["0", "0.05", "0.1"], metavar='"SD1 ..."',
                   help="localisation noise sd per axis [m] (default: 0 0.05 0.1)")
    p.add_argument("--seeds", type=common.positive_int(experiment.MAX_COUNT), default=3, metavar="N",
                   help="seeds 1..N (default 3)")
    p.add_argument("--max-steps", type=common.positive_int(10 ** 12 - 1), metavar="N",
                   help="override the scenarios' max_steps (scanning robots that do not finish run to it)")
    p.add_argument("--timeout", type=common.positive_int(9999999), default=1800, metavar="S",
                   help="wall seconds per run (default 1800)")
    p.add_argument("--dds", choices=("cyclone", "fastdds"), default="cyclone", help="DDS vendor (default cyclone)")
    p.add_argument("--out", default="out/sensing", metavar="DIR", help="output folder (default out/sensing)")
    p.add_argument("--no-plot", dest="plot", action="store_false", help="skip OUT/sensing.png (it needs gnuplot)")
    return p


def experiment_argv(args, scenario, sensor):
    """deploy/experiment.sh's arguments for one scenario and sensor."""
    argv = ["--scenario", scenario_file(scenario), "--vary", NOISE_FIELD, "--values", " ".join(args.noises),
            "--agents", str(SCENARIOS[scenario]), "--seeds", str(args.seeds), "--out", sub_out(args, scenario, sensor),
            "--set", f"robot_type.sensor.name={sensor}", "--dump-maps", "--no-plot", "--timeout", str(args.timeout),
            "--dds", args.dds, "--label", "localisation noise sd [m]"]
    return argv + (["--max-steps", str(args.max_steps)] if args.max_steps else [])


def scenario_file(name):
    return os.path.join(common.ROOT, "deploy", "scenarios", f"{name}.pbtxt")


def sub_out(args, scenario, sensor):
    return os.path.join(args.out, f"{scenario}-{sensor}")


def map_error(run_dir, scenario):
    """[robots, known cells, median error, p95 error, believed passable not] over the robots' maps of one run (see
    EPILOG), as CSV words; empty words when the run left no map. ToolError when marsala-terrain compare fails."""
    maps = os.path.join(run_dir, "maps")
    files = sorted(f for f in os.listdir(maps) if f.endswith("-height.asc")) if os.path.isdir(maps) else []
    if not files:
        return ["0", "", "", "", ""]
    reports = []
    for f in files:
        command = [common.binary("marsala-terrain"), "compare", os.path.join(maps, f),
                   os.path.join(run_dir, "terrain_final.asc"), "--scenario", scenario_file(scenario), "--json"]
        r = subprocess.run(command, stdin=subprocess.DEVNULL, capture_output=True, text=True)
        if r.returncode != 0:
            raise common.ToolError(f"{' '.join(command)} failed (exit {r.returncode}): {r.stderr.strip()}")
        reports.append(json.loads(r.stdout))
    return [str(len(reports)), f"{statistics.median(x['known_cells'] for x in reports):.0f}",
            f"{statistics.median(x['median_error_m'] for x in reports):.6f}",
            f"{max(x['p95_error_m'] for x in reports):.6f}", str(sum(x["believed_passable_not"] for x in reports))]


def run_rows(args, scenario, sensor):
    """The CSV rows of one scenario's and sensor's experiment, from its experiment.csv and each run's maps."""
    out = sub_out(args, scenario, sensor)
    path = os.path.join(out, "experiment.csv")
    if not os.path.isfile(path):
        return []
    rows = []
    for r in tables.read_rows(path, experiment.COLUMNS):
        value, seed, completed, steps, _, volume, _, _, refused, end = r[:10]
        rows.append([scenario, sensor, value, seed, completed, steps, volume, refused, end] +
                    map_error(os.path.join(out, f"v{value}-s{seed}"), scenario))
    return rows


def stats_rows(rows):
    """Per scenario, sensor and noise: runs, completed, means over the seeds (map errors in mm)."""
    groups = {}
    for r in rows:
        groups.setdefault((r[0], r[1], r[2]), []).append(r)
    out = []
    for (scenario, sensor, noise), mine in groups.items():
        def mean(i, scale=1.0):
            return tables.number_text(stats.spread(float(r[i]) * scale for r in mine if r[i] != "").mean)
        out.append([scenario, sensor, noise, len(mine), sum(int(r[4]) for r in mine), mean(5), mean(6), mean(7),
                    mean(11, 1e3), mean(12, 1e3), mean(13)])
    return out


def plot_script(args, stats_csv):
    """gnuplot: a row per scenario, panels steps, volume, p95 map error against the noise, a line per sensor."""
    colours = {"ground_truth": "#1f77b4", "rgbd": "#d62728", "laser": "#2ca02c"}
    panels = (("steps (mean)", 6), ("deposited volume [m^3] (mean)", 7), ("map p95 error [mm] (mean)", 10))
    script = (f"set terminal pngcairo size 1200,{420 * len(args.scenarios)} font \",10\" noenhanced\n"
              f"set output '{args.out}/sensing.png'\nset datafile separator ','\nset grid\nset key top left\n"
              f"set multiplot layout {len(args.scenarios)},3 title 'sensing: steps, volume and map error (95th percentile) against "
              "localisation noise'\nset xlabel 'localisation noise sd [m]'\n"
              "set offsets graph 0.05, graph 0.05, graph 0.05, graph 0.05\n")
    for scenario in args.scenarios:
        for ylabel, column in panels:
            lines = [f"'{stats_csv}' using 3:((strcol(1) eq '{scenario}' && strcol(2) eq '{sensor}') ? ${column} : "
                     f"1/0) with linespoints pt 7 lc rgb '{colours[sensor]}' title '{sensor}'"
                     for sensor in args.sensors]
            script += f"set title '{scenario}'\nset ylabel '{ylabel}'\nplot " + ", \\\n     ".join(lines) + "\n"
    return script + "unset multiplot\n"


def main_checked(args):
    """Runs every scenario's and sensor's experiment, writes the outputs; returns the exit code."""
    failed = False
    rows = []
    os.makedirs(args.out, exist_ok=True)
    for scenario in args.scenarios:
        for sensor in args.sensors:
            say(f"{PROG}: {scenario} with {sensor} robots, noise {' '.join(args.noises)} m, {args.seeds} seed(s)")
            code = experiment.Experiment(experiment.parse_arguments(experiment_argv(args, scenario, sensor))).main()
            if code == common.EXIT_INTERRUPTED:
                return code
            failed |= code != common.EXIT_OK
            rows += run_rows(args, scenario, sensor)
    tables.write_rows(os.path.join(args.out, "sensing.csv"), COLUMNS, rows)
    stats_csv = os.path.join(args.out, "sensing_stats.csv")
    tables.write_rows(stats_csv, STATS_COLUMNS, stats_rows(rows), header_prefix="# ")
    say(f"{PROG}: {len(rows)} runs in {args.out}/sensing.csv, means in {stats_csv}")
    if args.plot and rows:
        if shutil.which("gnuplot") is None:
            warn(PROG, "gnuplot not found: no plot (install gnuplot-nox)")
        else:
            r = subprocess.run(["gnuplot"], input=plot_script(args, stats_csv), capture_output=True, text=True)
            if r.returncode != 0:
                warn(PROG, f"gnuplot failed: {r.stderr.strip()}")
            else:
                say(f"{PROG}: plot {args.out}/sensing.png")
    return common.EXIT_FAILED if failed else common.EXIT_OK


def parse_arguments(argv):
    """The experiment's settings; UsageError on a bad command line or a noise value marsala-world --check refuses
    (every experiment's values are checked before anything runs or is written)."""
    args = build_parser().parse_args(argv)
    for scenario in args.scenarios:
        for sensor in args.sensors:
            experiment.check_values(experiment.parse_arguments(experiment_argv(args, scenario, sensor)))
    return args


def main(argv):
    """deploy/experiments/sensing.sh: returns the exit code."""
    return common.run_main(PROG, lambda a: main_checked(parse_arguments(a)), argv)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
