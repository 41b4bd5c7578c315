#!/usr/bin/env bash
# Faults a dependable run survives (issue 29, docs/runtime.md#silence, #run-folders, #resume, #discovery-star): real
# marsala-world and marsala-agent processes of the ramp scenario (3 agents, Cyclone), each case against the terrain of
# the same run without the fault, measured first in the same test.
#
# Usage: fault_test.sh CASE DOMAIN
#   world-pause      the world SIGSTOPped 30 s; meanwhile a second --resume and a spawn.sh --replace of its folder are
#                    refused (exit 2, naming its pid): the run ends on the uninterrupted terrain
#   resume-late      the world SIGKILLed, resumed 60 s later with the agents still running; then killed again, a byte
#                    flipped near run.log's end, resumed: the damaged tail is cut and named, and the run ends on the
#                    uninterrupted terrain
#   monitors-first   eight marsala-monitor tail started before the world: the agents find it, same terrain (and a bad
#                    --world-timeout: one line naming it, exit 2); then four ddsperf participants holding indices 0..3
#                    before a Cyclone world and a Fast DDS world: same terrain
#   world-cut        namespace hosts on a bridge (LAN profile): the world's host cut off 30 s, same terrain
#   agent-cut        the agents' host cut off 60 s, then back: the team waits (the world hears no agent), every robot
#                    rejoins, same terrain
# world-pause and resume-late run inside run_isolated.sh; the cut cases make their own network and mount namespaces
# (77 = skipped where they cannot be made).
set -euo pipefail
case_name="$1"
domain="$2"
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
# The cut cases: network and mount namespaces of their own (the bridge and /run/netns exist only there).
if [[ "$case_name" == *-cut ]] && [ "${MARSALA_FAULT_INNER:-}" != 1 ]; then
  unshare -n -m --propagation private true 2>/dev/null || { echo "SKIP: no network and mount namespaces here"; exit 77; }
  exec env MARSALA_FAULT_INNER=1 unshare -n -m --propagation private bash "$0" "$case_name" "$domain"
fi
. "$here/lib.sh"  # field, test_workspace
test_workspace fault
scenario="$root/deploy/scenarios/ramp.pbtxt"

# The world and agents of the cut cases run in namespace hosts; `on HOST` prefixes their commands (empty: here).
on() { [ -z "$1" ] || echo ip netns exec "$1"; }
world_host="" agent_host="" dds_config=() vendor=cyclone

# reference: the uninterrupted run's terrain_sha256 (loopback, this namespace).
reference() {
  MARSALA_BUILD_DIR="$(dirname "$bin")" "$root/deploy/spawn.sh" --scenario "$scenario" --agents 3 --domain "$domain" \
    --out "$work/reference" --quiet --timeout 300 >/dev/null || fail "the reference run failed"
  field terrain_sha256 "$work/reference/summary.json"
}
# start_world [ARGS]: the world on world_host into $out (sets world); start_agents: agents 1..3 on agent_host.
start_world() {
  $(on "$world_host") "$bin/marsala-world" --dds "$vendor" --domain "$domain" "${dds_config[@]}" "$@" \
    >>"$out/logs/world.log" 2>&1 &
  world=$!
}
start_agents() {
  pids=()
  for id in 1 2 3; do
    $(on "$agent_host") "$bin/marsala-agent" --scenario "$scenario" --id "$id" --dds "$vendor" --domain "$domain" \
      "${dds_config[@]}" >"$out/logs/agent-$id.log" 2>&1 &
    pids+=($!)
  done
}
# start_mid_run: the reference's terrain into sha, then the run (world and agents) until agent 1 has deposited.
start_mid_run() {
  sha=$(reference)
  start_world --scenario "$scenario" --agents 3 --out "$out"
  start_agents
  mid_run
}
# mid_run: waits until agent 1 has deposited (events.log is written live).
mid_run() {
  for _ in $(seq 1 3000); do grep -q '"agent":1,"kind":"deposited"' "$out/events.log" 2>/dev/null && return 0; sleep 0.02; done
  fail "agent 1 never deposited (see $out/logs)"
}
# finish EXPECTED_SHA WHAT: the world and every agent exit 0 and the run ends complete on EXPECTED_SHA.
finish() {
  wait "$world" || { tail -20 "$out/logs/world.log"; fail "the world exited non-zero"; }
  for pid in "${pids[@]}"; do wait "$pid" || { tail -n 3 "$out"/logs/agent-*.log; fail "an agent exited non-zero"; }; done
  [ "$(field completed "$out/summary.json")" = "true" ] || { cat "$out/summary.json"; fail "the run did not complete"; }
  [ "$(field terrain_sha256 "$out/summary.json")" = "$1" ] ||
    fail "$2: ended on $(field terrain_sha256 "$out/summary.json"), uninterrupted on $1"
  ! grep -q '"kind":"dropped"' "$out/events.log" || { grep '"kind":"dropped"' "$out/events.log"; fail "$2: a drop"; }
  echo "ok: $2: completed in $(field steps "$out/summary.json") steps on the uninterrupted terrain $1"
}
# refused_with_pid RC LOG: a refusal of a folder in use, exit 2, one line naming the world's pid.
refused_with_pid() {
  [ "$1" -eq 2 ] || { cat "$2"; fail "a second start on a folder in use exited $1, not 2"; }
  [ "$(wc -l <"$2")" -eq 1 ] && grep -q "in use by marsala-world pid $3" "$2" || { cat "$2"; fail "no one line naming pid $3"; }
}
# bridge_lab: hosts h1 (the world) and h2 (the agents) on a bridge (lib.sh bridge_hosts), the LAN profile; cut HOST /
# reconnect HOST detach its port from the bridge and attach it again (a cable pulled at the switch).
bridge_lab() {
  bridge_hosts 10.78.0 2
  world_host=h1 agent_host=h2 dds_config=(--dds-config "$root/deploy/dds/cyclone-lan.xml")
}
cut() { ip link set "port${1#h}" nomaster; }
reconnect() { ip link set "port${1#h}" master br0; }

