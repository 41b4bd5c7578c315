"""deploy/spawn.sh --help prints its whole header comment, down to the last line of the exit-code table."""

import os
import subprocess

from conftest import ROOT

SPAWN = os.path.join(ROOT, "deploy", "spawn.sh")


def header_comment():
    """The comment lines after the shebang, up to the first line of code, without their '# '."""
    lines = []
    with open(SPAWN) as f:
        for line in list(f)[1:]:
            if not line.startswith("#"):
                break
            lines.append(line[2:].rstrip("\n") if line.startswith("# ") else line[1:].rstrip("\n"))
    return lines


def test_help_prints_the_whole_header():
    result = subprocess.run(["bash", SPAWN, "--help"], capture_output=True, text=True)
    assert result.returncode == 0
    printed = result.stdout.splitlines()
    assert printed[-1].endswith("130 stopped.")
    assert printed == header_comment()
    assert printed[0].startswith("Runs a scenario as real processes")
