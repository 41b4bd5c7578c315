"""What every run tool shares: its errors and exit codes, argparse with the tools' error style, argument types, the
build's binaries and marsala-world --check."""

import argparse
import json
import math
import os
import re
import subprocess
import sys

# The project's root: deploy/marsala_tools/ is two folders below it.
ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

EXIT_OK = 0
EXIT_FAILED = 1
EXIT_USAGE = 2
EXIT_INTERRUPTED = 130


class ToolError(Exception):
    """Ends a tool: `message` on stderr as "<tool>: message", then exit `code` (EXIT_FAILED unless given)."""

    def __init__(self, message, code=EXIT_FAILED):
        super().__init__(message)
        self.code = code


class UsageError(ToolError):
    """A bad command line or a scenario that marsala-world --check rejects: exit 2, nothing run."""

    def __init__(self, message):
        super().__init__(message, EXIT_USAGE)


def _help_format(prog):
    # The descriptions keep their own lines; the options' help is as wide as the project's text (118 columns).
    return argparse.RawDescriptionHelpFormatter(prog, max_help_position=30, width=118)


class ArgumentParser(argparse.ArgumentParser):
    """argparse whose errors raise UsageError (so the tool prints them in its own style) and that takes no
    abbreviated option names."""

    def __init__(self, **kwargs):
        kwargs.setdefault("formatter_class", _help_format)
        super().__init__(allow_abbrev=False, **kwargs)

    def error(self, message):
        """Raises UsageError(message) instead of printing usage and exiting."""
        raise UsageError(f"{message} (try --help)")


def positive_int(limit):
    """An argparse type: a decimal integer in [1, limit]."""

    def parse(text):
        try:
            return count_word(limit)(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"'{text}' is not an integer in [1, {limit}]") from None

    return parse


def word_list(parse_one, noun, description):
    """An argparse type: a space-separated list of words, each read by parse_one (ValueError when it is not
    `description`, e.g. "a seed (a non-negative integer)"), at least one and no `noun` twice."""

    def parse(text):
        words = text.split()
        if not words:
            raise argparse.ArgumentTypeError(f"needs at least one {noun}")
        values = []
        for word in words:
            try:
                values.append(parse_one(word))
            except ValueError:
                raise argparse.ArgumentTypeError(f"'{word}' is not {description}") from None
        if len(set(values)) != len(values):
            raise argparse.ArgumentTypeError(f"'{text}' lists a {noun} twice")
        return values

    return parse


def _is_decimal(word):
    return re.fullmatch(r"[0-9]+", word) is not None


def count_word(limit):
    """Reads a word as an integer in [1, limit] (ValueError otherwise)."""

    def parse(word):
        if not (_is_decimal(word) and 1 <= int(word) <= limit):
            raise ValueError(word)
        return int(word)

    return parse


def seed_word(word):
    """Reads a word as a seed: a non-negative integer of at most 18 digits (ValueError otherwise)."""
    if not (_is_decimal(word) and len(word) <= 18):
        raise ValueError(word)
    return int(word)


def finite_number(word):
    """Reads a word that is a finite number and keeps its text (ValueError otherwise)."""
    if not math.isfinite(float(word)):
        raise ValueError(word)
    return word


def bin_dir():
    """The build's bin/ folder: $MARSALA_BUILD_DIR/bin, else build/bin under the project's root."""
    return os.path.join(os.environ.get("MARSALA_BUILD_DIR") or os.path.join(ROOT, "build"), "bin")


def binary(name):
    """The path of one of the build's programs; ToolError when it is not built."""
    path = os.path.join(bin_dir(), name)
    if not (os.path.isfile(path) and os.access(path, os.X_OK)):
        raise ToolError(f"{path} not built (run deploy/build.sh, or set MARSALA_BUILD_DIR)")
    return path


def spawn_command():
    """The command that runs one scenario as real processes: deploy/spawn.sh; ToolError when it cannot run."""
    path = os.path.join(ROOT, "deploy", "spawn.sh")
    if not (os.path.isfile(path) and os.access(path, os.X_OK)):
        raise ToolError(f"{path} missing or not executable")
    return [path]


def world_check(scenario, overrides=(), as_json=False):
    """Runs marsala-world --check on the scenario with `--set` overrides; returns its stdout (the check's JSON when
    as_json). A scenario or override the world rejects is a UsageError with the check's message."""
    command = [binary("marsala-world"), "--check"] + (["--json"] if as_json else []) + [scenario]
    for override in overrides:
        command += ["--set", override]
    result = subprocess.run(command, stdin=subprocess.DEVNULL, capture_output=True, text=True)
    message = result.stderr.strip()
    if result.returncode == EXIT_USAGE:
        raise UsageError(message or f"marsala-world --check rejects '{scenario}'")
    if result.returncode != 0:
        raise ToolError(f"marsala-world --check '{scenario}' failed (exit {result.returncode}): {message}")
    return result.stdout


def agent_slots(scenario):
    """The number of agent slots of the scenario, as marsala-world --check --json reports them."""
    text = world_check(scenario, as_json=True)
    try:
        slots = json.loads(text)["slots"]
        if not isinstance(slots, list):
            raise ValueError("slots is not a list")
    except (ValueError, KeyError, TypeError) as e:
        raise ToolError(f"marsala-world --check --json printed no slots for '{scenario}': {e}") from None
    return len(slots)


def say(text=""):
    """A line on stdout, flushed at once (runs take minutes)."""
    print(text, flush=True)


def warn(prog, text):
    """A line "<prog>: text" on stderr."""
    print(f"{prog}: {text}", file=sys.stderr, flush=True)


def run_main(prog, main, argv):
    """Runs a tool's main(argv) and returns its exit code; a ToolError prints "<prog>: message"."""
    try:
        return main(argv)
    except ToolError as e:
        warn(prog, str(e))
        return e.code
    except KeyboardInterrupt:
        return EXIT_INTERRUPTED
    except OSError as e:
        warn(prog, f"{e.filename + ': ' if e.filename else ''}{e.strerror or e}")
        return EXIT_FAILED
