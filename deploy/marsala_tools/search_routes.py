"""Route search (issue 14, paper Fig. 3): path scenarios with separate construction sites on a DEM, found with
`marsala-terrain route`. Front end: deploy/search_routes.py."""

import argparse
import json
import math
import os
import subprocess
import tempfile

from . import common
from .common import UsageError, say

PROG = "search_routes"
DESCRIPTION = """\
For every window (a square of --size metres at each X0 Y0 of --windows, cropped and resampled as a scenario's
terrain is), takes the points of a grid (--spacing) that are occupiable for the payload and stand on their own
ground (MARS gap below --min-depth; --base-gap relaxes it for bases), plans the builders' route between every two of
them --min-dist .. --max-dist apart that the payload cannot drive yet (marsala-terrain route --pairs), keeps the
routes with at least --min-sites construction sites separated by natural ground, and ranks them by volume. Prints
what it searched and the best routes; --json FILE writes every kept route.

Coordinates are the DEM's (a crop keeps them), as in deploy/scenarios/*.pbtxt. MARSALA_BUILD_DIR (default build/)
names the build with bin/marsala-terrain.

Example (what deploy/scenarios/path_gale_sites.pbtxt was chosen with; about 6 min):
  deploy/search_routes.py --dem ../shared/data/terrains/gale_crater_1m.asc"""
SEARCHED_FIELDS = ("x0", "y0", "grid", "occupiable", "targets", "pairs", "kept", "best_m3", "largest_m3")


def windows_type(text):
    """An argparse type: "X0,Y0 X0,Y0 ..." as [(x0, y0)] [m]."""
    try:
        windows = [tuple(float(v) for v in w.split(",")) for w in text.split()]
        if not windows or any(len(w) != 2 for w in windows):
            raise ValueError
    except ValueError:
        raise argparse.ArgumentTypeError("expects X0,Y0 pairs separated by spaces") from None
    return windows


def build_parser():
    """The route search's command line."""
    p = common.ArgumentParser(prog="deploy/search_routes.py", description=DESCRIPTION)
    p.add_argument("--dem", required=True, metavar="FILE", help="terrain file (.asc or .tif)")
    p.add_argument("--windows", type=windows_type,
                   default="0,0 94,0 188,0 0,88 94,88 188,88 0,177 94,177 188,177 90,90",
                   help="lower-left corners X0,Y0 of the windows [m] (default: a 3 x 3 grid over 348 x 337 m "
                        "and path_gale's window)")
    p.add_argument("--size", type=float, default=160.0, help="window side [m]")
    p.add_argument("--cell-size", type=float, default=0.25, help="resample to this cell size [m]")
    p.add_argument("--spacing", type=float, default=4.0, help="grid of candidate points [m]")
    p.add_argument("--margin", type=float, default=4.0, help="keep points this far inside the window [m]")
    p.add_argument("--min-dist", type=float, default=15.0, help="shortest base-target distance [m]")
    p.add_argument("--max-dist", type=float, default=40.0, help="longest base-target distance [m]")
    p.add_argument("--kappa", type=float, default=0.2, help="payload (and construction) slope [m/m]")
    p.add_argument("--delta", type=float, default=2.0, help="payload body [m]")
    p.add_argument("--eps", type=float, default=0.05, help="payload discontinuity [m]")
    p.add_argument("--width", type=float, default=3.0, help="construction band width [m]")
    p.add_argument("--local-radius", type=float, default=0.0,
                   help="take the MARS bound within this half-window only [m] (0, the default: the whole window, "
                        "which the builders' ramps reach in the end)")
    p.add_argument("--min-depth", type=float, default=0.016,
                   help="gap a cell needs to be built on: one cube layer [m] (0.1 m cubes on 0.25 m cells)")
    p.add_argument("--base-gap", type=float, default=0.0,
                   help="largest MARS gap at the base [m] (default: below --min-depth, on its own ground like the "
                        "target; bases in pits several metres deep stall the builders)")
    p.add_argument("--min-sites", type=common.positive_int(999), default=3,
                   help="keep routes with at least this many sites")
    p.add_argument("--rank", choices=("volume", "site"), default="volume",
                   help="rank by the route's volume, or by the volume of its --min-sites-th largest site")
    p.add_argument("--top", type=int, default=15, help="routes to print")
    p.add_argument("--json", help="write every kept route to this file")
    return p


def run_route(binary, common_args, pairs):
    """Runs marsala-terrain route on `pairs` [(fx, fy, tx, ty)] [m]; returns its routes (JSON)."""
    with tempfile.NamedTemporaryFile("w", suffix=".txt", delete=False) as f:
        for p in pairs:
            f.write("%.4f %.4f %.4f %.4f\n" % p)
        name = f.name
    try:
        out = subprocess.run([binary, "route"] + common_args + ["--json", "--pairs", name], check=True,
                             stdout=subprocess.PIPE, text=True).stdout
    except subprocess.CalledProcessError as e:
        raise common.ToolError(f"marsala-terrain route failed (exit {e.returncode})") from None
    finally:
        os.unlink(name)
    return json.loads(out)["routes"]


