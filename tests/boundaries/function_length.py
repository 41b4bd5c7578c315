#!/usr/bin/env python3
"""Fails when a function outside the tests is longer than LIMIT lines (default 120): long functions hide state machines
and mix concerns; split them by meaning (a CLI per subcommand, a loop per phase).

Usage: function_length.py [ROOT [LIMIT]]   (ROOT: the repository, default: two folders up from this file)
A function is found by its head: a line ending in ") {" (or "const {" ...) whose statement starts at most 4 columns in
and is not a control statement; it ends at the matching brace. Prints each long one as "file:line: N lines: head"
and exits 1; exits 0 when none is.
"""
import os
import re
import sys

root = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", ".."))
limit = int(sys.argv[2]) if len(sys.argv) > 2 else 120
ends_head = re.compile(r'\)\s*(const)?\s*(noexcept)?\s*(override)?\s*(->\s*[\w:<>]+)?\s*\{\s*$')
kw = re.compile(r'^\s*(if|for|while|switch|else|do|catch|return|namespace|class|struct|case|\}|\[|//)')
long_ones = 0
checked = 0
for dp, dn, fn in os.walk(root):
    dn[:] = sorted(d for d in dn if not d.startswith((".", "build", "out")) and not (dp == root and d == "tests"))
    if os.path.basename(dp) == "node_modules":
        continue
    for f in sorted(fn):
        if not f.endswith((".cpp", ".hpp")):
            continue
        p = os.path.join(dp, f)
        checked += 1
        lines = open(p, encoding="utf-8", errors="replace").read().split("\n")
        i = 0
        while i < len(lines):
            l = lines[i]
            if ends_head.search(l):
                s = i
                while s > 0 and lines[s - 1].rstrip().endswith((",", "(")):
                    s -= 1
                first = lines[s]
                indent = len(first) - len(first.lstrip())
                if indent <= 4 and not kw.match(first) and "=" not in first.split("(")[0] and "(" in first:
                    depth = 0
                    for j in range(i, len(lines)):
                        depth += lines[j].count("{") - lines[j].count("}")
                        if depth <= 0:
                            break
                    n = j - s + 1
                    if n > limit:
                        long_ones += 1
                        print(f"function_length: {os.path.relpath(p, root)}:{s+1}: {n} lines: {first.strip()[:90]}")
                    i = j + 1
                    continue
            i += 1
print(f"function_length: {checked} files checked, {long_ones} functions over {limit} lines")
sys.exit(1 if long_ones else 0)
