#!/usr/bin/env python3
"""The scalability sweep of deploy/sweep.sh (paper Fig. 5), as a program: scheduler, CSV upsert, statistics, plot.

Runs a scenario as real processes through deploy/spawn.sh for every (team size, seed), one CSV row per run, and keeps
the command line, CSV columns, outputs, resume semantics, exit codes and messages of the shell script it replaces.
Scenario facts (the agent slots) come from `marsala-world --check --json`, never from parsing the scenario file.
Standard library only (Debian's python3). The usage text is USAGE below (`--help`).
"""

import difflib
import hashlib
import json
import math
import os
import re
import shutil
import signal
import subprocess
import sys
import time
from decimal import Decimal

USAGE = """\
Scalability sweep (paper Fig. 5): runs a scenario as real processes (deploy/spawn.sh, loopback DDS, a fresh domain
per run) for every team size and seed, collects one CSV row per run, prints a table per team size and plots the
completion steps and the idle fraction against the team size.

Usage: deploy/sweep.sh [--scenario FILE] [--teams "1 3 5 9 12"] [--seeds N | --seed-list "1 2"] [--out DIR]
                       [--dds cyclone|fastdds] [--max-steps N] [--timeout S] [--jobs N] [--force] [--no-plot]
  --scenario   scenario file (default deploy/scenarios/path_gale.pbtxt); needs as many agent slots as the largest team
  --teams      team sizes (default "1 3 5 9 12")
  --seeds      seeds 1..N (default 2); --seed-list gives them explicitly (non-negative integers)
  --out        output folder (default out/sweep): OUT/sweep.csv, OUT/sweep_stats.csv, OUT/sweep.png, OUT/n<T>-s<S>/
  --dds        DDS vendor of every process (default cyclone)
  --max-steps  override the scenario's max_steps; --timeout: wall seconds per run (default 1800)
  --jobs       runs at a time (default 1; more share the cores, so wall times grow)
  --force      re-run the requested runs and replace their rows; by default a re-run into the same OUT runs only
               the (team, seed) pairs missing from sweep.csv, so an interrupted sweep resumes
  --no-plot    skip OUT/sweep.png
CSV columns: team_size,seed,completed,completion_steps,wall_seconds,deposited_m3,path_length_m,idle_steps,
             idle_fraction,end_reason,sites,site_spans_m (idle_fraction = idle_steps / completion_steps; sites: the
             construction sites along the payload's final path, site_spans_m their FROM-TO [m] along it, joined
             by ';': summary.json's construction_sites).
Exit codes: 0 ok, 1 a run failed (no summary) or the binaries are missing, 2 usage error (or a scenario that
            marsala-world --check rejects), 130 interrupted.
"""

CSV_HEADER = ("team_size,seed,completed,completion_steps,wall_seconds,deposited_m3,path_length_m,idle_steps,"
              "idle_fraction,end_reason,sites,site_spans_m")
STATS_HEADER = ("# team_size,runs,completed,steps_mean,steps_min,steps_max,wall_mean,wall_min,wall_max,idle_mean,"
                "idle_min,idle_max")
# deploy/sweep.sh runs this program under its own name, so that messages read as they always did.
ME = os.environ.get("MARSALA_SWEEP_PROG") or "sweep.py"
VALUE_OPTIONS = ("--scenario", "--teams", "--seeds", "--seed-list", "--out", "--dds", "--max-steps", "--timeout",
                 "--jobs")
# The signals that stop a sweep; spawn.sh children ignore SIGINT and SIGQUIT like a shell's background jobs, so a
# Ctrl-C reaches the sweep only, which stops its runs itself.
STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM)


class Exit(Exception):
    """Ends the program: `message` (when given) on stderr as "<ME>: message", then exit `code`."""

    def __init__(self, code, message=None):
        super().__init__(message)
        self.code = code
        self.message = message


class Interrupted(Exception):
    """A stop signal arrived (raised from the signal handler)."""


def die_usage(message):
    raise Exit(2, message)


def die(message):
    raise Exit(1, message)