def centre(v, origin, cs):
    """The centre of the cell holding coordinate v [m] on a grid starting at origin with cells of cs [m]."""
    return origin + (math.floor((v - origin) / cs) + 0.5) * cs


def search_window(binary, args, x0, y0):
    """The kept routes of the window at (x0, y0) [m] and what was searched there (SEARCHED_FIELDS)."""
    cs = args.cell_size
    common_args = [args.dem, "--crop", str(x0), str(y0), str(args.size), str(args.size), "--cell-size", str(cs),
                   "--zero-base", "--kappa", str(args.kappa), "--delta", str(args.delta), "--eps", str(args.eps),
                   "--width", str(args.width), "--local-radius", str(args.local_radius), "--min-depth",
                   str(args.min_depth), "--min-natural", str(args.delta)]
    n = int((args.size - 2 * args.margin) // args.spacing) + 1
    grid = [(centre(x0 + args.margin + i * args.spacing, x0, cs), centre(y0 + args.margin + j * args.spacing, y0, cs))
            for j in range(n) for i in range(n)]
    # A route from a point to itself says whether the point is occupiable and on its own ground.
    here = run_route(binary, common_args, [(x, y, x, y) for x, y in grid])
    points = [(p, r["from_region"], r["from_gap_m"]) for p, r in zip(grid, here) if r["from_occupiable"]]
    bases = [p for p in points if p[2] < max(args.base_gap, args.min_depth)]
    targets = [p for p in points if p[2] < args.min_depth]
    # Targets on their own ground (no gap for the builders to fill there), bases with at most --base-gap, in different
    # payload regions: within one the payload drives already (the run would be over at its start).
    pairs = [(a[0], a[1], b[0], b[1]) for a, ra, _ in bases for b, rb, _ in targets
             if ra != rb and args.min_dist <= math.hypot(a[0] - b[0], a[1] - b[1]) <= args.max_dist]
    routes = run_route(binary, common_args, pairs) if pairs else []
    blocked = [r for r in routes if not r["navigable_now"]]
    largest = max(blocked, key=lambda r: r["volume_m3"], default=None)
    good = [r for r in blocked if len(r["sites"]) >= args.min_sites]
    for r in good:
        r["window"] = [x0, y0]
    best = max((r["volume_m3"] for r in good), default=0.0)
    top = largest["volume_m3"] if largest else 0.0
    say("window [%g, %g] + %g m: %d grid points, %d occupiable (%d on their own ground), %d pairs in different "
        "regions, %d with >= %d sites (best %.1f m^3); largest route volume %.1f m^3 (%d sites)"
        % (x0, y0, args.size, len(grid), len(points), len(targets), len(pairs), len(good), args.min_sites, best, top,
           len(largest["sites"]) if largest else 0))
    return good, (x0, y0, len(grid), len(points), len(targets), len(pairs), len(good), best, top)


def report(args, kept, searched):
    """Ranks the kept routes, prints the best, writes --json."""

    def nth_site(r):
        """The volume of the route's --min-sites-th largest site [m^3]."""
        return sorted((s["volume_m3"] for s in r["sites"]), reverse=True)[args.min_sites - 1]

    kept.sort(key=lambda r: -(nth_site(r) if args.rank == "site" else r["volume_m3"]))
    say("\n%d windows, %d pairs planned, %d routes with >= %d sites; best by %s (MARS gap within %s, %g m band):"
        % (len(searched), sum(s[5] for s in searched), len(kept), args.min_sites, args.rank,
           "%g m" % args.local_radius if args.local_radius > 0 else "the window", args.width))
    for r in kept[:args.top]:
        sites = ", ".join("%.1f-%.1f m %.1f m^3" % (s["from_m"], s["to_m"], s["volume_m3"]) for s in r["sites"])
        say("  [%g, %g]  (%.3f, %.3f) -> (%.3f, %.3f)  %.1f m  %.1f m^3  %d sites: %s" % (
            r["window"][0], r["window"][1], r["from"][0], r["from"][1], r["to"][0], r["to"][1], r["length_m"],
            r["volume_m3"], len(r["sites"]), sites))
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"searched": [dict(zip(SEARCHED_FIELDS, s)) for s in searched], "routes": kept}, f, indent=1)


def search(argv):
    """Searches every window and reports; returns the exit code."""
    args = build_parser().parse_args(argv)
    if not os.path.isfile(args.dem):
        raise UsageError(f"terrain file '{args.dem}' not found")
    binary = common.binary("marsala-terrain")
    kept, searched = [], []
    for x0, y0 in args.windows:
        good, what = search_window(binary, args, x0, y0)
        kept += good
        searched.append(what)
    report(args, kept, searched)
    return common.EXIT_OK


def main(argv):
    """deploy/search_routes.py: returns the exit code."""
    return common.run_main(PROG, search, argv)
