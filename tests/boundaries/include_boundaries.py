#!/usr/bin/env python3
"""Fails when pure code reaches the bus or the wire: the core, terrain, render and scenario libraries and the agent's
deliberative and executive layers (with agent_context) must never include, directly or through other project
headers, a header of marsala/bus or marsala/protocol, a DDS vendor header, or generated wire types.

Usage: include_boundaries.py [ROOT]   (ROOT: the repository, default: two folders up from this file)
Prints each violation as a chain of includes "file -> header -> ... -> forbidden" and exits 1; exits 0 when clean.
"""
import os
import re
import sys

# Where each library's headers live: "marsala/<lib>/<path>" -> <folder>/<path> (cmake/marsala.cmake).
LIBRARY_FOLDERS = {
    "core": "common/core", "terrain": "common/terrain", "render": "common/render", "protocol": "common/protocol",
    "bus": "common/bus", "scenario": "common/scenario", "cli": "common/cli", "agent": "agent",
    "world_server": "world_server", "monitor": "monitor",
}
# The guarded code: every .hpp/.cpp below these paths (a path may also name one file stem).
GUARDED = ["common/core", "common/terrain", "common/render", "common/scenario", "agent/deliberative",
           "agent/executive", "agent/agent_context"]
# What guarded code may never reach.
FORBIDDEN = [
    (re.compile(r"^marsala/(bus|protocol)/"), "a bus or wire-protocol header"),
    (re.compile(r"^(dds/|fastdds/|fastrtps/|fastcdr/)"), "a DDS vendor header"),
    (re.compile(r"^marsala(PubSubTypes)?\.h$"), "generated DDS wire types"),
]
INCLUDE = re.compile(r'^\s*#\s*include\s*([<"])([^>"]+)[>"]', re.M)


def includes(path):
    with open(path, encoding="utf-8", errors="replace") as f:
        return [(m.group(1), m.group(2)) for m in INCLUDE.finditer(f.read())]


def resolve(root, including_file, quote, name):
    """The project file an include names, or None for a system or generated header."""
    if name.startswith("marsala/"):
        parts = name.split("/", 2)
        if len(parts) == 3 and parts[1] in LIBRARY_FOLDERS:
            path = os.path.join(root, LIBRARY_FOLDERS[parts[1]], parts[2])
            return path if os.path.isfile(path) else None
    if quote == '"':
        local = os.path.normpath(os.path.join(os.path.dirname(including_file), name))
        if os.path.isfile(local):
            return local
    return None


def violations(root, start):
    """(chain, why) for every forbidden header reachable from `start`, one per forbidden header."""
    found, seen, stack = [], {start}, [(start, [os.path.relpath(start, root)])]
    while stack:
        path, chain = stack.pop()
        for quote, name in includes(path):
            for pattern, why in FORBIDDEN:
                if pattern.search(name):
                    found.append((chain + [name], why))
            if quote == '"' and name.startswith(".."):
                found.append((chain + [name], "a relative include that leaves the folder"))
            target = resolve(root, path, quote, name)
            if target and target not in seen:
                seen.add(target)
                stack.append((target, chain + [name]))
    return found


def guarded_files(root):
    for guard in GUARDED:
        folder = os.path.join(root, guard)
        if os.path.isdir(folder):
            for dirpath, _, names in os.walk(folder):
                for n in sorted(names):
                    if n.endswith((".hpp", ".cpp", ".h")):
                        yield os.path.join(dirpath, n)
        else:
            for ext in (".hpp", ".cpp"):
                if os.path.isfile(folder + ext):
                    yield folder + ext


def main():
    root = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", ".."))
    files = list(guarded_files(root))
    if not files:
        print(f"include_boundaries: no guarded sources under {root}", file=sys.stderr)
        return 2
    bad = 0
    for path in files:
        for chain, why in violations(root, path):
            bad += 1
            print(f"include_boundaries: {' -> '.join(chain)}: {why}")
    print(f"include_boundaries: {len(files)} files checked, {bad} violations")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
