"""Runs a tool's jobs on a Slurm cluster as one array job (`--slurm [--partition P]`): task i is job i, one spawn.sh
run in a private network namespace of its own on whichever node Slurm gives it; the tool gathers the results as its
tasks end, exactly as from local runs. The output folder, the project and its build must be at the same paths on
every node (a shared file system)."""

import json
import os
import shlex
import shutil
import signal
import subprocess
import time

from . import runner
from .common import ToolError, UsageError

POLL_SECONDS = 1.0
# A task that leaves no exit code (killed by Slurm, node lost) counts as failed with this code.
LOST_TASK_EXIT = 1
TASK_SCRIPT = r"""#!/usr/bin/env bash
# One task of a MARSala array job: line SLURM_ARRAY_TASK_ID+1 of jobs.jsonl is its run (folder, spawn.sh command);
# the run gets a private network namespace with loopback only (unshare -n as root, unshare -rn otherwise) and its
# exit code goes to RUN_DIR/slurm.rc.
set -u
line=$(sed -n "$((SLURM_ARRAY_TASK_ID + 1))p" "$1")
run_dir=$(printf '%s' "$line" | python3 -c 'import json, sys; print(json.load(sys.stdin)["run_dir"])')
mapfile -t argv < <(printf '%s' "$line" | python3 -c 'import json, sys; print("\n".join(json.load(sys.stdin)["argv"]))')
rm -rf "$run_dir" && mkdir -p "$run_dir"
ns=(-n)
[ "$(id -u)" -eq 0 ] || ns=(-r -n)
unshare "${ns[@]}" sh -c 'ip link set lo up && exec "$@"' task "${argv[@]}" >"$run_dir/spawn.log" 2>&1 </dev/null
rc=$?
echo "$rc" >"$run_dir/slurm.rc.tmp" && mv "$run_dir/slurm.rc.tmp" "$run_dir/slurm.rc"
echo "task $SLURM_ARRAY_TASK_ID on ${SLURMD_NODENAME:-?}: $run_dir exit $rc"
"""


def add_arguments(parser):
    """The --slurm and --partition options of a run tool."""
    parser.add_argument("--slurm", action="store_true",
                        help="run the matrix on a Slurm cluster as one array job (sbatch; OUT and the build on a "
                             "file system shared by the nodes)")
    parser.add_argument("--partition", metavar="P", help="the Slurm partition (with --slurm; default: the cluster's)")


def check(args):
    """UsageError when --slurm cannot be used: no sbatch/squeue, --partition without --slurm, an unknown partition."""
    if args.partition and not args.slurm:
        raise UsageError("--partition needs --slurm")
    if not args.slurm:
        return
    for tool in ("sbatch", "squeue", "scancel", "sinfo"):
        if shutil.which(tool) is None:
            raise UsageError(f"--slurm: {tool} not found (install Slurm's client: deploy/install-deps.sh --slurm)")
    if args.partition:
        r = subprocess.run(["sinfo", "-h", "-p", args.partition, "-o", "%R"], stdin=subprocess.DEVNULL,
                           capture_output=True, text=True)
        if r.returncode != 0:
            raise UsageError(f"--slurm: sinfo failed: {r.stderr.strip() or r.returncode}")
        if args.partition not in r.stdout.split():
            raise UsageError(f"--partition: Slurm partition '{args.partition}' does not exist")