out="$work/run"
mkdir -p "$out/logs"
case "$case_name" in
  world-pause)
    start_mid_run
    kill -STOP "$world"
    # A paused world still owns its folder: a second --resume, and spawn.sh --replace, are refused.
    rc=0
    "$bin/marsala-world" --resume "$out" --dds cyclone --domain "$domain" >"$work/second.log" 2>&1 || rc=$?
    refused_with_pid "$rc" "$work/second.log" "$world"
    rc=0
    MARSALA_BUILD_DIR="$(dirname "$bin")" "$root/deploy/spawn.sh" --scenario "$scenario" --agents 3 --out "$out" \
      --replace --quiet >/dev/null 2>"$work/replace.log" || rc=$?
    refused_with_pid "$rc" "$work/replace.log" "$world"
    [ -f "$out/logs/agent-1.log" ] || fail "spawn.sh --replace removed the live run's logs"
    sleep 30
    kill -CONT "$world"
    finish "$sha" "world paused 30 s, a second --resume and a --replace refused meanwhile"
    ;;
  resume-late)
    start_mid_run
    kill -KILL "$world"
    wait "$world" 2>/dev/null || true
    sleep 60
    start_world --resume "$out"
    # Let it go on to step 120 at least, then kill it again and flip one byte of the last record but one.
    step_reached() { sed -n 's/^{"step":\([0-9]*\),.*/\1/p' "$out/events.log" | awk '$1 >= 120 { f = 1 } END { exit !f }'; }
    for _ in $(seq 1 3000); do step_reached && break; sleep 0.02; done
    step_reached || fail "the resumed run never reached step 120 (see $out/logs)"
    kill -KILL "$world"
    wait "$world" 2>/dev/null || true
    size=$(stat -c %s "$out/run.log")
    python3 - "$out/run.log" $((size - 300)) <<'EOF'
import sys
path, at = sys.argv[1], int(sys.argv[2])
data = bytearray(open(path, "rb").read())
data[at] ^= 0xFF
open(path, "wb").write(data)
EOF
    start_world --resume "$out"
    finish "$sha" "world killed, resumed 60 s later, killed, a byte flipped near run.log's end, resumed"
    grep -q "cut run.log's damaged tail: .*damaged record at byte [0-9]*" "$out/logs/world.log" ||
      fail "the resume did not name the damaged record's offset"
    grep -q "the world went back to step" "$out/logs/agent-1.log" || echo "note: the cut held no step agent 1 had answered"
    ;;
  monitors-first)
    # Bad input first: a --world-timeout that is negative or not a number is one line naming it, exit 2.
    for bad in -1 soon; do
      rc=0
      "$bin/marsala-agent" --scenario "$scenario" --id 1 --world-timeout "$bad" >/dev/null 2>"$work/bad.log" || rc=$?
      [ "$rc" -eq 2 ] && [ "$(wc -l <"$work/bad.log")" -eq 1 ] && grep -q -- "--world-timeout.*'$bad'" "$work/bad.log" ||
        { cat "$work/bad.log"; fail "--world-timeout $bad: exit $rc, not one line naming it and exit 2"; }
    done
    sha=$(reference)
    monitors=()
    for i in 1 2 3 4 5 6 7 8; do
      "$bin/marsala-monitor" tail --dds cyclone --domain "$domain" >"$out/logs/monitor-$i.log" 2>&1 &
      monitors+=($!)
    done
    sleep 2
    start_world --scenario "$scenario" --agents 3 --out "$out" --admit-timeout 30
    start_agents
    finish "$sha" "eight monitors started before the world"
    for pid in "${monitors[@]}"; do kill -TERM "$pid" 2>/dev/null || true; wait "$pid" 2>/dev/null || true; done
    # Four participants of another program (ddsperf, cyclonedds-tools) hold indices 0..3 before the world starts:
    # the world discovers on a port of its own that no automatic index takes, the agents probe it, and the run
    # completes on the same terrain, a Cyclone run and a Fast DDS run (docs/runtime.md#discovery-star).
    others=()
    for i in 1 2 3 4; do ddsperf -D 120 -i "$domain" sub >/dev/null 2>&1 & others+=($!); done
    sleep 2
    for vendor in cyclone fastdds; do
      out="$work/others-$vendor"
      mkdir -p "$out/logs"
      start_world --scenario "$scenario" --agents 3 --out "$out" --admit-timeout 30
      start_agents
      finish "$sha" "four participants of another program holding indices 0..3 before a $vendor world"
    done
    vendor=cyclone
    for pid in "${others[@]}"; do kill -TERM "$pid" 2>/dev/null || true; wait "$pid" 2>/dev/null || true; done
    ;;
  world-cut|agent-cut)
    bridge_lab
    start_mid_run
    host=$world_host seconds=30
    [ "$case_name" = agent-cut ] && host=$agent_host seconds=60
    cut "$host"
    sleep "$seconds"
    reconnect "$host"
    finish "$sha" "the $( [ "$host" = h1 ] && echo world || echo agents)' host cut off $seconds s"
    ;;
  *) fail "unknown case" ;;
esac
