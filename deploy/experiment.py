#!/usr/bin/env python3
"""One-parameter experiments (deploy/experiment.sh): a scenario run as real processes for every value of one scenario
field and every seed; one CSV row per run, statistics per value, a plot. Standard library only (Debian's python3).
The usage text is USAGE below (`--help`)."""

import json
import math
import os
import shutil
import signal
import subprocess
import sys
import threading
import time

USAGE = """\
One-parameter experiment: runs SCENARIO with `--set FIELD=VALUE` for every value and seed as real processes
(deploy/spawn.sh: loopback DDS, a fresh domain per run), one CSV row per run, and plots completion steps, deposited
volume and (level_site scenarios) the final level fraction against the value, mean +- sd over the seeds.

Usage: deploy/experiment.sh --scenario FILE --vary FIELD --values "V1 V2 ..." [--agents N] [--seeds N]
                            [--out DIR] [--set FIELD=VALUE ...] [--max-steps N] [--timeout S] [--jobs N]
                            [--dds cyclone|fastdds] [--label TEXT] [--no-plot]
  --vary       the scenario field that takes each value, as spawn.sh --set names it, e.g.
               robot_type.body.sensing_range_m or robot_type.localisation.noise_sd_m
  --values     its values (each checked by marsala-world --check before anything runs)
  --agents     team size (default: every slot of the scenario)
  --seeds      seeds 1..N (default 3)
  --out        output folder (default out/experiment): OUT/experiment.csv, OUT/experiment_stats.csv,
               OUT/experiment.png, OUT/v<value>-s<seed>/ (each run's outputs and logs)
  --set        a further fixed override for every run (repeatable)
  --max-steps  override the scenario's max_steps; --timeout: wall seconds per run (default 1800)
  --jobs       runs at a time (default 1; more share the cores, so wall times grow; results do not change)
  --label      the value's name on the plot (default: FIELD)
  --no-plot    skip OUT/experiment.png (it needs gnuplot)
CSV columns: value,seed,completed,completion_steps,wall_seconds,deposited_m3,site_level_fraction,path_length_m,
             rejected_requests,end_reason,completion (site_level_fraction: level_site runs; path_length_m: the
             payload's constructed path, payload_path runs; the plot's third panel shows the one that applies)
Exit codes: 0 every run ended (completed or not), 1 a run failed (no summary) or the binaries are missing, 2 usage
            error or a value marsala-world --check rejects, 130 interrupted.
"""

CSV_HEADER = "value,seed,completed,completion_steps,wall_seconds,deposited_m3,site_level_fraction,path_length_m," \
             "rejected_requests,end_reason,completion"
STATS_HEADER = "# value,runs,completed,steps_mean,steps_sd,volume_mean,volume_sd,level_mean,level_sd,path_mean,path_sd"
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


class Exit(Exception):
    def __init__(self, code, message=None):
        super().__init__(message)
        self.code = code
        self.message = message


def parse_args(argv):
    opts = {"scenario": None, "vary": None, "values": None, "agents": None, "seeds": 3, "out": "out/experiment",
            "sets": [], "max_steps": None, "timeout": 1800, "jobs": 1, "dds": "cyclone", "label": None, "plot": True}
    value_options = {"--scenario", "--vary", "--values", "--agents", "--seeds", "--out", "--set", "--max-steps",
                     "--timeout", "--jobs", "--dds", "--label"}
    i = 0
    while i < len(argv):
        a = argv[i]
        if a in ("-h", "--help"):
            sys.stdout.write(USAGE)
            raise Exit(0)
        if a == "--no-plot":
            opts["plot"] = False
            i += 1
            continue
        if a not in value_options:
            raise Exit(2, f"unknown argument '{a}' (try --help)")
        if i + 1 >= len(argv):
            raise Exit(2, f"{a} needs a value")
        v = argv[i + 1]
        i += 2
        if a == "--set":
            opts["sets"].append(v)
        elif a in ("--agents", "--seeds", "--max-steps", "--timeout", "--jobs"):
            if not v.isdigit() or int(v) < 1:
                raise Exit(2, f"{a} needs a positive integer, got '{v}'")
            opts[a[2:].replace("-", "_")] = int(v)
        elif a == "--dds":
            if v not in ("cyclone", "fastdds"):
                raise Exit(2, f"--dds must be cyclone or fastdds, got '{v}'")
            opts["dds"] = v
        else:
            opts[a[2:]] = v
    for required in ("scenario", "vary", "values"):
        if not opts[required]:
            raise Exit(2, f"--{required} is required (try --help)")
    if not os.path.isfile(opts["scenario"]):
        raise Exit(2, f"scenario file '{opts['scenario']}' not found")
    values = opts["values"].split()
    if not values or len(set(values)) != len(values):
        raise Exit(2, f"--values needs distinct values, got '{opts['values']}'")
    for v in values:
        try:
            if not math.isfinite(float(v)):
                raise ValueError
        except ValueError:
            raise Exit(2, f"--values: '{v}' is not a finite number (the plot needs numbers)") from None
    opts["values"] = values
    return opts


