#!/usr/bin/env bash
# Builds the MARSala image with podman and runs docker/docker-compose.yml: the world, AGENTS agents and a monitor,
# inside a private network namespace (nothing leaves this machine), then prints the summary and exits with the
# world's exit code (0 completed, 7 completed short of slots, 3 max_steps, 4 no_live_agents, 5 signal, 6 stalled,
# 1 error).
# Usage: docker/run.sh [--scenario NAME] [--agents N] [--dds cyclone|fastdds] [--domain D] [--out DIR] [--image TAG]
#                      [--identities DIR | --insecure]
#   --identities  the identity folders of secured runs (default OUT/identities, kept between runs: made on first use
#                 in DIR/domain-D by the world's container, reused afterwards; docs/runtime.md#security)
#   --insecure    no DDS Security (the containers' network is this run's alone inside the namespace)
#   --image  the image tag to build and run (default $MARSALA_IMAGE, else localhost/marsala:latest); give each checkout
#            its own when several may run at once on one machine, so that none runs another's binaries
# Needs podman, runc, podman-compose and, without an image registry, mmdebstrap for the base image
# (deploy/install-deps.sh --containers). docs: ../shared/notes/CONTAINERS.md recipe, README "Containers".
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
scenario=ramp agents=3 dds=cyclone domain=0 out="$root/out/containers" image="${MARSALA_IMAGE:-localhost/marsala:latest}"
identities="" insecure=0
while [ $# -gt 0 ]; do
  case "$1" in
    --scenario) scenario="$2"; shift 2 ;;
    --agents) agents="$2"; shift 2 ;;
    --dds) dds="$2"; shift 2 ;;
    --domain) domain="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    --image) image="$2"; shift 2 ;;
    --identities) identities="$2"; shift 2 ;;
    --insecure) insecure=1; shift ;;
    -h|--help) sed -n '2,13p' "$0"; exit 0 ;;
    *) echo "run.sh: unknown argument '$1'" >&2; exit 2 ;;
  esac
done
if [ "$insecure" -eq 1 ] && [ -n "$identities" ]; then
  echo "run.sh: --identities is for secured runs, and --insecure asks for none: give one" >&2; exit 2
fi
identities="${identities:-$out/identities}"
for tool in podman podman-compose; do
  command -v "$tool" >/dev/null || { echo "run.sh: $tool is not installed (deploy/install-deps.sh --containers)" >&2; exit 1; }
done
export CONTAINERS_CONF="$root/docker/podman/containers.conf"

# The base image from Debian's packages when no registry is reachable (cached by podman between runs).
t0=$SECONDS
if ! podman image exists docker.io/library/debian:bookworm-slim; then
  command -v mmdebstrap >/dev/null || { echo "run.sh: no debian:bookworm-slim image and no mmdebstrap" >&2; exit 1; }
  tmp="$(mktemp -d)"
  echo "run.sh: building the debian:bookworm-slim base image with mmdebstrap"
  mmdebstrap --quiet --variant=minbase bookworm "$tmp/base.tar"
  podman import -q "$tmp/base.tar" docker.io/library/debian:bookworm-slim >/dev/null
  rm -rf "$tmp"
  echo "run.sh: base image built in $((SECONDS - t0)) s"
fi
t1=$SECONDS
echo "run.sh: building $image"
podman build --pull=never -q -t "$image" -f "$root/docker/Dockerfile" "$root" >/dev/null
echo "run.sh: image built in $((SECONDS - t1)) s ($(podman image ls --format '{{.Size}}' "$image" | head -1))"

mkdir -p "$out" "$identities"
chmod 777 "$out"  # the containers' user (uid 1000) writes there
# The identity folders: the containers' user makes them (0700 inside); rootful podman maps it to uid 1000 here.
chown 1000:1000 "$identities" 2>/dev/null || chmod 777 "$identities"
rm -rf "$out/run"
# One project per run: its containers and network are its own, and removed at the end (podman-compose 1.0.3's `down`
# leaves the network, whose /24 of podman's pool would otherwise stay taken).
project="marsala$$"
compose="$root/docker/docker-compose.yml"
t2=$SECONDS
rc=0
SCENARIO="$scenario" AGENTS="$agents" DDS="$dds" DOMAIN="$domain" OUT="$out" MARSALA_IMAGE="$image" \
  IDENTITIES="$identities" INSECURE="$insecure" \
  unshare -n sh -c '
    ip link set lo up
    podman-compose -p "$1" -f "$2" up -d >"$3/compose.log" 2>&1 || { cat "$3/compose.log" >&2; exit 1; }
    rc=$(podman wait "$1_world_1") || rc=1
    podman logs "$1_world_1" >"$3/world.log" 2>&1 || true
    for c in $(podman ps -a --format "{{.Names}}" | grep "^$1_" | grep -v "^$1_world_"); do
      podman logs "$c" >"$3/${c#"$1"_}.log" 2>&1 || true
    done
    podman-compose -p "$1" -f "$2" down -t 2 >/dev/null 2>&1 || true
    podman network rm -f "$1_default" >/dev/null 2>&1 || true
    exit "$rc"' sh "$project" "$compose" "$out" || rc=$?
[ -f "$out/run/summary.json" ] && cat "$out/run/summary.json"
echo "run.sh: the world exited $rc after $((SECONDS - t2)) s of compose run (its log: $out/world.log)"
exit "$rc"
