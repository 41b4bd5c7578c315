#!/usr/bin/env bash
# Several hosts on one machine: three network namespaces (h1, h2, h3) joined by a bridge, addresses 10.77.0.1-3/24
# that exist only inside this test's private namespaces. The world runs on h1, five agents of path_generated on h2
# and h3, every process with the LAN profile of its vendor (deploy/dds/*-lan.xml: interface chosen automatically,
# multicast discovery). Each team must end on the loopback run's terrain_sha256 after the same 600 steps (of the
# 5,550 the run needs: every step already goes through all hosts, and CI's time is counted).
# Usage: multihost_test.sh CASE DOMAIN     CASE: cyclone | fastdds | mixed (world on Cyclone, agents on both)
# Exits 77 (skipped) where network or mount namespaces, veth pairs or bridges cannot be made.
set -euo pipefail
case_name="$1"
domain="$2"
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
bin="${MARSALA_BUILD_DIR:-$root/build}/bin"
scenario="$root/deploy/scenarios/path_generated.pbtxt"
steps_cap=600
fail() { echo "FAIL (multihost $case_name): $*" >&2; exit 1; }

# Private network and mount namespaces of our own: the bridge and /run/netns exist only there.
if [ "${MARSALA_MULTIHOST_INNER:-}" != 1 ]; then
  unshare -n -m --propagation private true 2>/dev/null || { echo "SKIP: no network and mount namespaces here"; exit 77; }
  exec env MARSALA_MULTIHOST_INNER=1 unshare -n -m --propagation private bash "$0" "$@"
fi
work="$(mktemp -d "${TMPDIR:-/tmp}/marsala-multihost-$case_name.XXXXXX")"
trap '[ -n "${MARSALA_KEEP_WORK:-}" ] || rm -rf "$work"' EXIT
. "$root/tests/integration/lib.sh"  # bridge_hosts
bridge_hosts 10.77.0 3

# The reference: the same team on loopback (in this namespace, which has lo only).
# Exit code 3: the run ended at max_steps (README).
rc=0
MARSALA_BUILD_DIR="$(dirname "$bin")" "$root/deploy/spawn.sh" --scenario "$scenario" --agents 5 --domain "$domain" \
  --max-steps "$steps_cap" --out "$work/reference" --quiet >/dev/null || rc=$?
[ "$rc" -eq 3 ] || fail "the loopback reference run exited $rc, not 3 (max_steps)"
reference=$(grep -o '"terrain_sha256": *"[0-9a-f]*"' "$work/reference/summary.json" | cut -d'"' -f4)

unset CYCLONEDDS_URI FASTRTPS_DEFAULT_PROFILES_FILE
world_dds=cyclone
case "$case_name" in
  cyclone) agent_dds() { echo cyclone; } ;;
  fastdds) world_dds=fastdds; agent_dds() { echo fastdds; } ;;
  mixed) agent_dds() { [ $(($1 % 2)) -eq 1 ] && echo cyclone || echo fastdds; } ;;
  *) fail "unknown case" ;;
esac
out="$work/run"
mkdir -p "$out/logs"
start=$(date +%s%N)
ip netns exec h1 "$bin/marsala-world" --scenario "$scenario" --agents 5 --dds "$world_dds" --max-steps "$steps_cap" \
  --dds-config "$root/deploy/dds/$world_dds-lan.xml" --domain "$domain" --out "$out" >"$out/logs/world.log" 2>&1 &
world=$!
pids=()
for id in 1 2 3 4 5; do
  vendor=$(agent_dds "$id")
  ip netns exec "h$((id % 2 + 2))" "$bin/marsala-agent" --scenario "$scenario" --id "$id" --dds "$vendor" \
    --dds-config "$root/deploy/dds/$vendor-lan.xml" --domain "$domain" >"$out/logs/agent-$id.log" 2>&1 &
  pids+=($!)
done
rc=0
wait "$world" || rc=$?
[ "$rc" -eq 3 ] || { tail -20 "$out/logs/world.log"; fail "the world exited $rc, not 3 (max_steps)"; }
for pid in "${pids[@]}"; do wait "$pid" || fail "an agent exited non-zero (see $out/logs)"; done
wall_ms=$(( ($(date +%s%N) - start) / 1000000 ))
sha=$(grep -o '"terrain_sha256": *"[0-9a-f]*"' "$out/summary.json" | cut -d'"' -f4)
steps=$(grep -o '"steps": *[0-9]*' "$out/summary.json" | grep -o '[0-9]*$')
grep -q '"end_reason": *"max_steps"' "$out/summary.json" && [ "$steps" = "$steps_cap" ] ||
  fail "the run ended at step $steps, not at the cap $steps_cap ($(grep -o '"end_reason": *"[a-z_]*"' "$out/summary.json"))"
[ "$sha" = "$reference" ] || fail "ended on $sha across hosts, on $reference on loopback"
echo "ok: world on h1 ($world_dds), agents on h2 and h3 ($(for id in 1 2 3 4 5; do agent_dds "$id"; done | sort | uniq -c | tr -s ' \n' ' ')): $steps steps in ${wall_ms} ms, terrain_sha256 $sha = loopback"