def build_dir():
    return os.environ.get("MARSALA_BUILD_DIR") or os.path.join(ROOT, "build")


def check_value(opts, value):
    """Runs marsala-world --check with the overrides of `value`; Exit(2) with its message when it refuses them."""
    world = os.path.join(build_dir(), "bin", "marsala-world")
    if not os.access(world, os.X_OK):
        raise Exit(1, f"{world} is missing: build first (deploy/build.sh) or set MARSALA_BUILD_DIR")
    cmd = [world, "--check", opts["scenario"]] + [x for s in overrides(opts, value) for x in ("--set", s)]
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        raise Exit(2, f"{opts['vary']}={value}: " + (r.stderr.strip() or f"marsala-world --check exit {r.returncode}"))


def overrides(opts, value):
    return opts["sets"] + [f"{opts['vary']}={value}"]


def run_one(opts, value, seed, stop):
    """Runs one (value, seed); returns its CSV row, or raises Exit(1) when it wrote no summary."""
    out = os.path.join(opts["out"], f"v{value}-s{seed}")
    cmd = ["bash", os.path.join(ROOT, "deploy", "spawn.sh"), "--scenario", opts["scenario"], "--seed", str(seed),
           "--out", out, "--replace", "--quiet", "--dds", opts["dds"], "--timeout", str(opts["timeout"])]
    if opts["agents"]:
        cmd += ["--agents", str(opts["agents"])]
    else:
        cmd += ["--agents", str(slot_count(opts))]
    if opts["max_steps"]:
        cmd += ["--max-steps", str(opts["max_steps"])]
    for s in overrides(opts, value):
        cmd += ["--set", s]
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                            start_new_session=True)
    while proc.poll() is None:
        if stop.is_set():
            os.killpg(proc.pid, signal.SIGTERM)
            proc.wait()
            raise Exit(130)
        time.sleep(0.2)
    summary_path = os.path.join(out, "summary.json")
    if not os.path.isfile(summary_path):
        raise Exit(1, f"run {opts['vary']}={value} seed {seed} wrote no summary (spawn.sh exit {proc.returncode}): "
                      + (proc.stderr.read().strip()[-400:] if proc.stderr else ""))
    with open(summary_path, encoding="utf-8") as f:
        s = json.load(f)
    return {"value": value, "seed": seed, "completed": 1 if s.get("completed") else 0,
            "completion_steps": int(s.get("steps", 0)), "wall_seconds": float(s.get("wall_seconds", 0.0)),
            "deposited_m3": float(s.get("deposited_volume_m3", 0.0)),
            "site_level_fraction": float(s.get("site_level_fraction", 0.0)),
            "path_length_m": float(s.get("path_length_m", 0.0)),
            "rejected_requests": int(s.get("rejected_requests", 0)), "end_reason": s.get("end_reason", ""),
            "completion": s.get("completion", "")}


_slots = None


def slot_count(opts):
    global _slots
    if _slots is None:
        world = os.path.join(build_dir(), "bin", "marsala-world")
        r = subprocess.run([world, "--check", "--json", opts["scenario"]], capture_output=True, text=True)
        if r.returncode != 0:
            raise Exit(2, r.stderr.strip())
        _slots = len(json.loads(r.stdout).get("slots", [])) or 1
    return _slots


def mean_sd(xs):
    if not xs:
        return float("nan"), float("nan")
    m = sum(xs) / len(xs)
    sd = math.sqrt(sum((x - m) ** 2 for x in xs) / (len(xs) - 1)) if len(xs) > 1 else 0.0
    return m, sd


def write_outputs(opts, rows):
    order = {v: i for i, v in enumerate(opts["values"])}
    rows = sorted(rows, key=lambda r: (order[r["value"]], r["seed"]))
    with open(os.path.join(opts["out"], "experiment.csv"), "w", encoding="utf-8") as f:
        f.write(CSV_HEADER + "\n")
        for r in rows:
            f.write(f"{r['value']},{r['seed']},{r['completed']},{r['completion_steps']},{r['wall_seconds']:.2f},"
                    f"{r['deposited_m3']:.3f},{r['site_level_fraction']:.4f},{r['path_length_m']:.2f},"
                    f"{r['rejected_requests']},{r['end_reason']},{r['completion']}\n")
    stats = []
    for v in opts["values"]:
        mine = [r for r in rows if r["value"] == v]
        done = [r for r in mine if r["completed"]]
        steps = mean_sd([r["completion_steps"] for r in done])
        vol = mean_sd([r["deposited_m3"] for r in mine])
        level = mean_sd([r["site_level_fraction"] for r in mine])
        path = mean_sd([r["path_length_m"] for r in done])
        stats.append((v, len(mine), len(done), steps, vol, level, path))
    with open(os.path.join(opts["out"], "experiment_stats.csv"), "w", encoding="utf-8") as f:
        f.write(STATS_HEADER + "\n")
        for v, n, c, st, vo, le, pa in stats:
            f.write(f"{v},{n},{c},{st[0]:.1f},{st[1]:.1f},{vo[0]:.3f},{vo[1]:.3f},{le[0]:.4f},{le[1]:.4f},"
                    f"{pa[0]:.2f},{pa[1]:.2f}\n")
    label = opts["label"] or opts["vary"]
    third = third_measure(rows)
    third_title = {"level": "site level fraction mean +- sd", "path": "path length [m] mean +- sd (completed runs)"}
    print(f"| {label} | completed | steps mean +- sd (completed runs) | m^3 mean +- sd |"
          + (f" {third_title[third]} |" if third else ""))
    print("| --- | --- | --- | --- |" + (" --- |" if third else ""))
    for v, n, c, st, vo, le, pa in stats:
        steps_text = f"{st[0]:.0f} +- {st[1]:.0f}" if c else "-"
        extra = {"level": f" {le[0]:.3f} +- {le[1]:.3f} |", "path": f" {pa[0]:.1f} +- {pa[1]:.1f} |" if c else " - |",
                 None: ""}[third]
        print(f"| {v} | {c} of {n} | {steps_text} | {vo[0]:.1f} +- {vo[1]:.1f} |" + extra)
    return third


