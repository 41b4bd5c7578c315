#!/usr/bin/env bash
# marsala-agent --dump-map on real processes (docs/runtime.md#mapping), inside run_isolated.sh:
#   1. spawn.sh --dump-maps runs tests/integration/scenarios/slope_sensors.pbtxt with its laser robot alone (agent 1,
#      150 steps): OUT/maps/agent-1-height.asc and agent-1-map.json are written, the record's known cells are the
#      map's non-NODATA cells, and its known cells agree with the run's terrain_final.asc (marsala-terrain compare:
#      over 2,000 known cells, median error <= 1 cm and 95th percentile <= 3 cm: the laser's range noise is 1 cm);
#   2. a second run (another run id) whose agent dumps into the same folder: the agent exits 2 once admitted, with one
#      line naming the first run's record, and the first run's files are left as they were (same bytes, no .tmp);
#   3. bad folders at start-up, before any DDS traffic: a regular file, a malformed record: exit 2, one line naming it.
# Usage: map_dump_test.sh DOMAIN
set -euo pipefail
case_name=dump
domain="$1"
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
. "$here/lib.sh"
test_workspace map_dump
scenario="$root/tests/integration/scenarios/slope_sensors.pbtxt"
out="$work/run"
maps="$out/maps"

# 1. One scanning robot, its map dumped at the run's end.
rc=0
"$root/deploy/spawn.sh" --scenario "$scenario" --agents 1 --domain "$domain" --out "$out" --quiet --timeout 300 \
  --max-steps 150 --dump-maps >"$work/spawn1.log" 2>&1 || rc=$?
[ "$rc" = 0 ] || [ "$rc" = 3 ] || { cat "$work/spawn1.log"; fail "spawn.sh exit $rc"; }
[ -f "$maps/agent-1-height.asc" ] || fail "no agent-1-height.asc in $maps (logs: $out/logs)"
[ -f "$maps/agent-1-map.json" ] || fail "no agent-1-map.json in $maps"
run_id=$(jq -r .run_id "$out/summary.json")
jq -e --arg run "$run_id" '.run_id == $run and .agent_id == 1 and .end == "run_over" and .sensor == "laser" and
  .height_file == "agent-1-height.asc" and .cells == 11200' "$maps/agent-1-map.json" >/dev/null ||
  { cat "$maps/agent-1-map.json"; fail "the record does not describe agent 1's map of run $run_id"; }
known=$(awk 'NR > 6 { for (i = 1; i <= NF; i++) if ($i != "-9999") n++ } END { print n + 0 }' \
  "$maps/agent-1-height.asc")
[ "$known" = "$(jq .known_cells "$maps/agent-1-map.json")" ] ||
  fail "the map has $known known cells, its record says $(jq .known_cells "$maps/agent-1-map.json")"
"$bin/marsala-terrain" compare "$maps/agent-1-height.asc" "$out/terrain_final.asc" \
  --scenario "$scenario" --robot-type laser_husky --json >"$work/compare.json" || fail "marsala-terrain compare failed"
jq -e '.known_cells > 2000 and .median_error_m <= 0.01 and .p95_error_m <= 0.03' "$work/compare.json" >/dev/null ||
  { cat "$work/compare.json"; fail "the dumped map does not agree with terrain_final.asc"; }
sha256sum "$maps"/* >"$work/first.sha256"

# 2. Another run into the same folder: refused once admitted, nothing written.
world_log="$work/world2.log"
"$bin/marsala-world" --scenario "$scenario" --agents 1 --domain "$domain" --out "$work/run2" --run-id other-run \
  --max-steps 20 --quiet >"$world_log" 2>&1 &
world_pid=$!
trap 'kill -TERM "$world_pid" 2>/dev/null || true; rm -rf "$work"' EXIT
rc=0
"$bin/marsala-agent" --scenario "$scenario" --id 1 --domain "$domain" --dump-map "$maps" --admit-timeout 60 \
  >"$work/agent2.out" 2>"$work/agent2.err" || rc=$?
kill -TERM "$world_pid" 2>/dev/null || true
wait "$world_pid" 2>/dev/null || true
[ "$rc" = 2 ] || { cat "$work/agent2.err"; fail "an agent dumping into another run's folder: exit $rc, expected 2"; }
grep -q "agent-1-map.json holds a map of run '$run_id', not of this run 'other-run'" "$work/agent2.err" ||
  fail "no clear refusal: $(cat "$work/agent2.err")"
sha256sum -c --quiet "$work/first.sha256" || fail "the first run's maps changed"
[ "$(ls "$maps" | wc -l)" = 2 ] || fail "the maps folder holds more than the first run's two files: $(ls "$maps")"

# 3. Bad folders, refused at start-up (no world runs now: no admission is awaited).
expect_refused() {  # expect_refused DIR NAMED
  local err="$work/agent3.err" code=0
  "$bin/marsala-agent" --scenario "$scenario" --id 1 --domain "$domain" --dump-map "$1" --admit-timeout 1 \
    >/dev/null 2>"$err" || code=$?
  [ "$code" = 2 ] || fail "--dump-map $1: exit $code, expected 2 ($(cat "$err"))"
  [ "$(wc -l <"$err")" = 1 ] && grep -q "$2" "$err" || fail "--dump-map $1: not one line naming $2: $(cat "$err")"
}
expect_refused "$out/summary.json" "summary.json: not a folder"
mkdir -p "$work/broken"
echo '{"run_id": ' >"$work/broken/agent-2-map.json"
expect_refused "$work/broken" "agent-2-map.json"
echo "ok: map dump: $(jq -c '{known_cells, median_error_m, p95_error_m, believed_passable_not}' "$work/compare.json")" \
  "of run $run_id; another run refused; bad folders refused"
