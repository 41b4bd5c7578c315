#!/usr/bin/env bash
# Discovery without multicast (--peers, docs/runtime.md#peers): four network namespaces (h1..h4) on a bridge with
# multicast off on every interface and an nftables rule on every host that counts and drops 224.0.0.0/4. The world runs
# on h1, one ramp agent on each of h2, h3 and h4, every process given only `--peers 10.77.0.1` (the world's address)
# and no profile. Four teams: Cyclone, Fast DDS, a Cyclone world with Fast DDS agents and a Fast DDS world with both.
# Each must end on the loopback run's terrain_sha256 after the same capped steps (every step crosses the hosts); a
# monitor on h4 (`marsala-monitor status --peers`) must see each run. Then: an agent whose peers name no world exits 1
# naming them. One control datagram per host to 239.255.0.1 shows the filter live; after it, no host sent or received a
# single multicast packet.
# Usage: peers_test.sh DOMAIN [STEPS] (default 100; 298 runs ramp 3 to completion). Exits 77 (skipped) where namespaces, bridges or nftables are not to be had.
set -euo pipefail
domain="$1"
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
bin="${MARSALA_BUILD_DIR:-$root/build}/bin"
scenario="$root/deploy/scenarios/ramp.pbtxt"
steps_cap="${2:-100}"
fail() { echo "FAIL (multihost peers): $*" >&2; exit 1; }

# Private network and mount namespaces of our own: the bridge and /run/netns exist only there.
if [ "${MARSALA_MULTIHOST_INNER:-}" != 1 ]; then
  unshare -n -m --propagation private true 2>/dev/null || { echo "SKIP: no network and mount namespaces here"; exit 77; }
  command -v nft >/dev/null || { echo "SKIP: no nft (apt-get install nftables)"; exit 77; }
  exec env MARSALA_MULTIHOST_INNER=1 unshare -n -m --propagation private bash "$0" "$@"
fi
work="$(mktemp -d "${TMPDIR:-/tmp}/marsala-multihost-peers.XXXXXX")"
trap '[ -n "${MARSALA_KEEP_WORK:-}" ] || rm -rf "$work"' EXIT
. "$root/tests/integration/lib.sh"  # bridge_hosts, no_multicast, multicast_drops, field
bridge_hosts 10.77.0 4
no_multicast 4
for h in h1 h2 h3 h4; do
  ip netns exec "$h" bash -c 'echo control >/dev/udp/239.255.0.1/7400' 2>/dev/null || true
  [ "$(multicast_drops "$h")" = "1 0" ] || fail "the filter on $h did not count the control datagram: $(multicast_drops "$h")"
done

# The reference: the same team on loopback (in this namespace, which has lo only). Exit 3: ended at max_steps, 0:
# completed (a cap at or above 298).
rc=0
MARSALA_BUILD_DIR="$(dirname "$bin")" "$root/deploy/spawn.sh" --scenario "$scenario" --agents 3 --domain "$domain" \
  --max-steps "$steps_cap" --out "$work/reference" --quiet >/dev/null 2>"$work/reference.err" || rc=$?
[ "$rc" -eq 3 ] || [ "$rc" -eq 0 ] || fail "the loopback reference run exited $rc: $(cat "$work/reference.err")"
reference=$(field terrain_sha256 "$work/reference/summary.json")
reference_steps=$(field steps "$work/reference/summary.json")
reference_rc=$rc

