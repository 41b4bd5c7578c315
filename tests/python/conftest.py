"""pytest setup for the run tools' tests: the package deploy/marsala_tools is imported from the source tree, and
`fake_build` makes a build folder whose programs are small scripts."""

import os
import stat
import sys

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "deploy"))


def write_script(path, text):
    """Writes an executable script."""
    with open(path, "w") as f:
        f.write(text)
    os.chmod(path, os.stat(path).st_mode | stat.S_IXUSR)
    return path


@pytest.fixture
def fake_build(tmp_path, monkeypatch):
    """A build folder (MARSALA_BUILD_DIR) whose marsala-world --check prints a scenario of 3 agent slots, or, for a
    scenario whose name holds 'bad', rejects it with exit 2; marsala-agent does nothing."""
    bin_dir = tmp_path / "build" / "bin"
    bin_dir.mkdir(parents=True)
    write_script(bin_dir / "marsala-world", """#!/usr/bin/env bash
for a in "$@"; do case "$a" in *bad*) echo "scenario $a: agent[1].robot_type: unknown robot type" >&2; exit 2 ;; esac; done
echo "$@" >>"$(dirname "$0")/world-calls.txt"
echo '{"slots": [{"id": 1}, {"id": 2}, {"id": 3}]}'
""")
    write_script(bin_dir / "marsala-agent", "#!/bin/sh\nexit 0\n")
    monkeypatch.setenv("MARSALA_BUILD_DIR", str(tmp_path / "build"))
    return bin_dir