def out(text=""):
    print(text, flush=True)


def err(text):
    print(text, file=sys.stderr, flush=True)


# --- small helpers with the shell script's semantics ----------------------------------------------------------------

def logical_abspath(path):
    """`cd "$path" && pwd`: an absolute path against the logical working directory ($PWD), '..' folded lexically."""
    base = os.environ.get("PWD", "")
    try:
        if not (os.path.isabs(base) and os.path.samefile(base, ".")):
            base = os.getcwd()
    except OSError:
        base = os.getcwd()
    return os.path.normpath(os.path.join(base, path))


def is_uint(text):
    return re.fullmatch(r"[0-9]+", text) is not None


def is_pos(text):
    return is_uint(text) and int(text) >= 1


_STRNUM = re.compile(r"\s*[+-]?(?:[0-9]+\.?[0-9]*(?:[eE][+-]?[0-9]+)?|\.[0-9]+(?:[eE][+-]?[0-9]+)?)\s*")
_NUM_PREFIX = re.compile(r"\s*([+-]?)(0x(?:[0-9a-f]+\.?[0-9a-f]*|\.[0-9a-f]+)(?:p[+-]?[0-9]+)?|inf(?:inity)?|nan|"
                         r"(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:e[+-]?[0-9]+)?)", re.IGNORECASE)
_SORT_PREFIX = re.compile(r"\s*(-?[0-9]*(?:\.[0-9]*)?)")


def num(text):
    """awk's `text + 0` (strtod): the number its longest numeric prefix spells, 0 when there is none."""
    m = _NUM_PREFIX.match(text)
    if not m:
        return 0.0
    body = m.group(2)
    value = float.fromhex(body) if body[:2].lower() == "0x" else float(body)
    return -value if m.group(1) == "-" else value


def cfmt(spec, x):
    """C's printf of one float: as Python's %-format, but a negative NaN prints as -nan."""
    text = spec % x
    if math.isnan(x) and math.copysign(1.0, x) < 0:
        text = text.replace("nan", "-nan")
        if text.startswith(" "):
            text = text[1:]
    return text


def awk_int(x):
    """awk's (mawk's) printf %d argument: truncated, clamped to +-2147483647, NaN as -2147483647."""
    if x >= 2147483647:
        return 2147483647
    if x > -2147483647:
        return int(x)
    return -2147483647


def same_value(field, value):
    """awk's `field == value` for CSV fields: numeric when both look numeric (exactly, so long seeds never collide),
    else as strings."""
    if _STRNUM.fullmatch(field) and _STRNUM.fullmatch(value):
        return Decimal(field.strip()) == Decimal(value.strip())
    return field == value


def sort_number(text):
    """`sort -n`'s key of a field: its leading [-]digits[.digits], 0 when there is none."""
    m = _SORT_PREFIX.match(text).group(1)
    try:
        return Decimal(m)
    except ArithmeticError:
        return Decimal(0)


def numeric_order(line):
    """`sort -t, -k1,1n -k2,2n`, ties by the whole line."""
    fields = line.split(",")
    return (sort_number(fields[0]), sort_number(fields[1] if len(fields) > 1 else ""), line.encode("utf-8",
                                                                                                  "surrogateescape"))


def read_text(path):
    with open(path, encoding="utf-8", errors="surrogateescape", newline="") as f:
        return f.read()


def records(text):
    """The lines of a file as awk reads them (no empty record after the final newline)."""
    lines = text.split("\n")
    if lines and lines[-1] == "":
        lines.pop()
    return lines


def count_lines(path):
    """`wc -l`: newline characters in the file."""
    with open(path, "rb") as f:
        return f.read().count(b"\n")


