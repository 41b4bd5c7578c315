#!/usr/bin/env python3
"""Fails when an include breaks one of the house's two rules:

1. Pure code never reaches the bus or the wire: the core, terrain, render and scenario libraries and the agent's
   deliberative and executive layers (with agent_context) never include, directly or through other project headers,
   a header of marsala/bus or marsala/protocol, a DDS vendor header, or generated wire types.
2. Layers point one way (LAYER_ORDER): a file of one rung of a ladder never includes a project header of a higher
   rung of the same ladder, nor of another part at its own rung (common never includes the agent, the world or the
   monitor, and those three never include each other; the agent's deliberative layer never includes its executive).

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
# Ladders of layers, lowest rung first; each rung is a list of folders (relative to the repository). A file in a
# rung's folder may include headers of its own folder and of lower rungs only.
LAYER_ORDER = {
    "parts": [["common"], ["agent", "world_server", "monitor"]],
    "agent": [["agent/deliberative"], ["agent/executive"], ["agent/reactive"], ["agent/runtime"]],
    "world_server": [["world_server/rules"], ["world_server/records"], ["world_server/runtime"]],
}
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


def project_path(root, name):
    """The repository path a "marsala/<lib>/..." include names, whether or not the file exists; else None."""
    parts = name.split("/", 2)
    if len(parts) == 3 and parts[0] == "marsala" and parts[1] in LIBRARY_FOLDERS:
        return os.path.join(root, LIBRARY_FOLDERS[parts[1]], parts[2])
    return None


def rung_of(root, path, ladder):
    """(rung index, folder) of the deepest folder of `ladder` holding `path`, or None."""
    rel = os.path.relpath(path, root).replace(os.sep, "/")
    best = None
    for index, folders in enumerate(ladder):
        for folder in folders:
            if rel.startswith(folder + "/") and (best is None or len(folder) > len(best[1])):
                best = (index, folder)
    return best


def layer_violations(root, path):
    """(chain, why) for every include of `path` that points up a ladder or across to a part of the same rung."""
    found = []
    for _, name in includes(path):
        target = project_path(root, name)
        if target is None:
            continue
        for ladder_name, ladder in LAYER_ORDER.items():
            mine, theirs = rung_of(root, path, ladder), rung_of(root, target, ladder)
            if mine is None or theirs is None or mine[1] == theirs[1] or theirs[0] < mine[0]:
                continue
            where = "a higher layer" if theirs[0] > mine[0] else "another part of the same layer"
            found.append(([os.path.relpath(path, root), name], f"{where} ({theirs[1]} above {mine[1]}, {ladder_name})"))
    return found


def layered_files(root):
    folders = sorted({folder for ladder in LAYER_ORDER.values() for rung in ladder for folder in rung})
    seen = set()
    for folder in folders:
        for dirpath, _, names in os.walk(os.path.join(root, folder)):
            for n in sorted(names):
                path = os.path.join(dirpath, n)
                if n.endswith((".hpp", ".cpp", ".h")) and path not in seen:
                    seen.add(path)
                    yield path


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
    layered = list(layered_files(root))
    for path in layered:
        for chain, why in layer_violations(root, path):
            bad += 1
            print(f"include_boundaries: {' -> '.join(chain)}: {why}")
    print(f"include_boundaries: {len(files)} files checked for the wire, {len(layered)} for the layer order, "
          f"{bad} violations")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
