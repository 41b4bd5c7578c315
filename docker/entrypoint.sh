#!/usr/bin/env bash
# The image's entrypoint (docker/docker-compose.yml): runs marsala-world, marsala-agent or marsala-monitor secured by
# DDS Security unless MARSALA_INSECURE=1 (docs/runtime.md#security, README "Containers").
#
# Usage: marsala-entrypoint world|agent|monitor ARGS...
#   world    makes the identity folder on first use, or reuses it (make-identities.sh --reuse: a folder for fewer
#            agents exits 2 naming it), and says where in one line; then runs marsala-world --agents $MARSALA_AGENTS
#   agent    waits for the folder (up to $MARSALA_IDENTITIES_WAIT s, default 120), claims the first free slot K of
#            $MARSALA_SLOTS (A-B, default all: 1-$MARSALA_AGENTS; each host of a run over several hosts its own range: the
#            claims are this host's) (a lock held for the agent's life: a restarted container takes a slot freed by a
#            dead one) and runs marsala-agent --id K with identity agent-K; unsecured: marsala-agent --id auto
#   monitor  waits for the folder, then runs marsala-monitor with identity monitor
# Environment: MARSALA_DOMAIN (the folder is $MARSALA_IDENTITIES_ROOT/domain-<D>, the root default /identities, a
# volume), MARSALA_AGENTS (the team size), MARSALA_INSECURE (1: no DDS Security; anyone on the network can read and
# write the run), and the programs' own MARSALA_DDS, MARSALA_DDS_CONFIG and MARSALA_PEERS (unicast discovery at
# those hosts, no multicast: docker/docker-compose.agents.yml sets the world's address; docs/runtime.md#peers).
# Fast DDS teams of 48 agents or more take the crowd's timing as deploy/spawn.sh gives it (deploy/dds/crowd.sh, read
# from the folder of the profile): a MARSALA_DDS_CONFIG naming the shipped fastdds-lo.xml or fastdds-unicast.xml
# becomes fastdds-crowd.xml or fastdds-unicast-crowd.xml beside it (one line says so; README "240 robots over four
# hosts").
set -euo pipefail
role="${1:-}"
[ $# -gt 0 ] && shift
case "$role" in world|agent|monitor) ;; *)
  echo "marsala-entrypoint: the first argument must be world, agent or monitor, got '$role'" >&2; exit 2 ;;
esac
agents="${MARSALA_AGENTS:-3}"
domain="${MARSALA_DOMAIN:-0}"
[[ "$agents" =~ ^[0-9]+$ ]] && [ "$agents" -ge 1 ] ||
  { echo "marsala-entrypoint: MARSALA_AGENTS must be a whole number >= 1, got '$agents'" >&2; exit 2; }
slots="${MARSALA_SLOTS:-all}"
[ "$slots" = all ] && slots="1-$agents"
[[ "$slots" =~ ^([0-9]+)-([0-9]+)$ ]] && [ "${BASH_REMATCH[1]}" -ge 1 ] &&
  [ "${BASH_REMATCH[1]}" -le "${BASH_REMATCH[2]}" ] && [ "${BASH_REMATCH[2]}" -le "$agents" ] ||
  { echo "marsala-entrypoint: MARSALA_SLOTS must be A-B with 1 <= A <= B <= MARSALA_AGENTS ($agents), got '$slots'" >&2
    exit 2; }
first_slot="${BASH_REMATCH[1]}" last_slot="${BASH_REMATCH[2]}"
config="${MARSALA_DDS_CONFIG:-}"
# The rule lies beside the shipped profiles (deploy/dds/crowd.sh); a profile in a folder without it is taken as given.
if [ "${MARSALA_DDS:-cyclone}" = fastdds ] && [ -n "$config" ] && [ -f "$(dirname -- "$config")/crowd.sh" ]; then
  # shellcheck source=deploy/dds/crowd.sh
  source "$(dirname -- "$config")/crowd.sh"
  config=$(marsala_crowd_profile "$config" "$agents")
  if [ "$config" != "$MARSALA_DDS_CONFIG" ]; then
    echo "marsala-entrypoint: $agents Fast DDS agents: the crowd's timing, $config (MARSALA_DDS_CONFIG)" >&2
    export MARSALA_DDS_CONFIG="$config"
  fi
fi
[ -n "${MARSALA_PEERS:-}" ] &&
  echo "marsala-entrypoint: $role discovers by unicast only, at $MARSALA_PEERS (MARSALA_PEERS)" >&2
case "${MARSALA_INSECURE:-0}" in
  1|true|yes)
    echo "marsala-entrypoint: $role runs without DDS Security (MARSALA_INSECURE): anyone on the network can read" \
      "and write this run" >&2
    unset MARSALA_SECURITY
    case "$role" in
      world) exec marsala-world --agents "$agents" "$@" ;;
      agent) exec marsala-agent --id auto "$@" ;;
      monitor) exec marsala-monitor "$@" ;;
    esac ;;
  0|false|no|"") ;;
  *) echo "marsala-entrypoint: MARSALA_INSECURE must be 1 or 0, got '$MARSALA_INSECURE'" >&2; exit 2 ;;
esac

root="${MARSALA_IDENTITIES_ROOT:-/identities}"
ids="$root/domain-$domain"
export MARSALA_SECURITY="$ids"
make_identities="${MARSALA_MAKE_IDENTITIES:-/usr/local/share/marsala/security/make-identities.sh}"
if [ "$role" = world ]; then
  line=$("$make_identities" --out "$ids" --agents "$agents" --domain "$domain" --reuse) || exit $?
  echo "marsala-entrypoint: $line (keep the volume: it is the run's CA and every process's key)" >&2
  exec marsala-world --agents "$agents" "$@"
fi
wait_s="${MARSALA_IDENTITIES_WAIT:-120}"
for _ in $(seq 1 $((wait_s * 5))); do
  [ -f "$ids/manifest" ] && break
  sleep 0.2
done
[ -f "$ids/manifest" ] ||
  { echo "marsala-entrypoint: no identities in $ids after ${wait_s} s (the world makes them)" >&2; exit 1; }
[ "$role" = monitor ] && exec marsala-monitor "$@"

# An agent: the first slot no living agent holds. flock exits 75 when the slot is taken (-E), else with the agent's
# own code, which ends the loop.
mkdir -p "$root/claims-domain-$domain"
for k in $(seq "$first_slot" "$last_slot"); do
  rc=0
  flock -n -E 75 "$root/claims-domain-$domain/agent-$k.lock" marsala-agent --id "$k" "$@" || rc=$?
  [ "$rc" -eq 75 ] || exit "$rc"
done
echo "marsala-entrypoint: agent slots $slots of domain $domain are all taken on this host (MARSALA_SLOTS)" >&2
exit 1
