#!/usr/bin/env bash
# DDS Security (docs/runtime.md#security), one vendor per case: identities from deploy/security/make-identities.sh,
# processes in a private network namespace (ctest runs it inside run_isolated.sh).
#
# Usage: security_test.sh VENDOR DOMAIN
#   1. a secured 3-agent ramp run (spawn.sh --secure) completes on the unsecured run's terrain_sha256;
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
. "$root/tests/integration/lib.sh"  # field
command -v openssl >/dev/null || { echo "SKIP: openssl not installed"; exit 77; }

# 1. A secured run ends where the unsecured one does.
run() {  # run OUT [--secure]
  "$root/deploy/spawn.sh" --scenario "$root/deploy/scenarios/ramp.pbtxt" --agents 3 --dds "$vendor" \
    --domain "$domain" --out "$work/$1" --quiet --timeout 300 "${@:2}" >&2 || fail "spawn.sh $* failed (logs: $work/$1/logs)"
}
run plain
run secured --secure
[ "$(field completed "$work/secured/summary.json")" = true ] || fail "the secured run did not complete"
sha_plain=$(field terrain_sha256 "$work/plain/summary.json")
sha_secured=$(field terrain_sha256 "$work/secured/summary.json")
[ "$sha_secured" = "$sha_plain" ] || fail "secured run ends on $sha_secured, unsecured on $sha_plain"
echo "ok: secured ramp run completed on ${sha_secured:0:8} (admitted in $(jq -r .admit_seconds "$work/secured/summary.json") s," \
  "unsecured $(jq -r .admit_seconds "$work/plain/summary.json") s; step median" \
  "$(jq -r .step_wall_median_ms "$work/secured/summary.json") ms against $(jq -r .step_wall_median_ms "$work/plain/summary.json") ms)"

# 2. The fence.
sec="$work/secured/security"
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
