#!/usr/bin/env bash
# Runs a scenario as real processes: one marsala-world and N marsala-agent processes on a fresh DDS domain with the
# loopback profile (or --profile lan|unicast, secured), waits for the end, prints a short account of the run
# (summary.json holds everything), and stops every child it started on exit or Ctrl-C. On a terminal it keeps one
# line up to date while the run goes: step, progress, steps/s and the estimated time left (marsala-monitor progress).
#
# Usage: deploy/spawn.sh --scenario FILE --agents N [--dds cyclone|fastdds] [--agent-dds cyclone|fastdds]
#                        [--out DIR [--replace]] [--domain D] [--monitor] [--max-steps N] [--timeout S] [--seed N]
#                        [--quiet] [--profile lo|lan|unicast] [--peers ADDR[,ADDR...]] [--secure | --insecure]
#                        [--identities DIR] [--frames-every K] [--dump-maps] [--metrics-port P] [--trace FILE]
#                        [--set FIELD=VALUE ...]
#        deploy/spawn.sh --fork DIR --at K --out NEW [--agents M] [--max-steps N] [--set FIELD=VALUE ...]
#                        [--scenario FILE] [options above]
#   --out         output folder (default out/<scenario>-<N>, whose previous run is replaced); the world refuses a
#                 folder that holds another run's files, unless --replace removes them (and logs/, maps/) first, and
#                 a folder a live (or paused) world holds, --replace or not (exit 2 naming its pid)
#   --dds         vendor of every process (default $MARSALA_DDS, else cyclone); --agent-dds overrides it for the agents
#   --domain      DDS domain id (default $MARSALA_DOMAIN, else a random one on which no world answers within 1 s)
#   --monitor     also run `marsala-monitor tail` in the foreground output (instead of the progress line)
#   --quiet       print nothing but errors (no progress line, no account at the end)
#   --timeout     give up (and stop everything) after S seconds of wall time (default 1800)
#   --frames-every a time-lapse: marsala-world draws OUT/frames/frame_<step>.png every K steps and the last, and
#                 OUT/frames/timelapse.mp4 when ffmpeg is installed
#   --dump-maps   every agent writes its own final map into OUT/maps (marsala-agent --dump-map OUT/maps):
#                 agent-<id>-height.asc (NODATA where it knows nothing) and agent-<id>-map.json; see how good it is
#                 with `marsala-terrain compare OUT/maps/agent-<id>-height.asc OUT/terrain_final.asc` (--replace
#                 removes the previous run's maps; an agent refuses maps of another run, exit 2)
#   --metrics-port the world serves its metrics on http://127.0.0.1:P/metrics (Prometheus text format,
#                 docs/runtime.md#metrics); a port in use exits 2 before anything starts
#   --trace       marsala-world writes the lockstep as a Chrome trace (trace-event JSON, for Perfetto) to FILE at the
#                 end (docs/runtime.md#step-traces)
#   --seed        run seed, passed as --seed N to marsala-world and every marsala-agent (default: the scenario's)
#   --set         change a field of the scenario for this run, e.g. --set robot_type.body.sensing_range_m=5
#                 (repeatable; passed to marsala-world and every marsala-agent; summary.json lists them)
#   --fork        a new run (--out NEW) from the finished run in DIR (docs/runtime.md#fork): the parent's team starts
#                 afresh with its scenario (DIR/summary.json's scenario_file, or --scenario), seed and --set; the world
#                 replays the parent's first K steps (--at K), checking each request against DIR/run.log (exit 8
#                 naming the agent and the step when one differs), then goes on live: --agents M (fewer than the
#                 parent's: the others leave at K; more: the slots above the parent's join at K, started with
#                 the others and admitted at K), --max-steps, --set of fields only the world reads (max_steps,
#                 step_deadline_s, stall_steps, goal, payload_path, site; applied from step 0). --seed and --set of a
#                 field the agents read may not change (exit 2, nothing written); NEW's run.log header and
#                 events.log say where the run came from
#   --profile     where DDS traffic goes (deploy/dds/<vendor>-<profile>.xml): lo (default: this host's loopback only,
#                 unsecured unless --secure), lan (a subnet, multicast discovery) or unicast (no multicast: every
#                 process finds the world at --peers); lan and unicast run secured unless --insecure. Fast DDS on lo
#                 with 48 agents or more: fastdds-crowd.xml (slower heartbeats and announcements; 120 agents
#                 were not admitted in 60 s with fastdds-lo.xml on two cores, README "Idle robots up to 120"); on
#                 unicast with 48 or more: fastdds-unicast-crowd.xml, the same timing (README "240 robots over four
#                 hosts")
#   --peers       unicast discovery at these hosts, given as --peers to the world, every agent and the monitor
#                 (docs/runtime.md#peers): the world's address is enough; implies --profile unicast; default with
#                 --profile unicast: $MARSALA_PEERS, else this host's first address, else 127.0.0.1
#                 (--world-address A: the same as --peers A)
#   --secure      DDS Security (also on lo): every process authenticated, access-controlled and encrypted (domain
#                 <= 230), with the identities of --identities
#   --insecure    no DDS Security on a lan or unicast profile: anyone on the network can read and write the run
#   --identities  the identity folder of secured runs (default $MARSALA_IDENTITIES, else ~/.marsala/identities: it
#                 outlives run folders and is what you copy to the other hosts): made on first use by
#                 deploy/security/make-identities.sh for the run's domain and team (one line says where), reused
#                 afterwards; without --domain a secured run takes the folder's domain. A folder made for another
#                 domain or a smaller team is refused (exit 2, nothing written)
# Exit codes: marsala-world's for a run that ended: 0 completed, 7 completed short of slots, 3 max_steps,
#             4 no_live_agents, 5 stopped by a signal, 6 stalled (no progress and no terrain change for the scenario's stall_steps: the account at the
#             end says what each robot waited for) (the summary is written in every case); 1 the world failed or
#             wrote no summary or the binaries are missing; 8 a fork whose request differed from its parent's before K;
#             2 usage error or a run that `marsala-world --check` rejects (nothing started); 130 stopped.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bin="${MARSALA_BUILD_DIR:-$root/build}/bin"

