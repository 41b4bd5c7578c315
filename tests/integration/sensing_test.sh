#!/usr/bin/env bash
# deploy/experiments/sensing.sh end to end, small: bad arguments and a noise marsala-world --check refuses (exit 2,
# nothing written), then the ramp with ground-truth and laser robots, noise 5 cm, one seed, 20 steps: one CSV row per
# run that agrees with its summary.json, every robot's map compared (known cells, errors), the statistics, the plot.
# ctest runs it inside run_isolated.sh; the runs go through spawn.sh with the loopback DDS configs.
#
# Usage: sensing_test.sh
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
sensing="$root/deploy/experiments/sensing.sh"

work="$(mktemp -d "${TMPDIR:-/tmp}/marsala-it-sensing.XXXXXX")"
trap 'rm -rf "$work"' EXIT

fail() { echo "FAIL (sensing): $*" >&2; exit 1; }
. "$root/tests/integration/lib.sh"  # field, is_png, expect_tool_usage_error

# --- 1. bad arguments: exit 2, a message that names the problem, nothing written ----------------------------------
expect_usage_error() { expect_tool_usage_error "$sensing" "$work" "$@"; }  # PATTERN ARGS...
expect_usage_error "'sonar' is not one of ground_truth, rgbd, laser" --sensors "laser sonar"
expect_usage_error "'site' is not one of ramp, path_generated" --scenarios site
expect_usage_error "noise_sd_m: -1 must be in \[0, 10\] m" --noises "0 -1"
expect_usage_error "argument --seeds: '0' is not an integer" --seeds 0

# --- 2. a real, small experiment ----------------------------------------------------------------------------------
out="$work/out"
"$sensing" --scenarios ramp --sensors "ground_truth laser" --noises 0.05 --seeds 1 --max-steps 20 --out "$out" \
  >"$work/run.txt" 2>&1 || { cat "$work/run.txt"; fail "the experiment failed"; }
csv="$out/sensing.csv"
[ "$(head -1 "$csv")" = \
  "scenario,sensor,noise_sd_m,seed,completed,completion_steps,deposited_m3,rejected_requests,end_reason,robots,known_cells,median_error_m,p95_error_m,believed_passable_not" ] ||
  fail "unexpected CSV header: $(head -1 "$csv")"
[ "$(tail -n +2 "$csv" | wc -l)" = 2 ] || { cat "$csv"; fail "expected 2 rows"; }
for sensor in ground_truth laser; do
  run="$out/ramp-$sensor/v0.05-s1"
  s="$run/summary.json"
  [ -f "$s" ] || fail "$sensor: no summary"
  row="$(awk -F, -v s="$sensor" 'NR > 1 && $2 == s' "$csv")"
  [ "$(echo "$row" | cut -d, -f6)" = "$(field steps "$s")" ] || fail "$sensor: CSV steps differ from the summary"
  [ "$(echo "$row" | cut -d, -f8)" = "$(field rejected_requests "$s")" ] || fail "$sensor: CSV refusals differ"
  [ "$(echo "$row" | cut -d, -f10)" = 3 ] || fail "$sensor: expected the maps of 3 robots: $row"
  [ "$(ls "$run/maps/"*-height.asc | wc -l)" = 3 ] || fail "$sensor: expected 3 dumped maps"
  # The median robot's map, compared again by hand, gives the row's known cells as one of the robots' counts.
  known="$(echo "$row" | cut -d, -f11)"
  counts="$(for m in "$run/maps/"*-height.asc; do
    "${MARSALA_BUILD_DIR:-$root/build}/bin/marsala-terrain" compare "$m" "$run/terrain_final.asc" \
      --scenario "$root/deploy/scenarios/ramp.pbtxt" --json | jq .known_cells; done | sort -n | sed -n 2p)"
  [ "$known" = "$counts" ] || fail "$sensor: known cells $known, the median robot's map has $counts"
done
grep -q "^ramp,laser,0.05,1,0,20," "$out/sensing_stats.csv" || { cat "$out/sensing_stats.csv"; fail "no statistics"; }
if command -v gnuplot >/dev/null; then
  is_png "$out/sensing.png" || fail "sensing.png missing or not a PNG"
fi
echo "ok: sensing: 2 runs, CSV with the robots' map errors, statistics and plot agree with the summaries"
