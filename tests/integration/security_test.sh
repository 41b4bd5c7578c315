#!/usr/bin/env bash
# DDS Security (docs/runtime.md#security), one vendor per case: identities from deploy/security/make-identities.sh,
# processes in a private network namespace (ctest runs it inside run_isolated.sh).
#
# Usage: security_test.sh VENDOR DOMAIN
#   0. spawn.sh's bad inputs: --secure with --insecure, an unknown profile, --peers on a multicast profile, a secured
#      team of two vendors, --identities on an unsecured run, an identity folder made for another domain or a smaller
#      team: one line naming it, exit 2, no run folder made;
#   1. a 3-agent ramp run on the unicast profile (--peers 127.0.0.1), no security flag, is secured by default (the
#      identity folder made on first use, the world's and agents' logs say "secured") and completes on the terrain of
#      the unsecured run (marsala-lockstep-sim, in-process); a second run, --secure on loopback, reuses the folder
#      (same CA fingerprint, no file rewritten) and ends there too;
#   2. the fence, with marsala-bus-probe processes on one partition of agent 1 (run/agent-1-5eed):
#      - the world's frames reach agent 1's secured reader;
#      - a participant without identity receives none of them, and its own frames never reach agent 1;
#      - agent 2 may not read agent 1's frames, nor write frames at all, nor open a request writer on agent 1's
#        partition, while agent 1 may.
set -euo pipefail
vendor="$1"
domain="$2"
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
build="${MARSALA_BUILD_DIR:-$root/build}"
probe="$build/tests/marsala-bus-probe"
work="$(mktemp -d "${TMPDIR:-/tmp}/marsala-it-security-$vendor.XXXXXX")"
pids=()
cleanup() {
  for p in "${pids[@]}"; do kill -KILL "$p" 2>/dev/null || true; done
  wait 2>/dev/null || true
  rm -rf "$work"
}
trap cleanup EXIT
fail() { echo "FAIL (security $vendor): $*" >&2; exit 1; }
. "$root/tests/integration/lib.sh"  # field, csv_last
command -v openssl >/dev/null || { echo "SKIP: openssl not installed"; exit 77; }

scenario="$root/deploy/scenarios/ramp.pbtxt"
ids="$work/identities"
# The unsecured run's terrain, in-process, while the secured runs go.
"$build/bin/marsala-lockstep-sim" --scenario "$scenario" --agents 3 --seeds 1 --csv "$work/sim.csv" >/dev/null 2>&1 &
sim=$!
spawn() {  # spawn OUT ARGS...: spawn.sh's exit code in rc, its stderr in $work/OUT.err
  rc=0
  "$root/deploy/spawn.sh" --scenario "$scenario" --agents 3 --dds "$vendor" --out "$work/$1" --timeout 300 \
    "${@:2}" >/dev/null 2>"$work/$1.err" || rc=$?
}

# 0. Bad inputs: exit 2, one line naming what is wrong, nothing written.
"$root/deploy/security/make-identities.sh" --out "$work/two" --agents 2 --domain "$domain" >/dev/null
# A relative --out (README's by-hand line) makes the folder where it says.
(cd "$work" && "$root/deploy/security/make-identities.sh" --out rel/ids --agents 1 --domain "$domain" >/dev/null) ||
  fail "make-identities.sh --out rel/ids failed"
[ -f "$work/rel/ids/manifest" ] && [ -f "$work/rel/ids/agent-1.key" ] || fail "make-identities.sh --out rel/ids made no folder"
spawn_refused() {  # spawn_refused WORDS ARGS...: spawn.sh ARGS exits 2, one line holding WORDS, no run folder
  local words="$1"
  shift
  spawn bad "$@"
  [ "$rc" = 2 ] && [ "$(wc -l <"$work/bad.err")" = 1 ] && grep -qF -- "$words" "$work/bad.err" ||
    fail "spawn.sh $*: exit $rc, expected 2 and one line with '$words': $(cat "$work/bad.err")"
  [ ! -e "$work/bad" ] || fail "spawn.sh $* wrote $work/bad"
}
spawn_refused "--secure and --insecure" --secure --insecure --domain "$domain"
spawn_refused "--profile must be lo, lan or unicast" --profile wan --domain "$domain"
other=$([ "$vendor" = cyclone ] && echo fastdds || echo cyclone)
spawn_refused "a secured team runs on one vendor" --profile unicast --agent-dds "$other" --domain "$domain"
spawn_refused "--peers is for --profile unicast" --peers 127.0.0.1 --profile lan --domain "$domain"
spawn_refused "--identities $ids is for secured runs" --profile lan --insecure --identities "$ids" --domain "$domain"
spawn_refused "$work/two was made for domain $domain, not $((domain + 1))" --profile lan --identities "$work/two" \
  --domain $((domain + 1))