# From marsala_crowd_agents on, Fast DDS takes fastdds-crowd.xml on loopback, fastdds-unicast-crowd.xml on unicast.
# shellcheck source=deploy/dds/crowd.sh
source "$root/deploy/dds/crowd.sh"
scenario="" agents="" dds="${MARSALA_DDS:-cyclone}" agent_dds="" out="" domain="${MARSALA_DOMAIN:-}" monitor=0 max_steps="" timeout_s=1800 seed="" quiet=0 frames_every=""
replace=0 secure=0 insecure=0 dump_maps=0 set_args=() observe_args=() profile="" peers="" identities=""
fork="" fork_at="" fork_set_args=()
usage() { awk 'NR > 1 && !/^#/ { exit } NR > 1 { sub(/^# ?/, ""); print }' "$0"; }  # the whole header comment
# The profile and security options, checked and settled: secure=1 for --secure and for lan/unicast without
# --insecure; identities and peers get their defaults (--peers implies --profile unicast). Exit 2 naming what is wrong.
security_options() {
  peers="${peers:-${MARSALA_PEERS:-}}"
  [ -n "$peers" ] && [ -z "$profile" ] && profile=unicast
  profile="${profile:-lo}"
  case "$profile" in
    lo|lan|unicast) ;;
    *) echo "spawn.sh: --profile must be lo, lan or unicast, got '$profile'" >&2; exit 2 ;;
  esac
  if [ "$secure" -eq 1 ] && [ "$insecure" -eq 1 ]; then
    echo "spawn.sh: --secure and --insecure contradict each other: give one" >&2; exit 2
  fi
  [ "$profile" != lo ] && [ "$insecure" -eq 0 ] && secure=1
  if [ "$secure" -eq 1 ] && [ "$agent_dds" != "$dds" ]; then
    echo "spawn.sh: a secured team runs on one vendor (Cyclone 0.10.2 and Fast DDS 2.9.1 fail each other's" \
      "handshake, docs/runtime.md#security): drop --agent-dds or give --insecure" >&2
    exit 2
  fi
  if [ "$secure" -eq 0 ] && [ -n "$identities" ]; then
    echo "spawn.sh: --identities $identities is for secured runs, and this one is not" \
      "(--insecure or --profile lo without --secure)" >&2
    exit 2
  fi
  identities="${identities:-${MARSALA_IDENTITIES:-${HOME:-/root}/.marsala/identities}}"
  [[ "$identities" = /* ]] || identities="$PWD/$identities"
  if [ -n "$peers" ] && [ "$profile" != unicast ]; then
    echo "spawn.sh: --peers is for --profile unicast (discovery without multicast), not '$profile'" >&2; exit 2
  fi
  if [ "$profile" = unicast ] && [ -z "$peers" ]; then
    peers=$(hostname -I 2>/dev/null | awk '{ print $1 }')
    peers="${peers:-127.0.0.1}"
  fi
}
# The domain the identity folder was made for (its manifest), or nothing (no folder yet, or made for every domain).
identities_domain() { sed -n 's/^domain=\([0-9][0-9]*\)$/\1/p' "$identities/manifest" 2>/dev/null | head -1 || true; }
# A fork's parent (--fork DIR --at K): its team, scenario file, seed and --set from DIR/summary.json, for the agents;
# the world takes them from DIR/run.log and checks the rest. Exit 2 naming what is wrong, nothing written.
fork_options() {
  [ -z "$seed" ] ||
    { echo "spawn.sh: --seed may not change at a fork (the parent's applies); --agents, --max-steps, --set of world-only fields may" >&2
      exit 2; }
  fork_set_args=("${set_args[@]}")  # the fork's own: for the world alone, which refuses fields the agents read
  set_args=()
  [[ "$fork_at" =~ ^[0-9]+$ ]] || { echo "spawn.sh: --fork needs --at K (K >= 0), got '$fork_at'" >&2; exit 2; }
  [ -f "$fork/summary.json" ] && [ -f "$fork/run.log" ] ||
    { echo "spawn.sh: --fork $fork: not a finished run folder (no summary.json and run.log)" >&2; exit 2; }
  local parent
  parent=$(python3 -c 'import json, sys
d = json.load(open(sys.argv[1]))
print(d["agents"], d["seed"], d["scenario_file"])
for o in d.get("overrides", []): print(o)' "$fork/summary.json") ||
    { echo "spawn.sh: --fork $fork: summary.json cannot be read" >&2; exit 2; }
  fork_agents="$agents"
  read -r agents seed parent_scenario <<<"$(head -1 <<<"$parent")"
  while IFS= read -r o; do [ -n "$o" ] && set_args+=(--set "$o"); done < <(tail -n +2 <<<"$parent")
  if [ -z "$scenario" ]; then
    scenario="$parent_scenario"
    [[ "$scenario" = /* ]] || [ -f "$scenario" ] || scenario="$root/$scenario"
  fi
  [ -z "$out" ] && { echo "spawn.sh: --fork needs --out NEW (the fork's own folder)" >&2; exit 2; }
  return 0
}
while [ $# -gt 0 ]; do
  case "$1" in
    --scenario) scenario="$2"; shift 2 ;;
    --agents) agents="$2"; shift 2 ;;
    --dds) dds="$2"; shift 2 ;;
    --agent-dds) agent_dds="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    --domain) domain="$2"; shift 2 ;;
    --monitor) monitor=1; shift ;;
    --max-steps) max_steps="$2"; shift 2 ;;
    --frames-every) frames_every="$2"; shift 2 ;;
    --metrics-port) observe_args+=(--metrics-port "$2"); shift 2 ;;
    --trace) observe_args+=(--trace "$2"); shift 2 ;;
    --timeout) timeout_s="$2"; shift 2 ;;
    --seed) seed="$2"; shift 2 ;;
    --set) set_args+=(--set "$2"); shift 2 ;;
    --quiet) quiet=1; shift ;;
    --replace) replace=1; shift ;;
    --secure) secure=1; shift ;;
    --insecure) insecure=1; shift ;;
    --profile) profile="$2"; shift 2 ;;
    --peers|--world-address)
      [ -z "$peers" ] || { echo "spawn.sh: give the peers once (--peers ADDR[,ADDR...])" >&2; exit 2; }
      peers="$2"; shift 2 ;;
    --identities) identities="$2"; shift 2 ;;
    --dump-maps) dump_maps=1; shift ;;
    --fork) fork="$2"; shift 2 ;;
    --at) fork_at="$2"; shift 2 ;;
    -h|--help) usage; exit 0 ;;
    *) echo "spawn.sh: unknown argument '$1' (try --help)" >&2; exit 2 ;;
  esac
done
fork_agents="" parent_team=""
if [ -n "$fork" ]; then
  fork_options  # sets scenario, agents, seed and set_args from the parent; fork_agents from --agents
  parent_team="$agents"
  # A larger team: its late slots start with the others and wait (unanswered) until the world admits them at K.
  [[ "$fork_agents" =~ ^[0-9]+$ ]] && [ "$fork_agents" -gt "$agents" ] && agents="$fork_agents"
elif [ -n "$fork_at" ]; then
  echo "spawn.sh: --at K is for --fork DIR" >&2; exit 2
fi
[ -n "$scenario" ] || { echo "spawn.sh: --scenario FILE is required (try --help)" >&2; exit 2; }
[ -f "$scenario" ] || { echo "spawn.sh: scenario file '$scenario' not found" >&2; exit 2; }
[[ "$agents" =~ ^[0-9]+$ ]] && [ "$agents" -ge 1 ] || { echo "spawn.sh: --agents N (N >= 1) is required" >&2; exit 2; }
for v in "$dds" "${agent_dds:-$dds}"; do
  case "$v" in cyclone|fastdds) ;; *) echo "spawn.sh: --dds must be cyclone or fastdds, got '$v'" >&2; exit 2 ;; esac
done
[ -z "$seed" ] || [[ "$seed" =~ ^[0-9]+$ ]] ||
  { echo "spawn.sh: --seed N needs a non-negative integer, got '$seed'" >&2; exit 2; }
agent_dds="${agent_dds:-$dds}"
[ -n "$out" ] || { out="$root/out/$(basename "${scenario%.*}")-$agents"; replace=1; }
security_options
for b in marsala-world marsala-agent; do
  [ -x "$bin/$b" ] || { echo "spawn.sh: $bin/$b not built (run deploy/build.sh)" >&2; exit 1; }
done

# The profile: loopback by default, DDS traffic never leaves this host's lo interface. The unicast one gets the peers
# from the command line of every process (--peers, through MARSALA_PEERS: the binaries check it, exit 2 when malformed).
export CYCLONEDDS_URI="file://$root/deploy/dds/cyclone-$profile.xml"
FASTRTPS_DEFAULT_PROFILES_FILE=$(marsala_crowd_profile "$root/deploy/dds/fastdds-$profile.xml" "$agents")
export FASTRTPS_DEFAULT_PROFILES_FILE
fastdds_profile=$(basename "$FASTRTPS_DEFAULT_PROFILES_FILE" .xml)
fastdds_profile=${fastdds_profile#fastdds-}  # lo, crowd, unicast, unicast-crowd, lan: said on the start line
if [ -n "$peers" ]; then export MARSALA_PEERS="$peers"; else unset MARSALA_PEERS; fi

# Without --domain: a random one (not derived from the PID, whose values repeat) on which no world answers
# `marsala-monitor status` within 1 s (a world publishes its status from its start, while it admits). Two runs
# started at the same moment may still pick one domain: the world itself then refuses to share it (the later one, or
# the one still admitting, exits 1 naming the other; docs/runtime.md#one-world-per-domain).
[ -z "$domain" ] && [ "$secure" -eq 1 ] && domain=$(identities_domain)
if [ -z "$domain" ]; then
  for _ in 1 2 3 4 5; do
    domain=$(( (RANDOM % 200) + 20 ))
    [ -x "$bin/marsala-monitor" ] || break
    "$bin/marsala-monitor" status --dds "$dds" --domain "$domain" --timeout 1 --listen 0 >/dev/null 2>&1 || break
    [ "$quiet" -eq 1 ] || echo "spawn.sh: domain $domain is busy (a world answers there), trying another"
  done
fi

# A folder a world holds (OUT/world.lock, flock: a run goes on there, or is paused) is refused before anything in it
# is touched (docs/runtime.md#run-folders); the world checks it again itself.
if [ -e "$out/world.lock" ] && ! flock -n "$out/world.lock" true 2>/dev/null; then
  echo "spawn.sh: output folder '$out' is in use by marsala-world pid $(head -c 20 "$out/world.lock" | tr -dc 0-9): a run goes on there, or is paused; wait for its end, stop it, or give another --out" >&2
  exit 2
fi
sec_args=()
if [ "$secure" -eq 1 ]; then
  [ "$domain" -le 230 ] || { echo "spawn.sh: a secured run needs a domain <= 230, got $domain" >&2; exit 2; }
  sec_args=(--security "$identities")
fi

world_args=(--scenario "$scenario" --agents "$agents")
[ -n "$fork" ] && world_args=(--fork "$fork" --at "$fork_at" ${fork_agents:+--agents "$fork_agents"})
world_args+=(--dds "$dds" --domain "$domain" --out "$out" "${sec_args[@]}")
[ "$replace" -eq 1 ] && world_args+=(--replace)
[ -n "$max_steps" ] && world_args+=(--max-steps "$max_steps")
[ -n "$frames_every" ] && world_args+=(--frames-every "$frames_every")  # the world checks K (exit 2 when bad)
[ "$quiet" -eq 1 ] && world_args+=(--quiet)
seed_args=()
[ -n "$seed" ] && seed_args=(--seed "$seed")
agent_args=()
[ "$dump_maps" -eq 1 ] && agent_args=(--dump-map "$out/maps")
# A fork's world takes the parent's from its log, and only the fork's own --set from here.
if [ -z "$fork" ]; then world_args+=("${seed_args[@]}" "${set_args[@]}"); else world_args+=("${fork_set_args[@]}"); fi
world_args+=("${observe_args[@]}")

# The world's own start-up checks with the run's arguments (scenario, terrain, completion, slots, --agents), before
# any process starts: a bad scenario fails here with the check's message (marsala-world --check, no DDS).
check_rc=0
"$bin/marsala-world" --check "${world_args[@]}" >/dev/null || check_rc=$?
if [ "$check_rc" -ne 0 ]; then
  echo "spawn.sh: marsala-world --check rejects the run (exit $check_rc); nothing started" >&2
  exit "$check_rc"
fi
# Secured: the identity folder, made on first use or reused when it fits this domain and team (exit 2 otherwise,
# before anything of the run is written; docs/runtime.md#security).
if [ "$secure" -eq 1 ]; then
  ids_line=$("$root/deploy/security/make-identities.sh" --out "$identities" --agents "$agents" --domain "$domain" \
    --reuse) || exit $?
  case "$ids_line" in
    "identities: made"*) echo "spawn.sh: $ids_line" >&2 ;;  # a new secret on disk: said even with --quiet
    *) [ "$quiet" -eq 1 ] || echo "spawn.sh: $ids_line" ;;
  esac
fi

# A run never mixes its outputs with another's: the world refuses a folder holding a run; with --replace it removes
# that run's files itself (marsala-world --replace knows the list), and the agents' old logs go here.
[ "$replace" -eq 1 ] && [ -d "$out" ] && rm -rf -- "$out/logs" "$out/maps" "$out/dds"

mkdir -p "$out/logs"
# The run's key (docs/runtime.md#who-wrote-it): the world proves itself with it; the agents and monitors, given it,
# believe no other participant speaking in the world's name. OUT/run.key, readable by its owner only; --resume reads
# it back.
(umask 077 && od -An -tx1 -N32 /dev/urandom | tr -d ' \n' >"$out/run.key")
key_args=(--run-key "$out/run.key")
export MARSALA_RUN_KEY="$out/run.key"
pids=()
cleanup() {
  trap - EXIT INT TERM
  for pid in "${pids[@]}"; do kill -TERM "$pid" 2>/dev/null || true; done
  sleep 0.5
  for pid in "${pids[@]}"; do kill -KILL "$pid" 2>/dev/null || true; done
  wait 2>/dev/null || true
}
trap cleanup EXIT
trap 'echo "spawn.sh: interrupted, stopping children" >&2; exit 130' INT TERM

"$bin/marsala-world" "${world_args[@]}" "${key_args[@]}" >"$out/logs/world.log" 2>&1 &
world_pid=$!
pids+=("$world_pid")
for id in $(seq 1 "$agents"); do
  late_args=()  # a fork's late slot waits for K, up to the run's time limit
  [ -n "$parent_team" ] && [ "$id" -gt "$parent_team" ] && late_args=(--admit-timeout "$timeout_s")
  "$bin/marsala-agent" --scenario "$scenario" --id "$id" --dds "$agent_dds" --domain "$domain" "${late_args[@]}" \
    "${seed_args[@]}" "${set_args[@]}" "${sec_args[@]}" "${agent_args[@]}" "${key_args[@]}" >"$out/logs/agent-$id.log" 2>&1 &
  pids+=("$!")
done
[ "$quiet" -eq 1 ] || echo "spawn.sh: world (pid $world_pid, $dds) and $agents agents ($agent_dds) on domain $domain, profile $profile$([ "$fastdds_profile" != "$profile" ] && [ "$dds$agent_dds" != cyclonecyclone ] && echo " (Fast DDS: $fastdds_profile)")$([ -n "$peers" ] && echo " (peers $peers)"), $([ "$secure" -eq 1 ] && echo "secured with $identities" || echo unsecured); logs in $out/logs"

progress_pid=""
if [ "$monitor" -eq 1 ] && [ -x "$bin/marsala-monitor" ]; then
  "$bin/marsala-monitor" tail --dds "$dds" --domain "$domain" "${sec_args[@]}" &
  pids+=("$!")
elif [ "$quiet" -eq 0 ] && [ -t 1 ] && [ -x "$bin/marsala-monitor" ]; then
  # One line, rewritten in place, on a terminal only: a log file or a pipe gets nothing extra.
  "$bin/marsala-monitor" progress --in-place --dds "$dds" --domain "$domain" "${sec_args[@]}" 2>/dev/null &
  progress_pid=$!
  pids+=("$progress_pid")
fi

# Wait for the world to finish, or give up after the timeout.
start=$SECONDS
while kill -0 "$world_pid" 2>/dev/null; do
  if [ $((SECONDS - start)) -ge "$timeout_s" ]; then
    echo "spawn.sh: no end after ${timeout_s}s, stopping the run" >&2
    kill -TERM "$world_pid" 2>/dev/null || true
    sleep 2
  fi
  sleep 0.2
done
world_rc=0
wait "$world_pid" || world_rc=$?
if [ "$dump_maps" -eq 1 ]; then
  # The agents write their maps on the run-over frame and exit: give them up to 10 s before the cleanup stops them
  # (stopped, they still write theirs, within its 0.5 s).
  for _ in $(seq 1 100); do
    alive=0
    for pid in "${pids[@]:1:$agents}"; do kill -0 "$pid" 2>/dev/null && alive=1; done
    [ "$alive" -eq 0 ] && break
    sleep 0.1
  done
fi
if [ -n "$progress_pid" ]; then
  # It ends by itself on the world's last status; a world that died without one leaves it waiting: stop it.
  for _ in $(seq 1 20); do kill -0 "$progress_pid" 2>/dev/null || break; sleep 0.1; done
  kill -TERM "$progress_pid" 2>/dev/null || true
  wait "$progress_pid" 2>/dev/null || true
fi
# 0 completed, 3 max_steps, 4 no_live_agents, 5 signal, 6 stalled, 7 completed short of slots: the run ended and
# wrote its outputs (docs/runtime.md#exit-codes).
case "$world_rc" in
  0|3|4|5|6|7) ;;  # 8: a fork's request differed from its parent's before K (the world's log says which)
  *)
    echo "spawn.sh: marsala-world exited with $world_rc; last lines of its log:" >&2
    tail -n 20 "$out/logs/world.log" >&2
    exit "$world_rc" ;;
esac
if [ ! -f "$out/summary.json" ]; then
  echo "spawn.sh: the world wrote no summary in $out" >&2
  exit 1
fi
if [ "$quiet" -eq 0 ]; then
  # The account for people; summary.json keeps every figure.
  if [ -x "$bin/marsala-monitor" ]; then
    "$bin/marsala-monitor" summary "$out" || echo "spawn.sh: see $out/summary.json"
  else
    echo "spawn.sh: the run is over; see $out/summary.json and the pictures in $out"
  fi
fi
if [ "$world_rc" -eq 7 ]; then
  echo "spawn.sh: the run completed without some of its slots (summary.json slots_missing); exit 7" >&2
elif [ "$world_rc" -ne 0 ]; then
  echo "spawn.sh: the run ended without completing; exit $world_rc" >&2
fi
exit "$world_rc"
