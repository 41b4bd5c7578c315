#!/usr/bin/env bash
# deploy/experiment.sh end to end: bad arguments and a value marsala-world --check refuses (exit 2, nothing run), then
# a real experiment on the small site (localisation noise 0 and 0.1 m, one seed, two runs at a time): one CSV row per
# run that agrees with that run's summary.json, the statistics, the plot. ctest runs it inside run_isolated.sh; the
# runs go through spawn.sh with the loopback DDS configs.
#
# Usage: experiment_test.sh
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
experiment="$root/deploy/experiment.sh"
scenario="$root/tests/integration/scenarios/site_small.pbtxt"
vary=robot_type.localisation.noise_sd_m

work="$(mktemp -d "${TMPDIR:-/tmp}/marsala-it-experiment.XXXXXX")"
trap 'rm -rf "$work"' EXIT

fail() { echo "FAIL (experiment): $*" >&2; exit 1; }
. "$root/tests/integration/lib.sh"  # field, is_png

# --- 1. bad arguments: exit 2, a message that names the problem, no run ------------------------------------------
expect_usage_error() {  # expect_usage_error PATTERN ARGS...
  local pattern="$1" rc=0
  shift
  "$experiment" --out "$work/bad" "$@" >"$work/stdout.txt" 2>"$work/stderr.txt" || rc=$?
  [ "$rc" -eq 2 ] || { cat "$work/stderr.txt"; fail "experiment.sh $* exited $rc, expected 2"; }
  grep -q -- "$pattern" "$work/stderr.txt" || { cat "$work/stderr.txt"; fail "no '$pattern' in the message"; }
  [ ! -e "$work/bad" ] || fail "experiment.sh $* wrote $work/bad"
}
expect_usage_error "arguments are required: --vary" --scenario "$scenario" --values "0 1"
expect_usage_error "'abc' is not a finite number" --scenario "$scenario" --vary "$vary" --values "0 abc"
expect_usage_error "'0.1 0.1' lists a value twice" --scenario "$scenario" --vary "$vary" --values "0.1 0.1"
expect_usage_error "argument --seeds: '0' is not an integer" --scenario "$scenario" --vary "$vary" --values 0 --seeds 0
expect_usage_error "unrecognized arguments: --team" --scenario "$scenario" --vary "$vary" --values 0 --team 3
expect_usage_error "Localisation has no field 'noise'" --scenario "$scenario" --vary robot_type.localisation.noise \
  --values 0.1
expect_usage_error "noise_sd_m: -1 must be in \[0, 10\] m" --scenario "$scenario" --vary "$vary" --values "0 -1"

# --- 2. a real experiment -----------------------------------------------------------------------------------------
out="$work/out"
"$experiment" --scenario "$scenario" --vary "$vary" --values "0 0.1" --seeds 1 --jobs 2 --out "$out" \
  --label "noise [m]" >"$work/run.txt" 2>&1 || { cat "$work/run.txt"; fail "the experiment failed"; }
csv="$out/experiment.csv"
[ "$(head -1 "$csv")" = \
  "value,seed,completed,completion_steps,wall_seconds,deposited_m3,site_level_fraction,path_length_m,rejected_requests,end_reason,completion" ] ||
  fail "unexpected CSV header: $(head -1 "$csv")"
[ "$(tail -n +2 "$csv" | wc -l)" = 2 ] || { cat "$csv"; fail "expected 2 rows"; }
for v in 0 0.1; do
  s="$out/v$v-s1/summary.json"
  [ -f "$s" ] || fail "no summary for value $v"
  row="$(awk -F, -v v="$v" 'NR > 1 && $1 == v && $2 == 1' "$csv")"
  [ "$(echo "$row" | cut -d, -f4)" = "$(field steps "$s")" ] || fail "value $v: CSV steps differ from the summary"
  [ "$(echo "$row" | cut -d, -f10)" = "$(field end_reason "$s")" ] || fail "value $v: CSV end_reason differs"
  if [ "$v" = 0.1 ]; then
    jq -e --arg o "$vary=0.1" '.overrides == [$o]' "$s" >/dev/null || fail "value 0.1: the run was not given the override"
  else
    jq -e --arg o "$vary=0" '.overrides == [$o]' "$s" >/dev/null || fail "value 0: the run was not given the override"
  fi
done
grep -q "^0.1,1,1," "$out/experiment_stats.csv" || { cat "$out/experiment_stats.csv"; fail "no statistics for 0.1"; }
grep -q "| 0.1 | 1 of 1 |" "$work/run.txt" || { cat "$work/run.txt"; fail "no table row for 0.1"; }
if command -v gnuplot >/dev/null; then
  is_png "$out/experiment.png" || fail "experiment.png missing or not a PNG"
fi
echo "ok: experiment: 2 runs, CSV, statistics and plot agree with the summaries"
