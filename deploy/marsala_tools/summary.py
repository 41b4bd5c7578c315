"""A run's summary.json (written by marsala-world), read into the values the tools' CSV rows hold."""

import json
import os
import re
from dataclasses import dataclass


@dataclass
class Summary:
    """What the tools take from a summary.json; fields an older build may not write read as 0 or none."""

    completed: bool
    steps: int
    wall_seconds: float          # [s]
    deposited_m3: float          # [m^3]
    path_length_m: float         # [m] the payload's constructed path (payload_path runs)
    idle_steps: int              # steps in which no robot deposited
    site_level_fraction: float   # the final level fraction (level_site runs)
    rejected_requests: int
    end_reason: str              # completed, max_steps, no_live_agents, signal, stalled
    completion: str              # the scenario's completion kind: payload_path, level_site, ...
    sites: list                  # [(from_m, to_m)] the construction sites along the payload's final path [m]
    material: tuple = (0.0, 0.0, 0.0, 0.0)  # summary.json's material: deposited, needed [m^3], ratio, off band [m^3]

    @property
    def idle_fraction(self):
        """idle_steps / steps, 0 for a run of no steps."""
        return self.idle_steps / self.steps if self.steps > 0 else 0.0


def _number(doc, key, kind):
    value = doc.get(key)
    if value is None:
        return kind(0)
    if isinstance(value, str):  # protobuf's JSON spells NaN, Infinity and 64-bit integers as strings
        value = float(value)
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ValueError(f"{key} is not a number")
    return kind(value)


def _text(doc, key):
    value = doc.get(key) or ""
    if not isinstance(value, str):
        raise ValueError(f"{key} is not a string")
    return value


def read_summary(path):
    """The Summary of a summary.json; ValueError (or OSError) when the file is not one."""
    with open(path, encoding="utf-8") as f:
        doc = json.load(f)
    if not isinstance(doc, dict):
        raise ValueError("not an object")
    material = doc.get("material") or {}
    if not isinstance(material, dict):
        raise ValueError("material is not an object")
    sites = doc.get("construction_sites") or []
    if not isinstance(sites, list) or not all(isinstance(s, dict) for s in sites):
        raise ValueError("construction_sites is not a list of objects")
    return Summary(completed=doc.get("completed") is True, steps=_number(doc, "steps", int),
                   wall_seconds=_number(doc, "wall_seconds", float),
                   deposited_m3=_number(doc, "deposited_volume_m3", float),
                   path_length_m=_number(doc, "path_length_m", float), idle_steps=_number(doc, "idle_steps", int),
                   site_level_fraction=_number(doc, "site_level_fraction", float),
                   rejected_requests=_number(doc, "rejected_requests", int), end_reason=_text(doc, "end_reason"),
                   completion=_text(doc, "completion"),
                   sites=[(_number(s, "from_m", float), _number(s, "to_m", float)) for s in sites],
                   material=tuple(_number(material, k, float)
                                  for k in ("deposited_m3", "needed_m3", "ratio", "off_band_m3")))


def csv_word(text):
    """A text as one CSV word: commas and white space become '_'."""
    return re.sub(r"[,\s]", "_", text)


# marsala-world's exit codes for a run that ended with its summary written (spawn.sh passes them on): completed,
# max_steps, no_live_agents, stopped by a signal (spawn.sh's --timeout), stalled, completed short of slots.
ENDED_EXIT_CODES = (0, 3, 4, 5, 6, 7)


def run_summary(run_dir, exit_code):
    """(Summary, None) for a run that ended with a readable run_dir/summary.json, else (None, why not)."""
    path = os.path.join(run_dir, "summary.json")
    if exit_code not in ENDED_EXIT_CODES or not os.path.isfile(path):
        return None, f"spawn.sh exit {exit_code}, no summary"
    try:
        return read_summary(path), None
    except (OSError, ValueError, OverflowError) as e:
        return None, f"unreadable {path}: {e}"


def failure_lines(name, run_dir, problem, tail=5):
    """The lines that tell of a failed run: "<name>: FAILED (problem; ...)", then the last `tail` lines of its
    spawn.log, indented."""
    log = os.path.join(run_dir, "spawn.log")
    lines = [f"{name}: FAILED ({problem}; see {log} and {run_dir}/logs)"]
    try:
        with open(log, encoding="utf-8", errors="replace") as f:
            lines += ["    " + line.rstrip("\n") for line in f.readlines()[-tail:]]
    except OSError:
        pass
    return lines
