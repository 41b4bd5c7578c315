#!/usr/bin/env bash
# A real run that stalls (docs/runtime.md#stall): tests/integration/scenarios/stall_small.pbtxt, two ramp builders
# without material below a base they cannot reach, through deploy/spawn.sh (world and agents over DDS, ctest runs it
# inside run_isolated.sh). Checks: spawn.sh exits 6; summary.json ends "stalled" exactly stall_steps steps after the
# quiet stretch began, with an account listing both robots (state, material, position, a non-empty waiting_for in
# the agents' words); `marsala-monitor summary` prints that account; the same run on Fast DDS stalls at the same
# step; `marsala-monitor replay` rebuilds the run from run.log to its "stalled" end; a stall_steps out of range is
# refused before anything starts (exit 2, one line naming the field).
#
# Usage: stall_test.sh DOMAIN
set -euo pipefail
domain="$1"
case_name=stall
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
. "$here/lib.sh"
test_workspace stall
scenario="$root/tests/integration/scenarios/stall_small.pbtxt"

run() {  # run OUT DDS [spawn.sh arguments...]: prints spawn.sh's exit code
  local out="$1" dds="$2"
  shift 2
  local rc=0
  "$root/deploy/spawn.sh" --scenario "$scenario" --agents 2 --dds "$dds" --domain "$domain" --out "$out" --quiet \
    --timeout 300 "$@" > "$out.log" 2>&1 || rc=$?
  echo "$rc"
}

rc=$(run "$work/cyclone" cyclone)
[ "$rc" = 6 ] || fail "spawn.sh exited $rc, expected 6 (stalled): $(tail -5 "$work/cyclone.log")"
python3 - "$work/cyclone/summary.json" <<'PY' || fail "summary.json's stall account"
import json, sys
s = json.load(open(sys.argv[1]))
assert s["end_reason"] == "stalled" and s["completed"] is False, s["end_reason"]
stall = s["stall"]
assert stall["stall_steps"] == 120 == s["stall_steps"], stall
assert s["steps"] == stall.get("quiet_since_step", 0) + 120, (s["steps"], stall)
assert s["longest_quiet_steps"] == 120, s["longest_quiet_steps"]
agents = stall["agents"]
assert [a["agent_id"] for a in agents] == [1, 2], agents
for a, p in zip(agents, s["per_agent"]):
    assert a["state"], a
    assert "material_m3" in a and "x_m" in a and "y_m" in a and "z_m" in a, a
    assert a["waiting_for"], a  # the agent said what it waits for
    assert a["waiting_for"] == p["waiting_for"] and a["x_m"] == p["x_m"] and a["state"] == p["state"], (a, p)
    print(f"agent {a['agent_id']} {a['state']} {a.get('material_m3', 0):.4f} m3 at ({a['x_m']}, {a['y_m']}): "
          f"{a['waiting_for']}")
PY
steps=$(field steps "$work/cyclone/summary.json")

report=$("$bin/marsala-monitor" summary "$work/cyclone") || fail "marsala-monitor summary failed"
grep -q "did not complete: it stopped making progress (stalled), after $steps steps" <<<"$report" ||
  fail "monitor summary: no stalled outcome: $report"
grep -q "no rise of the progress and no terrain change for 120 steps" <<<"$report" || fail "monitor summary: $report"
for id in 1 2; do
  grep -Eq "^    agent $id [a-z_]+, [0-9.]+ m3 on board, at \([-0-9., ]+\) m: [^(]" <<<"$report" ||
    fail "monitor summary: no account of agent $id: $report"
done

rc=$(run "$work/fastdds" fastdds)
[ "$rc" = 6 ] || fail "Fast DDS: spawn.sh exited $rc, expected 6"
[ "$(field steps "$work/fastdds/summary.json")" = "$steps" ] ||
  fail "Fast DDS stalled after $(field steps "$work/fastdds/summary.json") steps, Cyclone after $steps"

replay=$("$bin/marsala-monitor" replay "$work/cyclone") || fail "replay failed: $replay"
grep -q "run end: stalled, final terrain sha256 matches the log" <<<"$replay" || fail "replay: $replay"

mkdir -p "$work/bad"
rc=$(run "$work/bad/out" cyclone --set stall_steps=-5)
[ "$rc" = 2 ] || fail "stall_steps=-5: spawn.sh exited $rc, expected 2"
grep -q "stall_steps: -5 must be 0 (never) or in 1..1000000000" "$work/bad/out.log" ||
  fail "stall_steps=-5: $(cat "$work/bad/out.log")"
[ ! -e "$work/bad/out/summary.json" ] || fail "stall_steps=-5: a summary was written"
echo "stall: stalled after $steps steps on both vendors; account and monitor summary checked"