spawn_refused "$work/two was made for 2 agents, this run needs 3" --secure --identities "$work/two" --domain "$domain"
# A run that marsala-world --check rejects (no --domain: the folder's, or a free one) makes no identities.
spawn bad --secure --identities "$ids" --set no_such_field=1
[ "$rc" = 2 ] && grep -q "marsala-world --check rejects the run" "$work/bad.err" ||
  fail "a rejected scenario: exit $rc, expected 2: $(cat "$work/bad.err")"
[ ! -e "$ids" ] && [ ! -e "$work/bad" ] || fail "a refused run made $ids or its run folder"
echo "ok: spawn.sh refuses --secure with --insecure, an unknown profile, a secured mixed team, --identities" \
  "unsecured, a folder of another domain or a smaller team (exit 2, one line, nothing written)"

# 1. Secured by default beyond loopback; the folder made on first use, then reused; the unsecured terrain.
spawn unicast --peers 127.0.0.1 --identities "$ids" --domain "$domain"  # --peers: the unicast profile
[ "$rc" = 0 ] || fail "the unicast run exited $rc: $(cat "$work/unicast.err") (logs: $work/unicast/logs)"
grep -qx "spawn.sh: identities: made $ids for domain $domain, 3 agents (CA sha256 .*)" "$work/unicast.err" ||
  fail "spawn.sh did not say where it made the identities: $(cat "$work/unicast.err")"
for log in world agent-1 agent-3; do
  grep -q "secured (DDS Security) as ${log} from $ids" "$work/unicast/logs/$log.log" ||
    fail "the unicast run's $log.log does not say it is secured"
