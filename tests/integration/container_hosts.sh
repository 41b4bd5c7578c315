#!/usr/bin/env bash
# Containers on two hosts without multicast, as docker/docker-compose.agents.yml lays them out: two network namespaces
# (h1, h2) on a bridge, multicast off everywhere and dropped by nftables (lib.sh no_multicast); on h1 the world and
# agents of slots 1-2, on h2 the agent of slot 3 with a copy of h1's identity folder; every container on its host's
# network with the unicast profile and MARSALA_PEERS=10.77.0.1, secured. podman-compose 1.0.3 (Debian 12) cannot
# run that file (it adds its project network beside network_mode: host, which podman refuses), so the containers are
# started with `podman run` and the file's settings. The run must end on REFERENCE with no multicast packet.
# Usage (root; called by container_test.sh): container_hosts.sh IMAGE WORK REFERENCE_SHA256 [DDS]
set -euo pipefail
image="$1" work="$2" reference="$3" dds="${4:-cyclone}"
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
fail() { echo "FAIL (container hosts): $*" >&2; exit 1; }
if [ "${MARSALA_CONTAINER_HOSTS_INNER:-}" != 1 ]; then
  exec env MARSALA_CONTAINER_HOSTS_INNER=1 unshare -n -m --propagation private bash "$0" "$@"
fi
. "$root/tests/integration/lib.sh"  # bridge_hosts, no_multicast, multicast_drops, field
bridge_hosts 10.77.0 2
no_multicast 2
mkdir -p "$work/out" "$work/ids-h1" "$work/ids-h2"
chmod 777 "$work/out"
chown 1000:1000 "$work/ids-h1" "$work/ids-h2"
names=()
cleanup() { for n in "${names[@]}"; do podman rm -f "$n" >/dev/null 2>&1 || true; done; }
trap cleanup EXIT
project="marsala-hosts$$"
# run HOST NAME ARGS...: a container on HOST's network (nsenter, not `ip netns exec`, which hides the cgroup mount).
run() {
  local host="$1" name="$project-$2"
  shift 2
  names+=("$name")
  nsenter --net="/run/netns/$host" podman run -d --name "$name" --network host --entrypoint marsala-entrypoint \
    -e MARSALA_DDS="$dds" -e MARSALA_DOMAIN=7 -e MARSALA_DDS_CONFIG="/usr/local/share/marsala/dds/$dds-unicast.xml" \
    -e MARSALA_PEERS=10.77.0.1 -e MARSALA_AGENTS=3 -e MARSALA_INSECURE=0 "$@" >/dev/null
}
agent_args=(--scenario scenarios/ramp.pbtxt --admit-timeout 120)
start=$SECONDS
run h1 world -v "$work/out:/out" -v "$work/ids-h1:/identities" "$image" world --scenario scenarios/ramp.pbtxt \
  --out /out/run --replace --admit-timeout 120
for i in 1 2; do run h1 "agent$i" -e MARSALA_SLOTS=1-2 -v "$work/ids-h1:/identities" "$image" agent "${agent_args[@]}"; done
for _ in $(seq 1 300); do [ -f "$work/ids-h1/domain-7/manifest" ] && break; sleep 0.2; done
[ -f "$work/ids-h1/domain-7/manifest" ] || fail "the world's container made no identities in 60 s"
cp -a "$work/ids-h1/domain-7" "$work/ids-h2/"  # what a user copies to every other host
run h2 agent3 -e MARSALA_SLOTS=3-3 -v "$work/ids-h2:/identities" "$image" agent "${agent_args[@]}"
rc=$(timeout 300 podman wait "$project-world") || rc=timeout
for n in world agent1 agent2 agent3; do podman logs "$project-$n" >"$work/$n.log" 2>&1 || true; done
[ "$rc" = 0 ] || { tail -5 "$work/world.log"; fail "the world exited $rc"; }
sha=$(field terrain_sha256 "$work/out/run/summary.json")
[ "$sha" = "$reference" ] || fail "ended on $sha across hosts, on $reference on loopback"
# The slot each container ran secured under: h1's two containers take slots 1 and 2 in whichever order their claims
# land (under one flock), h2's takes 3, its host's only slot.
slot() { grep -o "secured (DDS Security) as agent-[0-9]* from /identities/domain-7" "$work/agent$1.log" |
  head -1 | sed 's/.*agent-\([0-9]*\) .*/\1/'; }
slots_h1="$(printf '%s\n' "$(slot 1)" "$(slot 2)" | sort -n | tr '\n' ' ')"
[ "$slots_h1" = "1 2 " ] ||
  fail "h1's agents did not run secured under slots 1 and 2 (MARSALA_SLOTS=1-2): got '$slots_h1'; $(tail -2 "$work/agent1.log")"
[ "$(slot 3)" = 3 ] ||
  fail "h2's agent did not run secured under slot 3 (MARSALA_SLOTS=3-3): $(tail -2 "$work/agent3.log")"
for n in 1 2 3; do
  grep -q "discovers by unicast only, at 10.77.0.1" "$work/agent$n.log" || fail "agent container $n does not say its peers"
done
for h in h1 h2; do
  [ "$(multicast_drops "$h")" = "0 0" ] || fail "$h sent or received multicast: $(multicast_drops "$h")"
done
echo "ok: containers on two hosts without multicast ($dds; world + agents 1-2 on h1, agent 3 on h2, secured," \
  "MARSALA_PEERS): completed in $((SECONDS - start)) s on the loopback terrain ${sha:0:8}"