def third_measure(rows):
    """What the third column and panel show: "level" (level_site), "path" (payload_path) or None."""
    kinds = {r["completion"] for r in rows}
    if kinds == {"level_site"}:
        return "level"
    if kinds == {"payload_path"}:
        return "path"
    return None


def plot(opts, third):
    if shutil.which("gnuplot") is None:
        print("experiment: gnuplot not found: no plot (install gnuplot-nox)", file=sys.stderr)
        return
    out = opts["out"]
    label = (opts["label"] or opts["vary"]).replace("'", "")
    script = f"""
set terminal pngcairo size {1200 if third else 800},450 font ",11" noenhanced
set output '{out}/experiment.png'
set datafile separator ','
set multiplot layout 1,{3 if third else 2} title '{os.path.basename(opts["scenario"])}: {label}'
set key off
set grid
set offsets graph 0.08, graph 0.08, graph 0.08, graph 0.08
set xlabel '{label}'
set ylabel 'completion steps'
plot '{out}/experiment_stats.csv' using 1:4:5 with yerrorbars pt 7 lc rgb '#1f77b4', \\
     '{out}/experiment.csv' using 1:($3 == 1 ? $4 : 1/0) every ::1 with points pt 1 lc rgb '#999999'
set ylabel 'deposited volume [m^3]'
plot '{out}/experiment_stats.csv' using 1:6:7 with yerrorbars pt 7 lc rgb '#d62728', \\
     '{out}/experiment.csv' using 1:6 every ::1 with points pt 1 lc rgb '#999999'
"""
    if third == "level":
        script += f"""
set ylabel 'site level fraction'
set yrange [0:1.05]
plot '{out}/experiment_stats.csv' using 1:8:9 with yerrorbars pt 7 lc rgb '#2ca02c', \\
     '{out}/experiment.csv' using 1:7 every ::1 with points pt 1 lc rgb '#999999'
"""
    elif third == "path":
        script += f"""
set ylabel 'constructed path length [m]'
plot '{out}/experiment_stats.csv' using 1:10:11 with yerrorbars pt 7 lc rgb '#2ca02c', \\
     '{out}/experiment.csv' using 1:($3 == 1 ? $8 : 1/0) every ::1 with points pt 1 lc rgb '#999999'
"""
    script += "unset multiplot\n"
    r = subprocess.run(["gnuplot"], input=script, capture_output=True, text=True)
    if r.returncode != 0:
        print("experiment: gnuplot failed: " + r.stderr.strip(), file=sys.stderr)
    else:
        print(f"experiment: plot {out}/experiment.png")


def main(argv):
    opts = parse_args(argv)
    for v in opts["values"]:
        check_value(opts, v)
    os.makedirs(opts["out"], exist_ok=True)
    runs = [(v, s) for v in opts["values"] for s in range(1, opts["seeds"] + 1)]
    rows, errors, lock, stop = [], [], threading.Lock(), threading.Event()
    pending = list(runs)

    def worker():
        while not stop.is_set():
            with lock:
                if not pending:
                    return
                v, s = pending.pop(0)
            try:
                row = run_one(opts, v, s, stop)
            except Exit as e:
                with lock:
                    errors.append(e)
                stop.set()
                return
            with lock:
                rows.append(row)
                print(f"experiment: {opts['vary']}={v} seed {s}: {row['end_reason']} after {row['completion_steps']} "
                      f"steps, {row['deposited_m3']:.2f} m^3 ({len(rows)} of {len(runs)})", flush=True)

    def on_signal(signum, frame):
        stop.set()
        errors.append(Exit(130, "interrupted"))

    signal.signal(signal.SIGINT, on_signal)
    signal.signal(signal.SIGTERM, on_signal)
    threads = [threading.Thread(target=worker) for _ in range(min(opts["jobs"], len(runs)))]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    third = write_outputs(opts, rows) if rows else None
    if errors:
        raise errors[0]
    if opts["plot"]:
        plot(opts, third)


if __name__ == "__main__":
    try:
        main(sys.argv[1:])
    except Exit as e:
        if e.message:
            print(f"experiment: {e.message}", file=sys.stderr)
        sys.exit(e.code)