def jq_number(x):
    """A number as jq 1.6 prints it: shortest round-trip digits, exponent form when the decimal point is 4 or more
    places left of the first digit or more than 15 places right of the last (1e+17, 1.2e-05), NaN as null."""
    if math.isnan(x):
        return "null"
    x = max(-sys.float_info.max, min(sys.float_info.max, x))
    if x == 0:
        return "-0" if math.copysign(1.0, x) < 0 else "0"
    sign = "-" if x < 0 else ""
    t = Decimal(repr(abs(x))).as_tuple()
    digits = "".join(map(str, t.digits))
    decpt = len(digits) + t.exponent
    digits = digits.rstrip("0")
    if decpt <= -4 or decpt > len(digits) + 15:
        mantissa = digits[0] + ("." + digits[1:] if len(digits) > 1 else "")
        return f"{sign}{mantissa}e{decpt - 1:+03d}"
    if decpt <= 0:
        return f"{sign}0.{'0' * -decpt}{digits}"
    if decpt >= len(digits):
        return sign + digits + "0" * (decpt - len(digits))
    return f"{sign}{digits[:decpt]}.{digits[decpt:]}"


def jq_or(value, default):
    """jq's `value // default`."""
    return default if value is None or value is False else value


def reject_constant(name):
    raise ValueError(f"invalid literal {name}")


def jq_tonumber(value):
    """jq 1.6's `tonumber`: a number as it is; a string that jq parses as a number (a JSON number, or a token its
    strtod reads whole: NaN, -nan, inf, Infinity); anything else fails with ValueError."""
    if isinstance(value, bool) or not isinstance(value, (int, float, str)):
        raise ValueError("cannot be parsed as a number")
    if isinstance(value, str):
        text = value.strip(" \t\n\r")
        try:
            value = json.loads(text, parse_constant=reject_constant)
        except ValueError:
            # jq reads a token of letters, digits, '.', '+', '-' with strtod unless it starts as a literal (t, f, n).
            if text[:1] in ("t", "f", "n") or not re.fullmatch(r"[A-Za-z0-9.+-]+", text):
                raise
            value = float(text)
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise ValueError("cannot be parsed as a number")
    return float(value)


def tsv(value):
    """One field of jq's @tsv."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (int, float)):
        return "" if math.isnan(value) else jq_number(float(value))
    if isinstance(value, str):
        return value.replace("\\", "\\\\").replace("\t", "\\t").replace("\n", "\\n").replace("\r", "\\r")
    raise ValueError("cannot be tsv-formatted")


def summary_values(path):
    """completed, steps, wall seconds, volume, path length, idle steps, end reason, the number of construction sites
    and their spans of a summary.json as the CSV holds them; fields a build may not have yet (idle_steps,
    path_length_m, construction_sites) read as 0 or none. Raises ValueError or OSError when the file is unreadable."""
    with open(path, "rb") as f:
        doc = json.loads(f.read().decode("utf-8"))
    if not isinstance(doc, dict):
        raise ValueError("not an object")
    reason = jq_or(doc.get("end_reason"), "")
    if not isinstance(reason, str):
        raise ValueError("end_reason is not a string")
    values = [jq_or(doc.get("completed"), False)]
    values += [jq_tonumber(jq_or(doc.get(key), 0))
               for key in ("steps", "wall_seconds", "deposited_volume_m3", "path_length_m", "idle_steps")]
    values.append(re.sub(r"[,\s]", "_", reason))
    sites = doc.get("construction_sites") or []
    if not isinstance(sites, list) or not all(isinstance(s, dict) for s in sites):
        raise ValueError("construction_sites is not a list of objects")
    spans = ";".join("%.1f-%.1f" % (float(s.get("from_m", 0)), float(s.get("to_m", 0))) for s in sites)
    return [tsv(v) for v in values] + [str(len(sites)), spans]


def as_int(text):
    """printf's %d argument: the integer a decimal string spells (truncated)."""
    try:
        return int(text)
    except ValueError:
        return int(num(text))


# --- the sweep --------------------------------------------------------------------------------------------------------

class Run:
    """A spawn.sh process under way."""

    def __init__(self, proc, team, seed):
        self.proc = proc
        self.team = team
        self.seed = seed


def child_setup():
    # As a shell starts background jobs: SIGINT and SIGQUIT ignored, and none of the parent's blocked signals.
    signal.pthread_sigmask(signal.SIG_SETMASK, [])
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGQUIT, signal.SIG_IGN)