class SlurmRunner:
    """runner.Runner's interface on Slurm: run(jobs) submits `command + job.args + ["--domain", D]` for every job as
    one array job and calls on_finish(job, exit_code) as each task ends; a stop signal cancels the array job."""

    def __init__(self, command, partition, on_finish, work_dir, name):
        self.command = list(command)
        self.partition = partition
        self.on_finish = on_finish
        self.work_dir = work_dir
        self.name = name
        self.job_id = None

    def run(self, jobs):
        """Submits and waits; raises Interrupted (after scancel) on a stop signal, ToolError when sbatch refuses."""
        jobs = list(jobs)
        if not jobs:
            return
        handlers = {s: signal.getsignal(s) for s in runner.STOP_SIGNALS}
        for s in runner.STOP_SIGNALS:
            if handlers[s] != signal.SIG_IGN:
                signal.signal(s, runner._on_stop_signal)
        try:
            self._submit(jobs)
            self._wait(jobs)
        finally:
            for s in runner.STOP_SIGNALS:
                signal.signal(s, signal.SIG_IGN)
            self.cancel()
            for s, handler in handlers.items():
                signal.signal(s, handler)

    def _submit(self, jobs):
        os.makedirs(self.work_dir, exist_ok=True)
        listing = os.path.join(self.work_dir, "jobs.jsonl")
        offset = os.getpid() % runner.DOMAIN_COUNT
        with open(listing, "w", encoding="utf-8") as f:
            for i, job in enumerate(jobs):
                argv = self.command + list(job.args) + ["--domain", str(runner.domain_of(i, offset))]
                f.write(json.dumps({"run_dir": os.path.abspath(job.run_dir), "argv": argv}) + "\n")
        for job in jobs:
            shutil.rmtree(job.run_dir, ignore_errors=True)  # a stale slurm.rc must not count as this run's
        script = os.path.join(self.work_dir, "task.sh")
        with open(script, "w", encoding="utf-8") as f:
            f.write(TASK_SCRIPT)
        os.chmod(script, 0o755)
        command = ["sbatch", "--parsable", f"--array=0-{len(jobs) - 1}", f"--job-name={self.name}",
                   "--cpus-per-task=1", "--output", os.path.join(self.work_dir, "task-%a.out")]
        if self.partition:
            command.append(f"--partition={self.partition}")
        r = subprocess.run(command + [script, listing], stdin=subprocess.DEVNULL, capture_output=True, text=True)
        if r.returncode != 0:
            message = " ".join(r.stderr.split()) or f"exit {r.returncode}"
            raise ToolError(f"--slurm: sbatch refused the array job: {message}")
        self.job_id = r.stdout.strip().split(";")[0]
        print(f"submitted Slurm array job {self.job_id}: {len(jobs)} tasks ({shlex.join(command)} ...)", flush=True)

    def _queued(self):
        """True while any task of the array job is pending or running (or squeue cannot say)."""
        r = subprocess.run(["squeue", "-h", "-j", self.job_id, "-o", "%i"], stdin=subprocess.DEVNULL,
                           capture_output=True, text=True)
        return r.returncode != 0 and "Invalid job id" not in r.stderr or bool(r.stdout.strip())

    def _wait(self, jobs):
        left = list(jobs)
        while left:
            queued = self._queued()  # asked before the files are read: a task that ends in between is still seen
            still = []
            for job in left:
                rc = _task_exit(job.run_dir)
                if rc is not None:
                    self.on_finish(job, rc)
                elif not queued:
                    self.on_finish(job, LOST_TASK_EXIT)
                else:
                    still.append(job)
            left = still
            if left:
                time.sleep(POLL_SECONDS)
        self.job_id = None

    def cancel(self):
        """scancel of the array job when it was submitted and has not ended."""
        if self.job_id is not None:
            subprocess.run(["scancel", self.job_id], stdin=subprocess.DEVNULL, capture_output=True)
            self.job_id = None


def _task_exit(run_dir):
    """A finished task's exit code (RUN_DIR/slurm.rc), None while it has none."""
    try:
        with open(os.path.join(run_dir, "slurm.rc"), encoding="utf-8") as f:
            return int(f.read().strip())
    except (OSError, ValueError):
        return None


def make_runner(args, command, parallel, on_finish, out, name):
    """The runner of a tool: SlurmRunner with --slurm, else the local runner.Runner."""
    if args.slurm:
        return SlurmRunner(command, args.partition, on_finish, os.path.join(out, "slurm"), name)
    return runner.Runner(command, parallel, on_finish)
