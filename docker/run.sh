#!/usr/bin/env bash
# Builds the MARSala image with podman and runs docker/docker-compose.yml: the world, AGENTS agents and a monitor,
# inside a private network namespace (nothing leaves this machine), then prints the summary and exits with the
# world's exit code (0 completed, 3 max_steps, 4 no_live_agents, 5 signal, 1 error).
# Usage: docker/run.sh [--scenario NAME] [--agents N] [--dds cyclone|fastdds] [--out DIR]
# Needs podman, runc, podman-compose and, without an image registry, mmdebstrap for the base image
# (deploy/install-deps.sh --containers). docs: ../shared/notes/CONTAINERS.md recipe, README "Containers".
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
scenario=ramp agents=3 dds=cyclone out="$root/out/containers"
while [ $# -gt 0 ]; do
  case "$1" in
    --scenario) scenario="$2"; shift 2 ;;
    --agents) agents="$2"; shift 2 ;;
    --dds) dds="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    -h|--help) sed -n '2,7p' "$0"; exit 0 ;;
    *) echo "run.sh: unknown argument '$1'" >&2; exit 2 ;;
  esac
done
for tool in podman podman-compose; do
  command -v "$tool" >/dev/null || { echo "run.sh: $tool is not installed (deploy/install-deps.sh --containers)" >&2; exit 1; }
done
export CONTAINERS_CONF="$root/docker/podman/containers.conf"

# The base image from Debian's packages when no registry is reachable (cached by podman between runs).
if ! podman image exists docker.io/library/debian:bookworm-slim; then
  command -v mmdebstrap >/dev/null || { echo "run.sh: no debian:bookworm-slim image and no mmdebstrap" >&2; exit 1; }
  tar="$(mktemp -d)/base.tar"
  echo "run.sh: building the debian:bookworm-slim base image with mmdebstrap"
  mmdebstrap --quiet --variant=minbase bookworm "$tar"
  podman import -q "$tar" docker.io/library/debian:bookworm-slim >/dev/null
  rm -rf "$(dirname "$tar")"
fi
echo "run.sh: building localhost/marsala:latest"
podman build --pull=never -q -t localhost/marsala:latest -f "$root/docker/Dockerfile" "$root" >/dev/null

mkdir -p "$out"
chmod 777 "$out"  # the containers' user (uid 1000) writes there
rm -rf "$out/run"
project="marsala$$"
inner=$(cat <<INNER
set -e
ip link set lo up
export SCENARIO=$scenario AGENTS=$agents DDS=$dds OUT=$out CONTAINERS_CONF=$CONTAINERS_CONF
podman-compose -p $project -f $root/docker/docker-compose.yml up -d >$out/compose.log 2>&1
rc=\$(podman wait ${project}_world_1)
podman logs ${project}_world_1 > $out/world.log 2>&1 || true
podman-compose -p $project -f $root/docker/docker-compose.yml down -t 2 >/dev/null 2>&1 || true
exit \$rc
INNER
)
rc=0
unshare -n sh -c "$inner" || rc=$?
[ -f "$out/run/summary.json" ] && cat "$out/run/summary.json"
echo "run.sh: the world exited $rc (its log: $out/world.log)"
exit "$rc"