class SignalsHeld:
    """Holds the stop signals back while a run starts or ends, so that neither is cut in half."""

    def __enter__(self):
        signal.pthread_sigmask(signal.SIG_BLOCK, STOP_SIGNALS)

    def __exit__(self, *exc):
        signal.pthread_sigmask(signal.SIG_UNBLOCK, STOP_SIGNALS)
        return False


def on_stop_signal(signum, frame):
    raise Interrupted()


def parse_arguments(argv, root):
    a = {"scenario": os.path.join(root, "deploy/scenarios/path_gale.pbtxt"), "teams": "1 3 5 9 12", "seeds": "",
         "seed-list": "", "out": os.path.join(root, "out/sweep"), "dds": "cyclone", "max-steps": "",
         "timeout": "1800", "jobs": "1", "force": False, "plot": True}
    i = 0
    while i < len(argv):
        arg = argv[i]
        if arg in VALUE_OPTIONS:
            if i + 1 >= len(argv) or argv[i + 1].startswith("--"):
                die_usage(f"{arg} needs a value (try --help)")
            a[arg[2:]] = argv[i + 1]
            i += 2
        elif arg == "--force":
            a["force"] = True
            i += 1
        elif arg == "--no-plot":
            a["plot"] = False
            i += 1
        elif arg in ("-h", "--help"):
            sys.stdout.write(USAGE)
            raise Exit(0)
        else:
            die_usage(f"unknown argument '{arg}' (try --help)")
    return a


def first_line_words(text):
    """`read -r -a words <<<"$text"`: the words of its first line."""
    return text.split("\n", 1)[0].split()


def check_arguments(a):
    teams_text = a["teams"]
    words = first_line_words(teams_text)
    if not words:
        die_usage("--teams needs at least one team size")
    for t in words:
        if not (is_pos(t) and len(t) <= 6):
            die_usage(f"--teams: '{t}' is not a team size (an integer >= 1)")
    teams = [int(t) for t in words]
    if len(set(teams)) != len(teams):
        die_usage(f"--teams lists a team size twice: '{teams_text}'")

    if a["seeds"] and a["seed-list"]:
        die_usage('give --seeds N or --seed-list "...", not both')
    if a["seed-list"]:
        words = first_line_words(a["seed-list"])
        if not words:
            die_usage("--seed-list needs at least one seed")
        for s in words:
            if not (is_uint(s) and len(s) <= 18):
                die_usage(f"--seed-list: '{s}' is not a seed (a non-negative integer)")
        seeds = [str(int(s)) for s in words]
        if len(set(seeds)) != len(seeds):
            die_usage(f"--seed-list lists a seed twice: '{a['seed-list']}'")
    else:
        n = a["seeds"] or "2"
        if not (is_pos(n) and len(n) <= 6):
            die_usage(f"--seeds N needs an integer N >= 1, got '{n}'")
        seeds = [str(s) for s in range(1, int(n) + 1)]

    if a["dds"] not in ("cyclone", "fastdds"):
        die_usage(f"--dds must be cyclone or fastdds, got '{a['dds']}'")
    max_steps = a["max-steps"]
    if max_steps and not (is_pos(max_steps) and len(max_steps) <= 12):
        die_usage(f"--max-steps N needs an integer N >= 1, got '{max_steps}'")
    if not (is_pos(a["timeout"]) and len(a["timeout"]) <= 7):
        die_usage(f"--timeout S needs whole seconds >= 1, got '{a['timeout']}'")
    if not (is_pos(a["jobs"]) and int(a["jobs"]) <= 64):
        die_usage(f"--jobs N needs an integer in [1, 64], got '{a['jobs']}'")
    if not a["out"]:
        die_usage("--out needs a folder")
    return teams, seeds, (str(int(max_steps)) if max_steps else ""), int(a["timeout"]), int(a["jobs"])