done
grep -q "discovers by unicast only, at 127.0.0.1" "$work/unicast/logs/world.log" || fail "the world does not say its peers"
[ "$(stat -c %a "$ids/world.key")" = 600 ] || fail "world.key is $(stat -c %a "$ids/world.key"), not 600"
ca=$(openssl x509 -noout -fingerprint -sha256 -in "$ids/ca.pem" | sed 's/^.*=//')
grep -qx "ca_sha256=$ca" "$ids/manifest" || fail "the manifest does not name the CA's fingerprint $ca"
before=$(cd "$ids" && ls -l --time-style=+%s.%N && sha256sum ./*)
spawn reused --secure --identities "$ids"  # no --domain: the folder's
[ "$rc" = 0 ] || fail "the reusing run exited $rc: $(cat "$work/reused.err") (logs: $work/reused/logs)"
[ "$(cd "$ids" && ls -l --time-style=+%s.%N && sha256sum ./*)" = "$before" ] || fail "the second run rewrote $ids"
grep -q "secured (DDS Security) as world from $ids" "$work/reused/logs/world.log" ||
  fail "the second run is not secured"
[ "$(jq -r .run_id "$work/reused/summary.json")" = "ramp-d$domain" ] ||
  fail "the second run did not take the folder's domain $domain ($(jq -r .run_id "$work/reused/summary.json"))"
wait "$sim" || fail "marsala-lockstep-sim failed"
want=$(csv_last "$work/sim.csv" terrain_sha256)
for run in unicast reused; do
  [ "$(field completed "$work/$run/summary.json")" = true ] || fail "the $run run did not complete"
  [ "$(field terrain_sha256 "$work/$run/summary.json")" = "$want" ] ||
    fail "the $run run ends on $(field terrain_sha256 "$work/$run/summary.json"), unsecured on $want"
done
admit=$(jq -r .admit_seconds "$work/unicast/summary.json")
step=$(jq -r .step_wall_median_ms "$work/unicast/summary.json")
echo "ok: the unicast run, secured by default, and a --secure run reusing its identities (CA ${ca:0:23}...)" \
  "completed on the unsecured terrain ${want:0:8} (admitted in $admit s; step median $step ms)"

# 2. The fence.
sec="$ids"
part="run/agent-1-5eed"
as() {  # as IDENTITY: the probe's security arguments ("none": unsecured)
  [ "$1" = none ] || echo "--security $sec --identity $1"
}
start() {  # start NAME IDENTITY MODE ARGS...: a probe in the background, output in $work/NAME.out
  local name="$1" who="$2" mode="$3"
  shift 3
  # shellcheck disable=SC2046  # the security arguments split into words on purpose
  "$probe" "$mode" --dds "$vendor" --domain "$domain" $(as "$who") "$@" >"$work/$name.out" 2>"$work/$name.err" &
  pids+=("$!")
  eval "pid_$name=$!"
}
wait_for() {  # wait_for NAME LINE SECONDS
  local i
  for i in $(seq 1 $(($3 * 10))); do
    grep -qx "$2" "$work/$1.out" 2>/dev/null && return 0
    sleep 0.1
  done
  return 1
}
exit_of() {  # exit_of NAME: waits for the probe and sets rc to its exit code (a child: not from a subshell)
  local pid
  pid=$(eval echo "\$pid_$1")
  rc=0
  wait "$pid" || rc=$?
}

start agent1 agent-1 read --role client --partition "$part" --count 5 --timeout-s 30
start outsider none read --role client --partition "$part" --count 0 --timeout-s 60
wait_for agent1 ready 10 || fail "agent 1's secured reader did not start: $(cat "$work/agent1.err")"
wait_for outsider ready 10 || fail "the unsecured reader did not start"
start world world write --partition "$part" --count 5 --readers 1
exit_of agent1
[ "$rc" = 0 ] || fail "agent 1 did not receive the world's 5 frames: $(tail -1 "$work/agent1.out")"
# The outsider ran all along; a frame reaching it makes it exit 1 at once.
sleep 2
kill -TERM "$pid_outsider" "$pid_world"
exit_of outsider
[ "$rc" = 0 ] || fail "a participant without identity received frames: $(tail -1 "$work/outsider.out")"
echo "ok: the world's frames reach agent 1 and no participant without identity"

# A participant without identity writes frames on agent 1's partition: agent 1 gets none.
start agent1b agent-1 read --role client --partition "$part" --count 0 --timeout-s 60
wait_for agent1b ready 10 || fail "agent 1's second reader did not start"
start forger none write --partition "$part" --count 5 --readers 0
wait_for forger "written 5" 20 || fail "the unsecured writer did not write: $(cat "$work/forger.err")"
sleep 3
kill -TERM "$pid_agent1b" "$pid_forger"
exit_of agent1b
[ "$rc" = 0 ] || fail "frames of a participant without identity reached agent 1"
echo "ok: frames written by a participant without identity never reach agent 1"

# Agent 2 against agent 1's partition, and agent 1 on its own.
refused() {  # refused NAME: the probe exited 3 (DDS Security refused the endpoint)
  exit_of "$1"
  [ "$rc" = 3 ] || fail "$1: exit $rc, expected 3 (refused): $(cat "$work/$1.out" "$work/$1.err" | tail -2)"
}
start snoop agent-2 read --role client --partition "$part" --count 0 --timeout-s 20
refused snoop
start fake agent-2 write --role client --partition "run/agent-2-5eed" --count 1 --readers 0
refused fake
start steal agent-2 open-request --role client --partition "$part"
refused steal
start own agent-1 open-request --role client --partition "$part"
wait_for own opened 10 || fail "agent 1 may not open its own request writer: $(cat "$work/own.err")"
kill -TERM "$pid_own"
echo "ok: agent 2 may not read agent 1's frames, write frames, or open a request writer on agent 1's partition"
