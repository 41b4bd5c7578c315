"""marsala_tools.runner with a fake spawn command: order of the results, exit codes, runs at a time, domains, a stop."""

import os
import signal
import sys
import time

import pytest

from marsala_tools import runner

# The fake spawn.sh: `fake WAIT EXIT_CODE --domain D` notes its start and end in the log given by $FAKE_LOG, waits
# (WAIT seconds, or until the file WAIT exists, at most 30 s), and exits with EXIT_CODE (KILL: dies by SIGKILL).
FAKE = """
import os, signal, sys, time
wait, code, domain = sys.argv[1], sys.argv[2], sys.argv[4]
def note(what):
    with open(os.environ["FAKE_LOG"], "a") as f:
        f.write(f"{what} {domain} {time.monotonic()}\\n")
note("start")
print("fake spawn.sh output")
if wait.startswith("/"):
    deadline = time.monotonic() + 30
    while not os.path.exists(wait) and time.monotonic() < deadline:
        time.sleep(0.01)
else:
    time.sleep(float(wait))
note("end")
if code == "KILL":
    os.kill(os.getpid(), signal.SIGKILL)
sys.exit(int(code))
"""


@pytest.fixture
def fake(tmp_path, monkeypatch):
    script = tmp_path / "fake_spawn.py"
    script.write_text(FAKE)
    monkeypatch.setenv("FAKE_LOG", str(tmp_path / "events.txt"))
    return [sys.executable, str(script)]


def jobs_of(tmp_path, plan):
    """One job per (seconds, exit code) of plan, keyed by its index."""
    return [runner.Job(i, str(tmp_path / f"run{i}"), [str(seconds), str(code)]) for i, (seconds, code) in enumerate(plan)]


def events(tmp_path):
    return [line.split() for line in (tmp_path / "events.txt").read_text().splitlines()]


def test_one_at_a_time_in_order_with_exit_codes(tmp_path, fake):
    finished = []
    r = runner.Runner(fake, 1, lambda job, code: finished.append((job.key, code)))
    r.run(jobs_of(tmp_path, [(0.05, 0), (0, 3), (0, 1), (0, "KILL")]))
    assert finished == [(0, 0), (1, 3), (2, 1), (3, 128 + signal.SIGKILL)]
    # Each run wrote its output into its own folder's spawn.log.
    assert (tmp_path / "run2" / "spawn.log").read_text() == "fake spawn.sh output\n"
    # Runs one after the other: every start follows the previous end.
    kinds = [e[0] for e in events(tmp_path)]
    assert kinds == ["start", "end"] * 4


def test_consecutive_runs_get_consecutive_fresh_domains(tmp_path, fake):
    runner.Runner(fake, 2, lambda job, code: None).run(jobs_of(tmp_path, [(0, 0)] * 3))
    domains = sorted({int(e[1]) for e in events(tmp_path)})
    first = runner.domain_of(0)
    assert domains == sorted(runner.domain_of(i, os.getpid() % runner.DOMAIN_COUNT) for i in range(3))
    assert all(runner.FIRST_DOMAIN <= d < runner.FIRST_DOMAIN + runner.DOMAIN_COUNT for d in domains)
    assert runner.domain_of(1, first - runner.FIRST_DOMAIN) == first + 1 or first == 179
    assert runner.domain_of(0, runner.DOMAIN_COUNT - 1) == 179 and runner.domain_of(1, runner.DOMAIN_COUNT - 1) == 20


def test_parallel_runs_finish_in_the_order_they_end_and_never_exceed_the_limit(tmp_path, fake):
    finished = []
    release = tmp_path / "release"

    def on_finish(job, code):
        finished.append(job.key)
        if job.key == 3:
            release.touch()

    r = runner.Runner(fake, 2, on_finish)
    r.run(jobs_of(tmp_path, [(str(release), 0), (0, 0), (0, 0), (0, 0)]))
    assert finished == [1, 2, 3, 0]  # the first run waits for the last one: the others pass it on the second slot
    running = peak = 0
    for kind, _, _ in sorted(events(tmp_path), key=lambda e: float(e[2])):
        running += 1 if kind == "start" else -1
        peak = max(peak, running)
    assert peak == 2


def test_no_domain_option_when_asked(tmp_path):
    script = tmp_path / "args.py"
    script.write_text("import sys\nprint(' '.join(sys.argv[1:]))\n")
    r = runner.Runner([sys.executable, str(script)], 1, lambda job, code: None, domains=False)
    r.run([runner.Job("k", str(tmp_path / "run"), ["--a", "1"])])
    assert (tmp_path / "run" / "spawn.log").read_text() == "--a 1\n"


def test_an_old_run_folder_is_replaced(tmp_path, fake):
    (tmp_path / "run0").mkdir()
    (tmp_path / "run0" / "summary.json").write_text("{}")
    runner.Runner(fake, 1, lambda job, code: None).run(jobs_of(tmp_path, [(0, 0)]))
    assert sorted(os.listdir(tmp_path / "run0")) == ["spawn.log"]


def test_a_stop_signal_stops_the_runs_under_way(tmp_path, fake):
    finished = []

    def on_finish(job, code):  # the first run's end brings a stop signal; the second run is under way then
        finished.append(job.key)
        os.kill(os.getpid(), signal.SIGTERM)

    r = runner.Runner(fake, 2, on_finish)
    before = signal.getsignal(signal.SIGTERM)
    started = time.monotonic()
    with pytest.raises(runner.Interrupted):
        r.run(jobs_of(tmp_path, [(0, 0), (30, 0), (30, 0)]))
    assert time.monotonic() - started < 10  # stopped, not waited for
    assert finished == [0]  # the stopped run has no result
    assert [e[0] for e in events(tmp_path)].count("end") == 1
    assert (tmp_path / "run1").exists() and not (tmp_path / "run2").exists()  # the third never started
    assert r.running == []
    assert signal.getsignal(signal.SIGTERM) == before


def test_exit_code_as_a_shell_reports_it():
    assert runner.exit_code(0) == 0
    assert runner.exit_code(5) == 5
    assert runner.exit_code(-signal.SIGTERM) == 128 + signal.SIGTERM