def agent_slots(world, scenario):
    """The scenario's agent slots as marsala-world --check --json reports them; a scenario the world would reject
    is a usage error with the check's message."""
    try:
        check = subprocess.run([world, "--check", "--json", scenario], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                               stdin=subprocess.DEVNULL)
    except OSError as e:
        die(f"cannot run {world}: {e.strerror}")
    message = check.stderr.decode("utf-8", "replace").strip()
    if check.returncode == 2:
        die_usage(message or f"marsala-world --check rejects '{scenario}'")
    if check.returncode != 0:
        die(f"marsala-world --check '{scenario}' failed (exit {check.returncode}): {message}")
    try:
        slots = json.loads(check.stdout.decode("utf-8"))["slots"]
        if not isinstance(slots, list):
            raise ValueError("slots is not a list")
    except (ValueError, KeyError, TypeError) as e:
        die(f"marsala-world --check --json printed no slots for '{scenario}': {e}")
    return len(slots)


def takes_seed(program):
    try:
        result = subprocess.run([program, "--help"], stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                stdin=subprocess.DEVNULL)
    except OSError:
        return False
    return b"--seed" in result.stdout


class Sweep:
    def __init__(self, root, a):
        self.root = root
        self.bin = os.path.join(os.environ.get("MARSALA_BUILD_DIR") or os.path.join(root, "build"), "bin")
        self.teams, self.seeds, self.max_steps, self.timeout_s, self.jobs = check_arguments(a)
        self.dds = a["dds"]
        self.force = a["force"]
        self.plot = a["plot"]
        scenario = a["scenario"]
        if not os.path.isfile(scenario):
            die_usage(f"scenario file '{scenario}' not found")
        self.scenario = os.path.join(logical_abspath(os.path.dirname(scenario)), os.path.basename(scenario))
        self.out_arg = a["out"]
        self.running = []
        self.failed = 0
        self.csv = self.tmp = None

    # --- before any run ---
    def prepare(self):
        for b in ("marsala-world", "marsala-agent"):
            path = os.path.join(self.bin, b)
            if not (os.path.isfile(path) and os.access(path, os.X_OK)):
                die(f"{path} not built (run deploy/build.sh)")
        self.slots = agent_slots(os.path.join(self.bin, "marsala-world"), self.scenario)
        max_team = max(self.teams)
        if self.slots < max_team:
            die_usage(f"scenario '{self.scenario}' has {self.slots} agent slots, fewer than the largest team "
                      f"({max_team}); use smaller --teams")
        self.spawn = os.path.join(self.root, "deploy/spawn.sh")
        if not (os.path.isfile(self.spawn) and os.access(self.spawn, os.X_OK)):
            die(f"{self.spawn} missing or not executable")
        # Seeds reach the processes only where both programs take --seed; otherwise every seed repeats the same run.
        self.pass_seed = all(takes_seed(os.path.join(self.bin, b)) for b in ("marsala-world", "marsala-agent"))
        if not self.pass_seed:
            err(f"{ME}: note: this build's marsala-world/marsala-agent take no --seed: every seed repeats the same run")

    def open_output(self):
        os.makedirs(self.out_arg, exist_ok=True)
        self.out = logical_abspath(self.out_arg)
        self.csv = os.path.join(self.out, "sweep.csv")
        self.tmp = f"{self.csv}.tmp.{os.getpid()}"
        conf = os.path.join(self.out, "sweep.conf")
        with open(self.scenario, "rb") as f:
            digest = hashlib.sha256(f.read()).hexdigest()
        # What makes rows comparable: a re-run into the same OUT with other settings would mix incomparable rows.
        conf_text = (f"scenario={self.scenario}\nscenario_sha256={digest}\ndds={self.dds}\n"
                     f"max_steps={self.max_steps or 'scenario'}\nseeds_passed={int(self.pass_seed)}")
        if os.path.isfile(self.csv) and os.path.isfile(conf):
            there = read_text(conf).rstrip("\n")
            if there != conf_text:
                if not self.force:
                    err(f"{ME}: {self.out} holds a sweep with other settings:")
                    old, new = there.split("\n"), conf_text.split("\n")
                    for tag, i1, i2, j1, j2 in difflib.SequenceMatcher(None, old, new, autojunk=False).get_opcodes():
                        if tag != "equal":
                            for line in old[i1:i2]:
                                err(f"  there: {line}")
                            for line in new[j1:j2]:
                                err(f"  now:   {line}")
                    die_usage("use another --out, or --force to start over (the old CSV is kept as sweep.csv.old)")
                os.replace(self.csv, self.csv + ".old")
        if os.path.isfile(self.csv) and records(read_text(self.csv))[:1] != [CSV_HEADER]:
            die_usage(f"{self.csv} does not start with the sweep header; use another --out")
        if not os.path.isfile(self.csv):
            with open(self.csv, "w") as f:
                f.write(CSV_HEADER + "\n")
        with open(conf, "w") as f:
            f.write(conf_text + "\n")

    # --- the CSV ---
    def rows(self):
        return records(read_text(self.csv))[1:]

    def has_row(self, team, seed):
        return any(self.is_row_of(line, team, seed) for line in self.rows())

    @staticmethod
    def is_row_of(line, team, seed):
        fields = line.split(",")
        return len(fields) >= 2 and same_value(fields[0], str(team)) and same_value(fields[1], seed)

    def put_row(self, team, seed, row):
        """Puts the row of (team, seed) in place of an older one, rows sorted by team and seed; the CSV is written whole
        to a temporary file, then renamed, so an interrupted sweep never leaves a partial row."""
        lines = [line for line in self.rows() if not self.is_row_of(line, team, seed)] + [row]
        lines.sort(key=numeric_order)
        with open(self.tmp, "w", encoding="utf-8", errors="surrogateescape", newline="") as f:
            f.write(CSV_HEADER + "\n" + "".join(line + "\n" for line in lines))
        os.replace(self.tmp, self.csv)

    # --- runs ---
    def start_run(self, team, seed, domain):
        run_dir = os.path.join(self.out, f"n{team}-s{seed}")
        shutil.rmtree(run_dir, ignore_errors=True)
        os.makedirs(run_dir, exist_ok=True)
        args = [self.spawn, "--scenario", self.scenario, "--agents", str(team), "--dds", self.dds, "--domain",
                str(domain), "--out", run_dir, "--quiet", "--timeout", str(self.timeout_s)]
        if self.max_steps:
            args += ["--max-steps", self.max_steps]
        if self.pass_seed:
            args += ["--seed", seed]
        with open(os.path.join(run_dir, "spawn.log"), "wb") as log:
            proc = subprocess.Popen(args, stdin=subprocess.DEVNULL, stdout=log, stderr=subprocess.STDOUT,
                                    preexec_fn=child_setup)
        self.running.append(Run(proc, team, seed))

    def finish_run(self, team, seed, rc):
        """Reads a finished run's summary.json into a CSV row and prints the run's line."""
        run_dir = os.path.join(self.out, f"n{team}-s{seed}")
        summary = os.path.join(run_dir, "summary.json")
        spawn_log = os.path.join(run_dir, "spawn.log")
        # spawn.sh passes marsala-world's exit code on: 0 completed, 3 max_steps, 4 no_live_agents, 5 signal (spawn.sh's
        # --timeout) each ended a run with its summary; the row says which.
        if rc not in (0, 3, 4, 5) or not os.path.isfile(summary):
            out(f"  team {team}, seed {seed}: FAILED (spawn.sh exit {rc}, no row written; see {spawn_log} and "
                f"{run_dir}/logs)")
            try:
                tail = records(read_text(spawn_log))[-5:]
            except OSError:
                tail = []
            for line in tail:
                out("    " + line.encode("utf-8", "surrogateescape").decode("utf-8", "replace"))
            self.failed += 1
            return
        try:
            completed, steps, wall, volume, path, idle, reason, sites, spans = summary_values(summary)
        except (OSError, ValueError, OverflowError):
            out(f"  team {team}, seed {seed}: FAILED (unreadable {summary})")
            self.failed += 1
            return
        try:
            if "no end after" in read_text(spawn_log):
                reason = "timeout"
        except OSError:
            pass
        steps_value = num(steps)
        idle_fraction = "%.6f" % (num(idle) / steps_value if steps_value > 0 else 0)
        self.put_row(team, seed, f"{team},{seed},{completed},{steps},{wall},{volume},{path},{idle},{idle_fraction},"
                                 f"{reason},{sites},{spans}")
        state = "completed" if completed == "true" else f"NOT completed ({reason})"
        idle_percent = float("%.6g" % (100 * float(idle_fraction)))  # awk's print, then printf %.1f
        out("  team %3d, seed %s: %s in %d steps, %.2f s wall, %.3f m^3 deposited, idle %.1f%%"
            % (team, seed, state, as_int(steps), num(wall), num(volume), idle_percent))

    def stop_runs(self):
        for run in self.running:
            try:
                run.proc.send_signal(signal.SIGTERM)
            except OSError:
                pass
        for run in self.running:
            run.proc.wait()
        self.running = []

    def run_all(self):
        todo = [(t, s) for t in self.teams for s in self.seeds if self.force or not self.has_row(t, s)]
        total = len(self.teams) * len(self.seeds)
        out(f"{ME}: {os.path.basename(self.scenario)} ({self.slots} slots), teams {' '.join(map(str, self.teams))}, "
            f"seeds {' '.join(self.seeds)}, {self.dds}; {len(todo)} of {total} runs to do; CSV {self.csv}")
        if self.jobs != 1:
            err(f"{ME}: {self.jobs} runs at a time share the cores: wall times are not comparable to --jobs 1")
        # A fresh domain per run, 20..179 (ctest's runtime cases use 200 and up): concurrent runs never share one,
        # nor does a run share its predecessor's.
        domain_offset = os.getpid() % 160
        next_run = 0
        while next_run < len(todo) or self.running:
            with SignalsHeld():
                while next_run < len(todo) and len(self.running) < self.jobs:
                    team, seed = todo[next_run]
                    self.start_run(team, seed, 20 + (domain_offset + next_run) % 160)
                    next_run += 1
                still = []
                for run in self.running:
                    if run.proc.poll() is None:
                        still.append(run)
                    else:  # a shell's `wait` reports a death by signal N as 128 + N
                        rc = run.proc.returncode
                        self.finish_run(run.team, run.seed, 128 - rc if rc < 0 else rc)
                self.running = still
            if len(self.running) >= self.jobs or (next_run >= len(todo) and self.running):
                time.sleep(0.2)

    # --- table and plot ---
    def write_stats(self):
        """Per team size over the completed runs: runs, completed, mean/min/max of steps, wall seconds and idle
        fraction."""
        runs, completed, total, lo, hi = {}, {}, {}, {}, {}
        for line in self.rows():
            fields = line.split(",")
            fields += [""] * (10 - len(fields))
            t = num(fields[0])
            runs[t] = runs.get(t, 0) + 1
            if fields[2] != "true":
                continue
            n = completed[t] = completed.get(t, 0) + 1
            for k, v in enumerate((num(fields[3]), num(fields[4]), num(fields[8]))):
                total[t, k] = total.get((t, k), 0.0) + v
                if n == 1 or v < lo[t, k]:
                    lo[t, k] = v
                if n == 1 or v > hi[t, k]:
                    hi[t, k] = v
        lines = []
        for t, count in runs.items():
            n = completed.get(t, 0)
            line = "%d,%d,%d" % (awk_int(t), count, n)
            for k in range(3):
                line += "".join("," + cfmt("%.6g", v) for v in (total[t, k] / n, lo[t, k], hi[t, k])) if n else \
                    ",NaN,NaN,NaN"
            lines.append(line)
        lines.sort(key=lambda l: (sort_number(l.split(",")[0]), l))
        self.stats = os.path.join(self.out, "sweep_stats.csv")
        with open(self.stats, "w") as f:
            f.write(STATS_HEADER + "\n" + "".join(line + "\n" for line in lines))
        return lines

    def print_table(self, lines):
        out()
        out(f"Completion per team size (completed runs; all rows of {self.csv}):")
        out("%5s %9s  %10s %8s %8s  %8s %8s %8s  %6s" % ("team", "completed", "steps mean", "min", "max", "wall [s]",
                                                         "min", "max", "idle"))
        for line in lines:
            f = [num(v) for v in line.split(",")]
            if f[2] == 0:
                out("%5d %5d/%-3d  %10s" % (awk_int(f[0]), awk_int(f[2]), awk_int(f[1]), "-"))
            else:
                out("%5d %5d/%-3d  %s %8d %8d  %s %s %s  %s%%"
                    % (awk_int(f[0]), awk_int(f[2]), awk_int(f[1]), cfmt("%10.1f", f[3]), awk_int(f[4]),
                       awk_int(f[5]), cfmt("%8.2f", f[6]), cfmt("%8.2f", f[7]), cfmt("%8.2f", f[8]),
                       cfmt("%5.1f", 100 * f[9])))

    def make_plot(self):
        if shutil.which("gnuplot") is None:
            out(f"{ME}: note: gnuplot is not installed (deploy/install-deps.sh or apt-get install gnuplot-nox): "
                "no sweep.png")
            return
        rows = count_lines(self.csv)
        if rows < 2:
            out(f"{ME}: note: no rows yet, no plot")
            return
        stem = self.scenario[:self.scenario.rfind(".")] if "." in self.scenario else self.scenario
        title = f"{os.path.basename(stem.rstrip('/'))}, {self.dds}, {rows - 1} runs"
        png = os.path.join(self.out, "sweep.png")
        with open(os.path.join(self.out, "plot.log"), "wb") as log:
            rc = subprocess.run(["gnuplot", "-c", os.path.join(self.root, "deploy/plot_sweep.gp"), self.csv,
                                 self.stats, png, title], stdin=subprocess.DEVNULL, stdout=log,
                                stderr=subprocess.STDOUT).returncode
        if rc == 0:
            out(f"Plot: {png}")
        else:
            err(f"{ME}: gnuplot failed (see {self.out}/plot.log)")
            self.failed += 1

    def interrupted(self):
        for s in STOP_SIGNALS:
            signal.signal(s, signal.SIG_DFL)
        err(f"{ME}: interrupted; stopping {len(self.running)} run(s) under way (their rows are not written)")
        self.stop_runs()
        self.remove_tmp()
        err(f"{ME}: {count_lines(self.csv) - 1} rows in {self.csv}; the same command resumes the sweep")
        return 130

    def remove_tmp(self):
        if self.tmp:
            try:
                os.remove(self.tmp)
            except FileNotFoundError:
                pass

    def main(self):
        self.prepare()
        self.open_output()
        for s in STOP_SIGNALS:
            if signal.getsignal(s) != signal.SIG_IGN:  # one ignored from the start stays ignored, as in a shell
                signal.signal(s, on_stop_signal)
        try:
            self.run_all()
            lines = self.write_stats()
            self.print_table(lines)
            if self.plot:
                self.make_plot()
            if self.failed > 0:
                err(f"{ME}: {self.failed} run(s) failed and have no row; the same command retries them")
                return 1
            return 0
        except Interrupted:
            return self.interrupted()
        finally:
            self.stop_runs()
            self.remove_tmp()


def main(argv):
    # Until the runs start, a stop signal ends the program at once, as it ended the shell script.
    if signal.getsignal(signal.SIGINT) != signal.SIG_IGN:
        signal.signal(signal.SIGINT, signal.SIG_DFL)
    root = logical_abspath(os.path.join(os.path.dirname(sys.argv[0]) or ".", ".."))
    try:
        return Sweep(root, parse_arguments(argv, root)).main()
    except Exit as e:
        if e.message:
            err(f"{ME}: {e.message}")
        return e.code
    except Interrupted:  # a stop signal during the final clean-up: the runs are stopped already
        return 130
    except OSError as e:
        err(f"{ME}: {e.filename or ''}{': ' if e.filename else ''}{e.strerror or e}")
        return 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
