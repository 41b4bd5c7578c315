"""The shared runner: spawn.sh jobs (one run each) run at most `parallel` at a time, each on a fresh DDS domain with
its output in its own folder; a stop signal stops every run under way."""

import os
import shutil
import signal
import subprocess
import time
from dataclasses import dataclass, field

# The signals that stop a tool. The runs are in sessions of their own, so a terminal's Ctrl-C reaches the tool only,
# which stops its runs itself.
STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM)
# Fresh domains per run, 20..179 (ctest's runtime cases use 200 and up): concurrent runs never share one, nor does a
# run share its predecessor's.
FIRST_DOMAIN = 20
DOMAIN_COUNT = 160
POLL_SECONDS = 0.1
STOP_GRACE_SECONDS = 60


class Interrupted(Exception):
    """A stop signal arrived; the runs under way have been stopped."""


@dataclass
class Job:
    """One run: `key` names it for the tool, `args` follow the command, output goes to run_dir/spawn.log."""

    key: object
    run_dir: str
    args: list = field(default_factory=list)


def domain_of(index, offset=None):
    """The DDS domain of the index-th run of a tool: consecutive runs get consecutive domains, from a start that
    depends on the tool's pid so that two tools on one machine rarely meet."""
    if offset is None:
        offset = os.getpid() % DOMAIN_COUNT
    return FIRST_DOMAIN + (offset + index) % DOMAIN_COUNT


def exit_code(returncode):
    """A finished process's exit code as a shell reports it: 128 + N for a death by signal N."""
    return 128 - returncode if returncode < 0 else returncode


class _SignalsHeld:
    """Holds the stop signals back while a run starts or its result is recorded, so that neither is cut in half."""

    def __enter__(self):
        signal.pthread_sigmask(signal.SIG_BLOCK, STOP_SIGNALS)

    def __exit__(self, *exc):
        signal.pthread_sigmask(signal.SIG_UNBLOCK, STOP_SIGNALS)
        return False


def _unblock_signals():
    # A run starts while the stop signals are held back; it must not inherit that, or it could not be stopped.
    signal.pthread_sigmask(signal.SIG_SETMASK, [])


def _on_stop_signal(signum, frame):
    raise Interrupted()


class Runner:
    """Runs jobs as `command + job.args + ["--domain", D]` (when domains), `parallel` at a time, and calls
    on_finish(job, exit_code) as each ends, in the order they end."""

    def __init__(self, command, parallel, on_finish, domains=True):
        self.command = list(command)
        self.parallel = parallel
        self.on_finish = on_finish
        self.domains = domains
        self.running = []  # (job, Popen)

    def run(self, jobs):
        """Runs every job; raises Interrupted (after stopping the runs under way) when a stop signal arrives."""
        handlers = {s: signal.getsignal(s) for s in STOP_SIGNALS}
        for s in STOP_SIGNALS:
            if handlers[s] != signal.SIG_IGN:  # one ignored from the start stays ignored, as in a shell
                signal.signal(s, _on_stop_signal)
        try:
            self._run(list(jobs))
        finally:
            for s in STOP_SIGNALS:
                signal.signal(s, signal.SIG_IGN)  # no second stop while the runs are stopped
            self.stop()
            for s, handler in handlers.items():
                signal.signal(s, handler)

    def _run(self, jobs):
        offset = os.getpid() % DOMAIN_COUNT
        started = 0
        while started < len(jobs) or self.running:
            with _SignalsHeld():
                while started < len(jobs) and len(self.running) < self.parallel:
                    self._start(jobs[started], domain_of(started, offset))
                    started += 1
                self._collect()
            if self.running:
                time.sleep(POLL_SECONDS)

    def _start(self, job, domain):
        shutil.rmtree(job.run_dir, ignore_errors=True)
        os.makedirs(job.run_dir)
        argv = self.command + list(job.args) + (["--domain", str(domain)] if self.domains else [])
        with open(os.path.join(job.run_dir, "spawn.log"), "wb") as log:
            process = subprocess.Popen(argv, stdin=subprocess.DEVNULL, stdout=log, stderr=subprocess.STDOUT,
                                       start_new_session=True, preexec_fn=_unblock_signals)
        self.running.append((job, process))

    def _collect(self):
        still = []
        for job, process in self.running:
            if process.poll() is None:
                still.append((job, process))
            else:
                self.on_finish(job, exit_code(process.returncode))
        self.running = still

    def stop(self):
        """Stops the runs under way: SIGTERM to each (spawn.sh stops its children), SIGKILL to the session of one that
        has not ended STOP_GRACE_SECONDS later. Their on_finish is not called."""
        for _, process in self.running:
            try:
                process.send_signal(signal.SIGTERM)
            except OSError:
                pass
        for _, process in self.running:
            try:
                process.wait(STOP_GRACE_SECONDS)
            except subprocess.TimeoutExpired:
                try:
                    os.killpg(process.pid, signal.SIGKILL)
                except OSError:
                    pass
                process.wait()
        self.running = []
