#!/usr/bin/env bash
# Real containers: docker/run.sh builds the image with podman and runs docker/docker-compose.yml (the world, three
# agents and a monitor, each container a host of its own on the compose network, LAN profiles) inside a private
# network namespace, secured by default: the world's container makes the identities in the identity folder and says
# so, every process runs with DDS Security, the agents claim slots 1..3; the run must end on the terrain_sha256 of the
# same run on loopback. Then the same image on two namespace hosts without multicast, world and agents joined by
# address (container_hosts.sh, about 30 s more).
# Exits 77 (skipped) where podman cannot run containers.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
export MARSALA_BUILD_DIR="${MARSALA_BUILD_DIR:-$root/build}"
fail() { echo "FAIL (container): $*" >&2; exit 1; }
for tool in podman podman-compose unshare; do
  command -v "$tool" >/dev/null || { echo "SKIP: $tool is not installed (deploy/install-deps.sh --containers)"; exit 77; }
done
export CONTAINERS_CONF="$root/docker/podman/containers.conf"
podman info >/dev/null 2>&1 || { echo "SKIP: podman cannot run here ($(podman info 2>&1 | tail -1))"; exit 77; }
unshare -n true 2>/dev/null || { echo "SKIP: cannot make a private network namespace (unshare -n needs root)"; exit 77; }
# An image tag of this checkout's own: a test of another checkout running at the same time on this machine (a CI
# clone beside a worktree) rebuilds its own tag and never makes this one run its binaries.
image="localhost/marsala:test-$(printf '%s' "$root" | sha256sum | cut -c1-12)"
work="$(mktemp -d "${TMPDIR:-/tmp}/marsala-container.XXXXXX")"
trap 'rm -rf "$work"' EXIT

unshare -n sh -c "ip link set lo up; '$root/deploy/spawn.sh' --scenario '$root/deploy/scenarios/ramp.pbtxt' \
  --agents 3 --out '$work/loopback' --quiet" >/dev/null || fail "the loopback reference run failed"
reference=$(grep -o '"terrain_sha256": *"[0-9a-f]*"' "$work/loopback/summary.json" | cut -d'"' -f4)

start=$SECONDS
rc=0
"$root/docker/run.sh" --scenario ramp --agents 3 --domain 7 --image "$image" --out "$work/containers" \
  >"$work/run.txt" 2>&1 || rc=$?
[ "$rc" -eq 0 ] || { tail -30 "$work/run.txt"; tail -20 "$work/containers/world.log" 2>/dev/null; fail "docker/run.sh exited $rc"; }
grep -E '^run.sh: .* (in|after) [0-9]+ s' "$work/run.txt" || true  # the build and run times
summary="$work/containers/run/summary.json"
[ -f "$summary" ] || fail "no summary.json from the containers"
grep -q '"completed": *true' "$summary" || fail "the containers' run did not complete"
sha=$(grep -o '"terrain_sha256": *"[0-9a-f]*"' "$summary" | cut -d'"' -f4)
[ "$sha" = "$reference" ] || fail "containers ended on $sha, loopback on $reference"
# Three agents took the three slots, each under its slot's name.
for id in 1 2 3; do
  grep -q "admitted agent $id: husky-$id\$" "$work/containers/world.log" ||
    fail "the world's log names no admission of slot $id as husky-$id"
done
# Secured by default: the identities made on first use in the identity folder, one line saying where.
grep -q "^marsala-entrypoint: identities: made /identities/domain-7 for domain 7, 3 agents" "$work/containers/world.log" ||
  fail "the world's container did not say where it made the identities"
[ -f "$work/containers/identities/domain-7/manifest" ] || fail "no identities in run.sh's identity folder"
grep -q "secured (DDS Security) as world" "$work/containers/world.log" || fail "the world did not run secured"
grep -l "secured (DDS Security) as agent-" "$work/containers/"agent*.log | wc -l | grep -qx 3 ||
  fail "not every agent ran secured"
echo "ok: world, 3 agents and a monitor in containers, secured, completed in $((SECONDS - start)) s (image build" \
  "included) on the loopback terrain $sha; image $image $(podman image ls --format '{{.Size}}' "$image" | head -1)"

# The same image on two hosts without multicast (docker/docker-compose.agents.yml's layout, --peers): no new build.
bash "$root/tests/integration/container_hosts.sh" "$image" "$work/hosts" "$reference" ||
  fail "containers on two hosts without multicast (logs: $work/hosts)"