unset CYCLONEDDS_URI FASTRTPS_DEFAULT_PROFILES_FILE MARSALA_DDS_CONFIG
peers=(--peers 10.77.0.1 --domain "$domain")
# team NAME WORLD_DDS AGENT_DDS AGENT_DDS AGENT_DDS: the run across hosts, checked against the reference.
team() {
  local name="$1" world_dds="$2" out="$work/$1" start rc=0 id pid
  shift 2
  local vendors=("$@") pids=()
  mkdir -p "$out/logs"
  start=$(date +%s%N)
  ip netns exec h1 "$bin/marsala-world" --scenario "$scenario" --agents 3 --dds "$world_dds" "${peers[@]}" \
    --max-steps "$steps_cap" --out "$out" >"$out/logs/world.log" 2>&1 &
  local world=$!
  for id in 1 2 3; do
    ip netns exec "h$((id + 1))" "$bin/marsala-agent" --scenario "$scenario" --id "$id" --dds "${vendors[$((id - 1))]}" \
      "${peers[@]}" >"$out/logs/agent-$id.log" 2>&1 &
    pids+=($!)
  done
  # A monitor of the other vendor than the world's where the team mixes them, on an agent's host.
  local monitor_dds="$world_dds"
  case "$name" in *-mixed) [ "$world_dds" = cyclone ] && monitor_dds=fastdds || monitor_dds=cyclone ;; esac
  ip netns exec h4 "$bin/marsala-monitor" status --dds "$monitor_dds" "${peers[@]}" --timeout 20 >"$out/status.txt" \
    2>&1 || fail "$name: marsala-monitor status --peers on h4 saw no world: $(cat "$out/status.txt")"
  wait "$world" || rc=$?
  [ "$rc" -eq "$reference_rc" ] ||
    { tail -5 "$out/logs/world.log"; fail "$name: the world exited $rc, on loopback $reference_rc"; }
  for pid in "${pids[@]}"; do wait "$pid" || fail "$name: an agent exited non-zero (see $out/logs)"; done
  local wall_ms=$(( ($(date +%s%N) - start) / 1000000 ))
  grep -q "^run ramp-d$domain " "$out/status.txt" || fail "$name: the monitor's status names no run: $(head -2 "$out/status.txt")"
  grep -q "discovers by unicast only, at 10.77.0.1" "$out/logs/agent-1.log" || fail "$name: agent 1 does not say its peers"
  [ "$(field steps "$out/summary.json")" = "$reference_steps" ] ||
    fail "$name: ended at step $(field steps "$out/summary.json"), on loopback at $reference_steps"
  local sha
  sha=$(field terrain_sha256 "$out/summary.json")
  [ "$sha" = "$reference" ] || fail "$name: ended on $sha across hosts, on $reference on loopback"
  echo "ok: $name: world on h1 ($world_dds), agents on h2..h4 (${vendors[*]}), monitor $monitor_dds:" \
    "$reference_steps steps in $wall_ms ms, terrain_sha256 ${sha:0:8} = loopback"
}
team cyclone cyclone cyclone cyclone cyclone
team fastdds fastdds fastdds fastdds fastdds
team cyclone-world-mixed cyclone fastdds cyclone fastdds
team fastdds-world-mixed fastdds cyclone fastdds cyclone

# A malformed address: exit 2 naming it, from spawn.sh (marsala-world --check refuses it) as from each binary.
rc=0
"$root/deploy/spawn.sh" --scenario "$scenario" --agents 3 --peers 10.77.0.1,10.77.0.300 --insecure --out "$work/bad" \
  --quiet >/dev/null 2>"$work/bad.err" || rc=$?
[ "$rc" -eq 2 ] && grep -q "'10.77.0.300' is not an IPv4 address" "$work/bad.err" && [ ! -e "$work/bad" ] ||
  fail "spawn.sh --peers 10.77.0.1,10.77.0.300: exit $rc, expected 2 naming it, nothing written: $(cat "$work/bad.err")"
for b in marsala-world marsala-agent "marsala-monitor status"; do
  rc=0
  MARSALA_PEERS=world:7402 $bin/$b --scenario "$scenario" --id 1 >/dev/null 2>"$work/bad.err" || rc=$?
  [ "$rc" -eq 2 ] && grep -q "^${b%% *}: --peers: 'world:7402' is not" "$work/bad.err" ||
    fail "$b with MARSALA_PEERS=world:7402: exit $rc, expected 2 naming it: $(cat "$work/bad.err")"
done

# Peers naming no world (an agent's host): the admit timeout's line names them.
rc=0
ip netns exec h2 "$bin/marsala-agent" --scenario "$scenario" --id 1 --peers 10.77.0.3 --domain "$domain" \
  --admit-timeout 2 >"$work/nowhere.out" 2>"$work/nowhere.err" || rc=$?
[ "$rc" -eq 1 ] || fail "an agent with --peers naming no world exited $rc, not 1"
grep -q "not admitted within 2 s .*no world answered at --peers 10.77.0.3 on domain $domain" "$work/nowhere.err" ||
  fail "the agent's line does not name the peers it tried: $(cat "$work/nowhere.err")"
[ "$(grep -c '^marsala-agent: ' "$work/nowhere.err")" -eq 1 ] || fail "not one error line: $(cat "$work/nowhere.err")"

for h in h1 h2 h3 h4; do
  [ "$(multicast_drops "$h")" = "1 0" ] ||
    fail "$h sent or received multicast (out, in packets: $(multicast_drops "$h"), 1 0 being the control)"
done
echo "ok: no multicast packet on any host (the control datagram aside); peers naming no world: one line, exit 1"
