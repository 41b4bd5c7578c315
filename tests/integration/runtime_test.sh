#!/usr/bin/env bash
# Multi-process integration tests of the runtime: real marsala-world and marsala-agent processes over DDS, each
# test on its own domain with the loopback configs; ctest runs it inside run_isolated.sh (a private network
# namespace with only lo, when permitted).
#
# Usage: runtime_test.sh CASE DOMAIN
#   ramp1-cyclone | ramp1-fastdds | ramp3-cyclone | ramp3-fastdds   the ramp scenario with 1 or 3 agents
#   mixed-cyclone-fastdds | mixed-fastdds-cyclone                    world on one vendor, agents on the other
#   determinism                                                      2 Cyclone runs + 1 Fast DDS run: same sha256
#   rogue                                                            a misbehaving agent is rejected, run completes
#   resume                                                           world killed 3 times and resumed: same terrain
#   torn-tail                                                        resume cuts a torn record at run.log's end
#   agent-restart                                                    SIGKILL an agent, restart it: it takes over
#   drop-rejoin                                                      an agent paused 7 s is dropped, then re-admitted
#   full-disk                                                        the world's disk fills: exit 1, then --resume
#   two-worlds                                                       a second world on a busy domain refuses
#   flood                                                            hello and request floods: bounded, same terrain
#   auto-ids                                                         three --id auto agents: same terrain as fixed ids
#   kill                                                             SIGKILL one of 3 agents mid-run, others finish
#   pause                                                            SIGSTOP the world, then an agent, 3 s each: the
#                                                                    run loses nothing (same sha256 as unpaused)
#   world-kill                                                       SIGKILL the world mid-run: every agent waits its
#                                                                    --world-timeout (5 s) and exits 1 saying so
#   monitor                                                          marsala-monitor tail follows a run to its end; a
#                                                                    run short of a slot exits 7 and says so; tail
#                                                                    ends (exit 3) when the world is killed
#   impostor                                                         a participant forging admissions, frames, statuses
#                                                                    and events in the world's name, also during a
#                                                                    4 s pause of the world, changes nothing
#   foreign                                                          a foreign type flooding the agents' partitions of
#                                                                    a Fast DDS run: bounded log, same terrain
#   fork                                                             spawn.sh --fork of a 160-step run at K = 100:
#                                                                    unchanged, it ends on the parent's terrain; a
#                                                                    world-only --set (a goal) ends where the parent
#                                                                    stood then; --agents 2 has the parent's terrain at
#                                                                    K, diverges, completes with exit 0; a third
#                                                                    agent joins a fork of a 2-agent run at K; agents of
#                                                                    another scenario: exit 8; bad input (an agents'
#                                                                    field in --set too): exit 2, nothing written
set -euo pipefail
case_name="$1"
domain="$2"
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
bin="${MARSALA_BUILD_DIR:-$root/build}/bin"
scenario="$root/deploy/scenarios/ramp.pbtxt"

work="$(mktemp -d "${TMPDIR:-/tmp}/marsala-it-$case_name.XXXXXX")"
trap '[ -n "${MARSALA_KEEP_WORK:-}" ] || rm -rf "$work"' EXIT  # MARSALA_KEEP_WORK=1 keeps the logs

fail() { echo "FAIL ($case_name): $*" >&2; exit 1; }
. "$root/tests/integration/lib.sh"  # field, is_png, csv_last
run_spawn() {  # run_spawn OUT_NAME AGENTS DDS [AGENT_DDS]
  local out="$work/$1"
  "$root/deploy/spawn.sh" --scenario "$scenario" --agents "$2" --dds "$3" --agent-dds "${4:-$3}" \
    --domain "$domain" --out "$out" --quiet --timeout 300 || fail "spawn.sh failed for $1 (logs: $out/logs)"
  [ -f "$out/summary.json" ] || fail "no summary.json in $out"
  echo "$out/summary.json"
}
# start_run OUT [WORLD ARGS]: world and agents 1..3 on Cyclone in the background; sets out, logs, world, pids.
# Optional: logs_dir (default OUT/logs), world_wrap (a command the world runs under), agent_ids=auto (--id auto),
# world_only=1 (the agents later, with start_agents).
start_run() {
  export CYCLONEDDS_URI="file://$root/deploy/dds/cyclone-lo.xml"
  out="$1"
  shift
  logs="${logs_dir:-$out/logs}"
  mkdir -p "$logs"
  ${world_wrap:-} "$bin/marsala-world" --scenario "$scenario" --agents 3 --dds cyclone --domain "$domain" \
    --out "$out" "$@" >"$logs/world.log" 2>&1 &
  world=$!
  [ -n "${world_only:-}" ] || start_agents
}
# start_agents: agents 1..3 of start_run's world (start_run with world_only=1 starts the world alone), with the
# options in agent_args.
agent_args=()
start_agents() {
  pids=()
  for id in 1 2 3; do
    "$bin/marsala-agent" --scenario "$scenario" --id "${agent_ids:-$id}" --dds cyclone --domain "$domain" \
      "${agent_args[@]}" >"$logs/agent-$id.log" 2>&1 &
    pids+=($!)
  done
}
expect_completed() {  # expect_completed SUMMARY AGENTS
  [ "$(field completed "$1")" = "true" ] || { cat "$1"; fail "run did not complete"; }
  [ "$(field agents "$1")" = "$2" ] || { cat "$1"; fail "expected $2 agents in the summary"; }
}

case "$case_name" in
  ramp1-cyclone|ramp1-fastdds|ramp3-cyclone|ramp3-fastdds)
    n="${case_name:4:1}"
    vendor="${case_name#ramp?-}"
    s=$(run_spawn run "$n" "$vendor")
    expect_completed "$s" "$n"
    echo "ok: $case_name completed in $(field steps "$s") steps, $(field wall_seconds "$s") s"
    ;;
  mixed-cyclone-fastdds|mixed-fastdds-cyclone)
    world="$(echo "$case_name" | cut -d- -f2)"
    agents="$(echo "$case_name" | cut -d- -f3)"
    s=$(run_spawn run 3 "$world" "$agents")
    expect_completed "$s" 3
    echo "ok: world on $world, agents on $agents: completed in $(field steps "$s") steps"
    ;;
  determinism)
    a=$(run_spawn a 3 cyclone)
    b=$(run_spawn b 3 cyclone)
    c=$(run_spawn c 3 fastdds)
    for s in "$a" "$b" "$c"; do expect_completed "$s" 3; done
    sha_a=$(field terrain_sha256 "$a"); sha_b=$(field terrain_sha256 "$b"); sha_c=$(field terrain_sha256 "$c")
    [ -n "$sha_a" ] || fail "no terrain_sha256"
    [ "$sha_a" = "$sha_b" ] || fail "two Cyclone runs differ: $sha_a vs $sha_b"
    [ "$sha_a" = "$sha_c" ] || fail "Cyclone and Fast DDS runs differ: $sha_a vs $sha_c"
    [ "$(field steps "$a")" = "$(field steps "$c")" ] || fail "step counts differ"
    echo "ok: three runs, one terrain: $sha_a"
    ;;
  rogue)
    export CYCLONEDDS_URI="file://$root/deploy/dds/cyclone-lo.xml"
    out="$work/rogue"
    mkdir -p "$out/logs"
    # A two-slot run: agent 1 is honest, agent 2 is the rogue.
    "$bin/marsala-world" --scenario "$scenario" --agents 2 --dds cyclone --domain "$domain" --out "$out" \
      >"$out/logs/world.log" 2>&1 &
    world=$!
    # The rogue first: it reads agent 1's session from agent 1's hellos.
    "$bin/marsala-rogue-agent" "$scenario" 2 cyclone "$domain" >"$out/logs/rogue.log" 2>&1 &
    rogue=$!
    sleep 0.5
    "$bin/marsala-agent" --scenario "$scenario" --id 1 --dds cyclone --domain "$domain" >"$out/logs/agent-1.log" 2>&1 &
    agent=$!
    wait "$rogue" || true
    # The rogue left: the run completes short of its slot, exit 7 (docs/runtime.md#exit-codes).
    rc=0
    wait "$world" || rc=$?
    [ "$rc" -eq 7 ] || { tail -30 "$out/logs/world.log"; fail "world exited $rc, expected 7 (completed without the rogue)"; }
    wait "$agent" || true
    s="$out/summary.json"
    [ "$(field completed "$s")" = "true" ] || { cat "$s"; tail -30 "$out/logs/world.log"; fail "honest agent did not complete"; }
    sent=$(grep -c "sending" "$out/logs/rogue.log" || true)
    [ "$sent" -ge 8 ] || { cat "$out/logs/rogue.log"; fail "rogue sent only $sent attacks"; }
    # Every attack is rejected (or, the identical duplicate, ignored) and charged to the sender: the rogue's own
    # identity, or no agent when it forged one; never the victim, agent 1.
    entry() { tr -d '\n ' <"$s" | grep -o "{\"agent_id\":$1,[^}]*}" | grep -o "\"$2\":[0-9]*" | cut -d: -f2; }
    [ "$(entry 1 rejected)" = "0" ] || fail "the victim was charged $(entry 1 rejected) rejections"
    [ "$(entry 2 rejected)" -ge 5 ] || fail "the rogue was charged only $(entry 2 rejected) rejections"
    # Agent 1's partition is written only by agent 1's participant: the spoofed id and agent 1's own session, sent
    # from the rogue's participant, are ignored before any rule sees them (docs/runtime.md#who-wrote-it).
    grep -q "sending agent 1's session" "$out/logs/rogue.log" || { cat "$out/logs/rogue.log"; fail "no hijack sent"; }
    grep -q "agent 1: ignoring requests of its session [0-9a-f]* from participant" "$out/logs/world.log" ||
      { grep "agent 1" "$out/logs/world.log" | tail; fail "the world did not ignore the requests on agent 1's session"; }
    # The second copy is noted as a repeat when it arrives before the step is applied, else as a request for a past
    # step (the first copy completed the step's answers): a race of the two writes, ignored either way.
    grep -Eq "agent 2: request for step [0-9]+ repeated; the first stands|agent 2: request for past step [0-9]+ dropped" \
      "$out/events.log" || {
      tail -12 "$out/logs/rogue.log"; grep '"agent":2\|agent 2' "$out/events.log" | tail -12
      fail "the identical duplicate was not noted"
    }
    echo "ok: $sent attacks; rogue charged $(entry 2 rejected), the victim's session ignored from the rogue, victim 0;" \
      "honest agent completed in $(field steps "$s") steps"
    ;;
  kill)
    start_run "$work/kill"
    # Kill agent 2 without warning as soon as it has deposited (events.log is written live): mid-run for sure.
    for _ in $(seq 1 3000); do grep -q '"agent":2,"kind":"deposited"' "$out/events.log" 2>/dev/null && break; sleep 0.02; done
    grep -q '"agent":2,"kind":"deposited"' "$out/events.log" || fail "agent 2 never deposited (see $out/logs)"
    kill -KILL "${pids[1]}"
    rc=0
    wait "$world" || rc=$?
    [ "$rc" -eq 7 ] || { tail -30 "$out/logs/world.log"; fail "world exited $rc, expected 7 (completed without agent 2)"; }
    s="$out/summary.json"
    [ "$(field completed "$s")" = "true" ] || { cat "$s"; tail -30 "$out/logs/world.log"; fail "survivors did not complete"; }
    [ "$(field slots_missing "$s")" = 1 ] && tr -d '\n ' <"$s" | grep -q '"missing_agents":\[2\]' ||
      { cat "$s"; fail "summary.json does not name slot 2 missing"; }
    grep -q "lost liveliness" "$out/logs/world.log" || fail "world never noticed the killed agent via liveliness"
    # Agent 2's entry: it took part before it died, and it was dropped.
    entry2=$(tr -d '\n ' <"$s" | grep -o '{"agent_id":2,[^}]*}')
    accepted2=$(echo "$entry2" | grep -o '"accepted":[0-9]*' | cut -d: -f2)
    echo "$entry2" | grep -q '"dropped":true' || fail "agent 2 is not marked dropped: $entry2"
    [ "${accepted2:-0}" -gt 0 ] || fail "agent 2 was killed before it took part (accepted $accepted2)"
    echo "ok: agent 2 killed, dropped, the other two completed in $(field steps "$s") steps"
    ;;
  pause)
    reference=$(run_spawn reference 3 cyclone)
    expect_completed "$reference" 3
    start_run "$work/pause"
    wait_for_event() {  # wait_for_event PATTERN: until events.log (written live) holds it
      for _ in $(seq 1 3000); do grep -q "$1" "$out/events.log" 2>/dev/null && return 0; sleep 0.02; done
      fail "no '$1' in events.log (see $out/logs)"
    }
    # Mid-run for sure: pause the world for 3 s (longer than the 1 s DDS liveliness lease), then agent 3.
    wait_for_event '"agent":2,"kind":"deposited"'
    kill -STOP "$world"; sleep 3; kill -CONT "$world"
    wait_for_event '"agent":1,"kind":"deposited"'
    kill -STOP "${pids[2]}"; sleep 3; kill -CONT "${pids[2]}"
    wait "$world" || { tail -30 "$out/logs/world.log"; fail "world exited non-zero"; }
    for pid in "${pids[@]}"; do wait "$pid" || fail "an agent exited non-zero after the pauses (see $out/logs)"; done
    s="$out/summary.json"
    expect_completed "$s" 3
    ! grep -q '"kind":"dropped"' "$out/events.log" ||
      { grep '"kind":"dropped"' "$out/events.log"; fail "a pause dropped an agent"; }
    [ "$(field terrain_sha256 "$s")" = "$(field terrain_sha256 "$reference")" ] ||
      fail "paused run ended on $(field terrain_sha256 "$s"), unpaused on $(field terrain_sha256 "$reference")"
    echo "ok: world and agent paused 3 s each; completed in $(field steps "$s") steps on the unpaused terrain"
    ;;
  resume)
    # SIGKILL of the world at three different steps, each time continued with --resume while the agents wait: the
    # run ends on the uninterrupted run's terrain, and a replay of its run.log gives the same digest.
    reference=$(run_spawn reference 3 cyclone)
    expect_completed "$reference" 3
    start_run "$work/resume" --snapshot-every 50
    step_reached() {  # step_reached N: events.log (written live) holds a line of step N or later
      sed -n 's/^{"step":\([0-9]*\),.*/\1/p' "$out/events.log" 2>/dev/null | awk -v n="$1" '$1 + 0 >= n { found = 1 } END { exit !found }'
    }
    resumes=0
    for at in 40 120 200; do
      for _ in $(seq 1 3000); do step_reached "$at" && break; sleep 0.01; done
      step_reached "$at" || fail "the run never reached step $at (see $out/logs)"
      kill -KILL "$world"
      wait "$world" 2>/dev/null || true
      resumes=$((resumes + 1))
      "$bin/marsala-world" --resume "$out" --dds cyclone --domain "$domain" --snapshot-every 50 \
        >"$out/logs/world-resume-$resumes.log" 2>&1 &
      world=$!
    done
    wait "$world" || { tail -30 "$out/logs/world-resume-$resumes.log"; fail "the resumed world exited non-zero"; }
    for pid in "${pids[@]}"; do wait "$pid" || fail "an agent exited non-zero across the resumes (see $out/logs)"; done
    s="$out/summary.json"
    expect_completed "$s" 3
    [ "$(field resumes "$s")" = "3" ] || fail "summary says $(field resumes "$s") resumes, not 3"
    [ "$(field terrain_sha256 "$s")" = "$(field terrain_sha256 "$reference")" ] ||
      fail "resumed run ended on $(field terrain_sha256 "$s"), uninterrupted on $(field terrain_sha256 "$reference")"
    replayed=$("$bin/marsala-monitor" replay "$out" | tail -1)
    [ "$replayed" = "terrain_sha256 $(field terrain_sha256 "$s")" ] || fail "replay printed '$replayed'"
    grep -h "resumed at step" "$out"/logs/world-resume-*.log | sed 's/^[^ ]* [^ ]* world: //'
    [ "$(grep -l "resumed at step .* after the snapshot of step" "$out"/logs/world-resume-*.log | wc -l)" -eq 3 ] ||
      fail "not every resume started from a snapshot"
    echo "ok: world killed 3 times, resumed; completed in $(field steps "$s") steps on the uninterrupted terrain;" \
      "replay agrees"
    ;;
  torn-tail)
    # A crash in the middle of writing a record leaves a torn one at the end of run.log: --resume reports and cuts
    # it, never applies it, and the run ends on the uninterrupted terrain.
    reference=$(run_spawn reference 3 cyclone)
    start_run "$work/torn-tail"
    for _ in $(seq 1 3000); do grep -q '^{"step":1[0-9][0-9],' "$out/events.log" 2>/dev/null && break; sleep 0.01; done
    kill -KILL "$world"
    wait "$world" 2>/dev/null || true
    # A frame that promises 200 payload bytes, then 7 of them.
    printf '\310\000\000\000\001\002\003\004torn!!!' >>"$out/run.log"
    "$bin/marsala-world" --resume "$out" --dds cyclone --domain "$domain" >"$out/logs/world-resume.log" 2>&1 &
    world=$!
    wait "$world" || { tail -30 "$out/logs/world-resume.log"; fail "the resumed world exited non-zero"; }
    for pid in "${pids[@]}"; do wait "$pid" || fail "an agent exited non-zero (see $out/logs)"; done
    grep -q "cut run.log's damaged tail: .*truncated record at byte [0-9]* (7 of 200 payload bytes)" \
      "$out/logs/world-resume.log" || { tail -30 "$out/logs/world-resume.log"; fail "the torn record was not reported"; }
    s="$out/summary.json"
    expect_completed "$s" 3
    [ "$(field terrain_sha256 "$s")" = "$(field terrain_sha256 "$reference")" ] ||
      fail "ended on $(field terrain_sha256 "$s"), uninterrupted on $(field terrain_sha256 "$reference")"
    [ "$("$bin/marsala-monitor" replay "$out" | tail -1)" = "terrain_sha256 $(field terrain_sha256 "$s")" ] ||
      fail "the replay of the continued log differs"
    echo "ok: a torn record was cut, never applied; completed on the uninterrupted terrain"
    ;;
  agent-restart)
    # SIGKILL of an agent, restarted at once with a new session: it waits for the old session's liveliness to lapse,
    # takes its slot over (pose and material as the world kept them), and the run completes.
    start_run "$work/agent-restart"
    for _ in $(seq 1 3000); do grep -q '"agent":2,"kind":"deposited"' "$out/events.log" 2>/dev/null && break; sleep 0.02; done
    grep -q '"agent":2,"kind":"deposited"' "$out/events.log" || fail "agent 2 never deposited (see $out/logs)"
    kill -KILL "${pids[1]}"
    wait "${pids[1]}" 2>/dev/null || true
    "$bin/marsala-agent" --scenario "$scenario" --id 2 --dds cyclone --domain "$domain" \
      >"$out/logs/agent-2-restarted.log" 2>&1 &
    pids[1]=$!
    wait "$world" || { tail -30 "$out/logs/world.log"; fail "world exited non-zero"; }
    for pid in "${pids[@]}"; do wait "$pid" || fail "an agent exited non-zero (see $out/logs)"; done
    s="$out/summary.json"
    expect_completed "$s" 3
    grep -q '"agent":2,"kind":"admitted","detail":"[^"]*takes over from' "$out/events.log" || fail "no takeover of slot 2 in events.log"
    ! grep -q '"kind":"dropped"' "$out/events.log" || fail "an agent was dropped: $(grep '"kind":"dropped"' "$out/events.log")"
    after=$(awk '/"agent":2,"kind":"admitted","detail":"[^"]*takes over/ { on = 1 } on && /"agent":2,"kind":"deposited"/ { n++ } END { print n + 0 }' \
      "$out/events.log")
    [ "$after" -gt 0 ] || fail "the restarted agent 2 never deposited"
    echo "ok: agent 2 killed and restarted; took its slot over, deposited $after times after, run completed in" \
      "$(field steps "$s") steps"
    ;;
  drop-rejoin)
    # An agent paused past the world's 6 s grace is dropped; when it runs again it asks the world (no frame for 2 s),
    # is re-admitted with the state the world kept, and the run completes with it.
    start_run "$work/drop-rejoin"
    for _ in $(seq 1 3000); do grep -q '"agent":3,"kind":"deposited"' "$out/events.log" 2>/dev/null && break; sleep 0.02; done
    kill -STOP "${pids[2]}"
    for _ in $(seq 1 150); do grep -q '"agent":3,"kind":"dropped"' "$out/events.log" 2>/dev/null && break; sleep 0.1; done
    grep -q '"agent":3,"kind":"dropped"' "$out/events.log" || { kill -CONT "${pids[2]}"; fail "agent 3 was not dropped while paused"; }
    kill -CONT "${pids[2]}"
    rc=0
    wait "$world" || rc=$?
    # 7: completed without agent 3 (the skip below); anything else but 0 is a failure.
    [ "$rc" -eq 0 ] || [ "$rc" -eq 7 ] || { tail -30 "$out/logs/world.log"; fail "world exited $rc"; }
    s="$out/summary.json"
    for k in 0 1 2; do
      wait "${pids[$k]}" && continue
      tail -n 3 "$out"/logs/agent-*.log >&2
      # The two others may reach the goal while agent 3 is still asking to come back (a loaded machine): the run
      # is over without it, and there is nothing left to check.
      if [ "$k" -eq 2 ] && [ "$(field readmissions "$s")" = "0" ] && [ "$(field completed "$s")" = "true" ]; then
        echo "SKIP: the run completed before agent 3 was re-admitted (a loaded machine); nothing to check"
        exit 77
      fi
      fail "agent $((k + 1)) exited non-zero (see $out/logs)"
    done
    expect_completed "$s" 3
    [ "$rc" -eq 0 ] || fail "the world exited $rc, though agent 3 came back (slots_missing $(field slots_missing "$s"))"
    grep -q '"agent":3,"kind":"admitted","detail":"[^"]*(re-admitted, 1 of 3)' "$out/events.log" || fail "agent 3 was not re-admitted"
    [ "$(field readmissions "$s")" = "1" ] || fail "summary says $(field readmissions "$s") readmissions"
    echo "ok: agent 3 dropped while paused, re-admitted; run completed in $(field steps "$s") steps"
    ;;
  full-disk)
    # The world's folder on a 200 kB tmpfs (a mount namespace of its own) fills mid-run: the world stops with an
    # error naming the file and exits 1, run.log ends at a whole record; on a larger disk --resume completes the
    # run on the uninterrupted terrain. Skipped (77) where mount namespaces are not permitted.
    disk="$work/disk"
    mkdir -p "$disk"
    unshare -m --propagation private true 2>/dev/null || { echo "SKIP: no mount namespaces here (unshare -m)"; exit 77; }
    reference=$(run_spawn reference 3 cyclone)
    unshare -m --propagation private sh -c "mount -t tmpfs -o size=200k tmpfs '$disk' && exec sleep 600" &
    holder=$!
    in_disk() { nsenter -t "$holder" -m -- "$@"; }
    for _ in $(seq 1 100); do in_disk mountpoint -q "$disk" 2>/dev/null && break; sleep 0.05; done
    in_disk mountpoint -q "$disk" || { kill "$holder"; echo "SKIP: cannot mount a tmpfs here"; exit 77; }
    trap 'kill "$holder" 2>/dev/null; [ -n "${MARSALA_KEEP_WORK:-}" ] || rm -rf "$work"' EXIT
    logs_dir="$work/logs" world_wrap=in_disk start_run "$disk/run"  # the world's folder on the small disk
    rc=0
    wait "$world" || rc=$?
    [ "$rc" -eq 1 ] || { tail -20 "$logs/world.log"; fail "the world exited $rc on a full disk, not 1"; }
    grep -q "No space left on device" "$logs/world.log" || { tail -5 "$logs/world.log"; fail "no 'No space left' error"; }
    error=$(grep "marsala-world: error" "$logs/world.log")
    in_disk test ! -e "$out/summary.json" || fail "a summary.json was written by a run that failed"
    in_disk "$bin/marsala-monitor" replay "$out" >"$logs/replay-full.txt" 2>"$logs/replay-full.err" ||
      { cat "$logs/replay-full.err"; fail "the log of the full disk does not replay"; }
    ! grep -q "damaged\|truncated" "$logs/replay-full.err" || fail "run.log was left with a torn record: $(cat "$logs/replay-full.err")"
    steps_full="$(awk '$1 == "steps" { print $2 + 0 }' "$logs/replay-full.txt") steps"
    in_disk mount -o remount,size=4m "$disk"
    in_disk "$bin/marsala-world" --resume "$out" --dds cyclone --domain "$domain" >"$logs/world-resume.log" 2>&1 &
    world=$!
    wait "$world" || { tail -20 "$logs/world-resume.log"; fail "the resumed world exited non-zero"; }
    for pid in "${pids[@]}"; do wait "$pid" || fail "an agent exited non-zero (see $logs)"; done
    in_disk cat "$out/summary.json" >"$work/summary.json"
    s="$work/summary.json"
    expect_completed "$s" 3
    [ "$(field terrain_sha256 "$s")" = "$(field terrain_sha256 "$reference")" ] ||
      fail "ended on $(field terrain_sha256 "$s"), uninterrupted on $(field terrain_sha256 "$reference")"
    echo "ok: the disk filled after $steps_full ($error); resumed on a larger disk, completed on the uninterrupted terrain"
    ;;
  two-worlds)
    # One world per domain: a second marsala-world started on the domain of a running one refuses to go on (exit 1,
    # naming the other run) and the first run completes undisturbed; a monitor sees the first one admitting.
    start_run "$work/two-worlds"
    for _ in $(seq 1 3000); do grep -q '"agent":1,"kind":"deposited"' "$out/events.log" 2>/dev/null && break; sleep 0.02; done
    rc=0
    "$bin/marsala-world" --scenario "$scenario" --agents 3 --dds cyclone --domain "$domain" --out "$work/second" \
      --admit-timeout 20 >"$work/second.log" 2>&1 || rc=$?
    [ "$rc" -eq 1 ] || { tail -5 "$work/second.log"; fail "the second world exited $rc, not 1"; }
    grep -q "another marsala-world runs on DDS domain $domain (run 'ramp-d$domain', scenario 'ramp', at step" \
      "$work/second.log" || { tail -5 "$work/second.log"; fail "the second world did not name the first"; }
    wait "$world" || { tail -30 "$out/logs/world.log"; fail "the first world exited non-zero"; }
    for pid in "${pids[@]}"; do wait "$pid" || fail "an agent exited non-zero (see $out/logs)"; done
    expect_completed "$out/summary.json" 3
    echo "ok: the second world refused ($(grep -o "another marsala-world.*" "$work/second.log" | head -c 120)...)," \
      "the first completed"
    ;;
  flood)
    # Floods of hellos (random ids and sessions) and of forged requests on every agent partition (a wildcard), both
    # as fast as a process can write them, for the whole run: it completes on the unflooded digest, nobody dropped,
    # the honest agents charged nothing, the flood counted; the world's memory and logs stay within stated bounds
    # (docs/runtime.md#load-limits).
    reference=$(run_spawn reference 3 cyclone)
    export CYCLONEDDS_URI="file://$root/deploy/dds/cyclone-lo.xml"
    mkdir -p "$work/logs"
    "$bin/marsala-flooder" hellos 12 "$scenario" cyclone "$domain" >"$work/logs/flood-hellos.txt" 2>&1 &
    f1=$!
    "$bin/marsala-flooder" requests 12 "$scenario" cyclone "$domain" >"$work/logs/flood-requests.txt" 2>&1 &
    f2=$!
    sleep 1
    start_run "$work/flood"
    peak=0
    while kill -0 "$world" 2>/dev/null; do
      rss=$(awk '/^VmRSS/ { print $2 }' "/proc/$world/status" 2>/dev/null || echo 0)
      [ "${rss:-0}" -gt "$peak" ] && peak=$rss
      sleep 0.25
    done
    wait "$world" || { tail -30 "$out/logs/world.log"; fail "world exited non-zero under the flood"; }
    for pid in "${pids[@]}"; do wait "$pid" || fail "an agent exited non-zero under the flood (see $out/logs)"; done
    wait "$f1" "$f2" || fail "a flooder failed: $(cat "$work"/logs/flood-*.txt)"
    s="$out/summary.json"
    expect_completed "$s" 3
    [ "$(field terrain_sha256 "$s")" = "$(field terrain_sha256 "$reference")" ] ||
      fail "flooded run ended on $(field terrain_sha256 "$s"), unflooded on $(field terrain_sha256 "$reference")"
    ! grep -q '"kind":"dropped"' "$out/events.log" || fail "the flood dropped an agent"
    for id in 1 2 3; do
      rej=$(tr -d '\n ' <"$s" | grep -o "{\"agent_id\":$id,[^}]*}" | grep -o '"rejected":[0-9]*' | cut -d: -f2)
      [ "$rej" = "0" ] || fail "honest agent $id was charged $rej rejections"
    done
    # The forged requests come from other participants than the sessions' owners: ignored before any rule, counted
    # per agent (docs/runtime.md#who-wrote-it).
    grep -q "agent [123]: ignoring requests of its session [0-9a-f]* from participant .* ([0-9]*000 so far)" \
      "$out/logs/world.log" || fail "the request flood was not counted (no 1000th ignored request in the world log)"
    events=$(stat -c %s "$out/events.log")
    world_log=$(stat -c %s "$out/logs/world.log")
    [ "$peak" -lt 153600 ] || fail "world peak RSS $peak kB exceeds the 150 MB bound"
    [ "$events" -lt 2097152 ] || fail "events.log grew to $events bytes under the flood (bound 2 MB)"
    [ "$world_log" -lt 2097152 ] || fail "the world's log grew to $world_log bytes under the flood (bound 2 MB)"
    echo "ok: $(cat "$work/logs/flood-hellos.txt") and $(cat "$work/logs/flood-requests.txt"); completed in" \
      "$(field steps "$s") steps ($(field wall_seconds "$s") s, unflooded $(field wall_seconds "$reference") s) on" \
      "the unflooded terrain; world peak RSS $peak kB; events.log $events B, world log $world_log B;" \
      "surplus $(field surplus_requests "$s"), unattributed $(field unattributed_rejections "$s"), honest agents 0"
    ;;
  auto-ids)
    # --id auto: three agents without ids take slots 1..3 in arrival order and end on the fixed-id run's terrain.
    reference=$(run_spawn reference 3 cyclone)
    agent_ids=auto start_run "$work/auto"
    wait "$world" || { tail -30 "$out/logs/world.log"; fail "world exited non-zero"; }
    for pid in "${pids[@]}"; do wait "$pid" || fail "an auto agent exited non-zero (see $out/logs)"; done
    expect_completed "$out/summary.json" 3
    slots=$(grep -ho "assigned slot [0-9]*" "$out"/logs/agent-*.log | awk '{ print $3 }' | sort | tr '\n' ' ')
    [ "$slots" = "1 2 3 " ] || fail "the auto agents got slots '$slots', not 1 2 3"
    [ "$(field terrain_sha256 "$out/summary.json")" = "$(field terrain_sha256 "$reference")" ] ||
      fail "auto ids ended on $(field terrain_sha256 "$out/summary.json"), fixed ids on $(field terrain_sha256 "$reference")"
    echo "ok: three --id auto agents took slots $slots and ended on the fixed-id terrain"
    ;;
  world-kill)
    # The world dies and never comes back: every agent waits for it --world-timeout (5 s here, 600 s by default;
    # docs/runtime.md#silence), then exits 1 saying so.
    agent_args=(--world-timeout 5)
    start_run "$work/world-kill"
    for _ in $(seq 1 3000); do grep -q '"agent":1,"kind":"deposited"' "$out/events.log" 2>/dev/null && break; sleep 0.02; done
    grep -q '"agent":1,"kind":"deposited"' "$out/events.log" || fail "agent 1 never deposited (see $out/logs)"
    kill -KILL "$world"
    killed=$SECONDS
    for id in 1 2 3; do
      rc=0
      wait "${pids[$((id - 1))]}" || rc=$?
      [ "$rc" -eq 1 ] || fail "agent $id exited $rc after the world died (expected 1)"
      grep -q "no sensor frame for 5 s" "$out/logs/agent-$id.log" || { cat "$out/logs/agent-$id.log"; fail "agent $id did not name its world timeout"; }
    done
    took=$((SECONDS - killed))
    [ "$took" -ge 4 ] && [ "$took" -le 15 ] || fail "the agents took $took s to give up on the dead world (5 s timeout)"
    echo "ok: world killed; all three agents waited their 5 s world timeout and exited within $took s saying so"
    ;;
  monitor)
    export CYCLONEDDS_URI="file://$root/deploy/dds/cyclone-lo.xml"
    "$bin/marsala-monitor" tail --dds cyclone --domain "$domain" --events --timeout 120 >"$work/tail.txt" 2>&1 &
    monitor=$!
    s=$(run_spawn run 3 cyclone)
    wait "$monitor" || { cat "$work/tail.txt"; fail "monitor tail exited non-zero"; }
    expect_completed "$s" 3
    grep -q "completed at step $(field steps "$s")" "$work/tail.txt" || { cat "$work/tail.txt"; fail "no final line"; }
    lines=$(wc -l <"$work/tail.txt")
    [ "$lines" -ge 10 ] || { cat "$work/tail.txt"; fail "tail printed only $lines lines"; }
    # Honest outcomes: three slots, agent 3 never started. The run completes short of it: exit 7, and summary.json
    # and the monitor's last line say which slot is missing (docs/runtime.md#exit-codes).
    "$bin/marsala-monitor" tail --dds cyclone --domain "$domain" --timeout 120 >"$work/short-tail.txt" 2>&1 &
    monitor=$!
    world_only=1 start_run "$work/short" --admit-timeout 3
    pids=()
    for id in 1 2; do
      "$bin/marsala-agent" --scenario "$scenario" --id "$id" --dds cyclone --domain "$domain" >"$logs/agent-$id.log" 2>&1 &
      pids+=($!)
    done
    rc=0
    wait "$world" || rc=$?
    [ "$rc" -eq 7 ] || { tail -20 "$logs/world.log"; fail "a run without agent 3 exited $rc, expected 7"; }
    for p in "${pids[@]}"; do wait "$p" || fail "an agent exited non-zero (see $logs)"; done
    wait "$monitor" || { cat "$work/short-tail.txt"; fail "monitor tail of the short run exited non-zero"; }
    s="$out/summary.json"
    [ "$(field completed "$s")" = true ] && [ "$(field slots_missing "$s")" = 1 ] && [ "$(field admitted "$s")" = 2 ] &&
      tr -d '\n ' <"$s" | grep -q '"missing_agents":\[3\]' || { cat "$s"; fail "summary.json does not say slot 3 is missing"; }
    grep -q "(1 of 3 slots missing at the end)" "$logs/world.log" || { tail -3 "$logs/world.log"; fail "the world's last line does not say it"; }
    grep -q "completed at step .* | live 2/3, .* | missing 1 of 3 slots: 3 never admitted |" "$work/short-tail.txt" ||
      { cat "$work/short-tail.txt"; fail "the monitor's last line does not name the missing slot"; }
    # The world killed mid-run: tail ends with a line and exit 3 once no world status writer has been alive for
    # --gone-after, instead of waiting for ever.
    timeout 60 "$bin/marsala-monitor" tail --dds cyclone --domain "$domain" --gone-after 2 >"$work/gone-tail.txt" 2>&1 &
    monitor=$!
    start_run "$work/gone"
    for _ in $(seq 1 3000); do grep -q '"kind":"deposited"' "$out/events.log" 2>/dev/null && break; sleep 0.02; done
    kill -KILL "$world"
    killed=$SECONDS
    for p in "${pids[@]}"; do kill -TERM "$p" 2>/dev/null || true; wait "$p" 2>/dev/null || true; done
    rc=0
    wait "$monitor" || rc=$?
    [ "$rc" -eq 3 ] || { cat "$work/gone-tail.txt"; fail "tail exited $rc after the world died, expected 3"; }
    grep -q "^world gone: no live world status writer for 2 s (last: step [0-9]* of run" "$work/gone-tail.txt" ||
      { cat "$work/gone-tail.txt"; fail "tail did not end with the world-gone line"; }
    echo "ok: monitor followed the run ($lines lines) and saw it complete; a run short of slot 3 exited 7 saying so;" \
      "tail ended $((SECONDS - killed)) s after the world was killed, exit 3"
    ;;
  impostor)
    # Issue 30's attack table on an unsecured run (docs/runtime.md#who-wrote-it): a Fast DDS participant speaks in the
    # name of a Cyclone world. It answers every hello first with a refusal and an acceptance of its own; it writes to
    # every admitted agent a "run over" frame, a frame for step 2^62 and a malformed one, and a "run over" frame again
    # when the agent says hello during a 4 s pause of the world; it publishes "completed at step 999999" with the
    # world's proof copied, with its own key and with none. Agents and monitors given the run key believe none of it:
    # the run ends on the terrain of an unperturbed run (marsala-lockstep-sim, the same steps in-process).
    export CYCLONEDDS_URI="file://$root/deploy/dds/cyclone-lo.xml"
    (umask 077; od -An -tx1 -N32 /dev/urandom | tr -d ' \n' >"$work/run.key")
    export MARSALA_RUN_KEY="$work/run.key"  # marsala-monitor: the run's key
    # The unperturbed terrain, in-process, meanwhile (the world is stopped 6 s of the run).
    "$bin/marsala-lockstep-sim" --scenario "$scenario" --agents 3 --seeds 1 --csv "$work/sim.csv" >/dev/null 2>&1 &
    sim=$!
    "$bin/marsala-monitor" tail --dds cyclone --domain "$domain" --events --timeout 120 >"$work/tail.txt" 2>&1 &
    monitor=$!
    "$bin/marsala-impostor" fastdds "$domain" 3 120 >"$work/impostor.log" 2>&1 &
    impostor=$!
    world_only=1 start_run "$work/run" --run-key "$work/run.key"
    for _ in $(seq 1 600); do grep -q "impostor ready" "$work/impostor.log" && break; sleep 0.05; done
    grep -q "impostor ready" "$work/impostor.log" || { cat "$work/impostor.log"; fail "the impostor never heard the world"; }
    sleep 1.5  # the impostor matched the world's writer; give the world time to match the impostor's reader too
    # The agents come while the world is stopped: for 2 s only the impostor answers them.
    kill -STOP "$world"
    agent_args=(--run-key "$work/run.key")
    start_agents
    sleep 2
    kill -CONT "$world"
    # Mid-run (agent 2 has deposited), the world stops for 4 s: the agents say hello again, the impostor answers.
    for _ in $(seq 1 3000); do grep -q '"agent":2,"kind":"deposited"' "$out/events.log" 2>/dev/null && break; sleep 0.02; done
    kill -STOP "$world"; sleep 4; kill -CONT "$world"
    "$bin/marsala-monitor" status --dds cyclone --domain "$domain" --timeout 5 --listen 2 >"$work/status.txt" 2>&1 ||
      { cat "$work/status.txt"; fail "marsala-monitor status failed during the run"; }
    wait "$world" || { tail -30 "$logs/world.log"; fail "world exited non-zero"; }
    for p in "${pids[@]}"; do wait "$p" || fail "an agent exited non-zero (see $logs)"; done
    wait "$impostor" || { cat "$work/impostor.log"; fail "the impostor did not forge for 3 agents"; }
    wait "$monitor" || { cat "$work/tail.txt"; fail "monitor tail exited non-zero"; }
    s="$out/summary.json"
    expect_completed "$s" 3
    steps=$(field steps "$s")
    wait "$sim" || fail "marsala-lockstep-sim failed"
    want=$(csv_last "$work/sim.csv" terrain_sha256)
    [ "$(field terrain_sha256 "$s")" = "$want" ] || fail "terrain $(field terrain_sha256 "$s") is not the unperturbed $want"
    grep -q "forged [1-9][0-9]* admissions" "$work/impostor.log" || { cat "$work/impostor.log"; fail "no admission forged"; }
    grep -q "([1-9][0-9]* run-over frames)" "$work/impostor.log" || { cat "$work/impostor.log"; fail "no frame forged"; }
    for id in 1 2 3; do
      grep -q "run over at step $steps (.*, [1-9][0-9]* frames ignored, [1-9][0-9]* admissions ignored;" \
        "$logs/agent-$id.log" || { tail -5 "$logs/agent-$id.log"; fail "agent $id did not ignore the forgeries"; }
      grep -q "ignoring an admission (refused) from participant" "$logs/agent-$id.log" ||
        { head -5 "$logs/agent-$id.log"; fail "agent $id heard no forged refusal before the world answered"; }
      grep -q "the world of run .* answers from participant" "$logs/agent-$id.log" &&
        fail "agent $id took the impostor for its world"
    done
    grep -q "completed at step $steps" "$work/tail.txt" || { cat "$work/tail.txt"; fail "no true final line"; }
    ! grep -q "999999" "$work/tail.txt" "$work/status.txt" || { cat "$work/tail.txt" "$work/status.txt"; fail "a monitor believed the forged status"; }
    grep -q "ignoring statuses from participant .*: another world/publisher" "$work/tail.txt" ||
      fail "the monitor did not say what it ignored"
    # The impostor forges a status every 0.5 s: within status's 2 s of listening it is named, and not believed.
    grep -q "ignoring statuses from participant .*: another world/publisher" "$work/status.txt" ||
      { cat "$work/status.txt"; fail "marsala-monitor status did not name the other publisher"; }
    echo "ok: forged admissions, frames, statuses and events ignored through a 4 s pause; the run completed at" \
      "step $steps on the unperturbed terrain $want"
    ;;
  fork)
    # docs/runtime.md#fork. The parent stops at max_steps 160 (exit 3) to keep the case short.
    forked() {  # forked NAME ARGS...: spawn.sh --fork of the parent into $work/NAME; prints its exit code
      local rc=0
      "$root/deploy/spawn.sh" --fork "$work/parent" --domain "$domain" --out "$work/$1" --quiet --timeout 120 \
        "${@:2}" >"$work/$1.out" 2>&1 || rc=$?
      echo "$rc"
    }
    rc=0
    "$root/deploy/spawn.sh" --scenario "$scenario" --agents 3 --domain "$domain" --out "$work/parent" --max-steps 160 \
      --quiet --timeout 120 || rc=$?
    [ "$rc" -eq 3 ] || fail "the parent exited $rc, not 3 (max_steps)"
    parent_sha=$(field terrain_sha256 "$work/parent/summary.json")
    at_k=$("$bin/marsala-world" --check --fork "$work/parent" --at 100 | sed 's/.* //')
    [ "$("$bin/marsala-monitor" replay "$work/parent" --to-step 100 | tail -1)" = "terrain_sha256 $at_k" ] ||
      fail "the world's digest of the parent at step 100 ($at_k) is not the monitor's replay's"
    [ "$(forked same --at 100)" = 3 ] || { cat "$work/same.out"; fail "the unchanged fork did not end at max_steps"; }
    [ "$(field terrain_sha256 "$work/same/summary.json")" = "$parent_sha" ] ||
      fail "the unchanged fork ended on $(field terrain_sha256 "$work/same/summary.json"), the parent on $parent_sha"
    [ "$(field at_step "$work/same/summary.json")" = 100 ] || fail "summary.json does not say the fork's K"
    [ "$(field parent_sha256_at_step "$work/same/summary.json")" = "$at_k" ] || fail "summary.json's parent digest"
    # A world-only --set (a goal reached at about step 127, as fresh runs with it find): the fork ends where the
    # parent stood at that step, since no request changes; with 2 agents it completes too, exit 0 (slot 3 left by
    # choice, not missing).
    goal=(--set goal.x0_m=0 --set goal.target_radius_m=30 --set goal.min_height_m=0.2)
    [ "$(forked goal --at 100 "${goal[@]}")" = 0 ] || { cat "$work/goal.out"; fail "the fork with a goal did not complete"; }
    goal_steps=$(field steps "$work/goal/summary.json")
    [ "$goal_steps" -gt 100 ] && [ "$goal_steps" -lt 160 ] || fail "the fork with a goal ended after $goal_steps steps"
    [ "$("$bin/marsala-monitor" replay "$work/parent" --to-step "$goal_steps" | tail -1)" = \
      "terrain_sha256 $(field terrain_sha256 "$work/goal/summary.json")" ] ||
      fail "the fork with a goal ended after $goal_steps steps on another terrain than the parent's there"
    tr -d '\n ' <"$work/goal/summary.json" | grep -q '"overrides":\["goal.x0_m=0","goal.target_radius_m=30","goal.min_height_m=0.2"\]' ||
      fail "summary.json does not list the fork's --set"
    [ "$(forked fewer --at 100 --agents 2 "${goal[@]}")" = 0 ] || { cat "$work/fewer.out"; fail "the fork with 2 agents failed"; }
    [ "$(field slots_missing "$work/fewer/summary.json")" = 0 ] && tr -d '\n ' <"$work/fewer/summary.json" |
      grep -q '"left_agents":\[3\]' || fail "summary.json does not say slot 3 left at K"
    fewer_sha=$(field terrain_sha256 "$work/fewer/summary.json")
    [ "$fewer_sha" != "$parent_sha" ] || fail "the fork with 2 agents did not diverge from its parent"
    # The fork's own run.log, replayed to K by the monitor, has the parent's terrain there; then agent 3 leaves.
    fewer_k=$("$bin/marsala-monitor" replay "$work/fewer" --to-step 100 | tail -1 | sed 's/.* //')
    [ "$fewer_k" = "$at_k" ] || fail "the fork with 2 agents had $fewer_k at step 100, the parent $at_k"
    grep -q '"step":100,"agent":3,"kind":"dropped","detail":"not in the fork' "$work/fewer/events.log" ||
      fail "agent 3 did not leave the fork at step 100"
    "$bin/marsala-monitor" replay "$work/fewer" | tail -1 | grep -q "terrain_sha256 $fewer_sha" ||
      fail "a replay of the fork's run.log does not end on its terrain"
    # Agents of another construction slope make other requests: the fork stops at the first, exit 8 naming it.
    sed 's/^  }$/  }\n  construction { kappa: 0.25 }/' "$scenario" >"$work/other.pbtxt"
    [ "$(forked other --at 100 --scenario "$work/other.pbtxt")" = 8 ] || { cat "$work/other.out"; fail "no exit 8"; }
    grep -q "error: fork of .* at step 100: agent [1-3] at step [0-9]*: its request differs" "$work/other.out" ||
      { cat "$work/other.out"; fail "the mismatch was not named"; }
    # Bad input: one line, exit 2, nothing written.
    for bad in "--at 161" "--at -1" "--at 100 --agents 4" "--at 100 --set max_steps=5" "--at 100 --seed 2" \
      "--at 100 --set robot_type.body.kappa=0.2"; do
      # shellcheck disable=SC2086
      [ "$(forked bad $bad)" = 2 ] || { cat "$work/bad.out"; fail "--fork $bad did not exit 2"; }
      [ ! -e "$work/bad" ] || fail "--fork $bad wrote $work/bad"
      [ "$(wc -l <"$work/bad.out")" -le 2 ] || { cat "$work/bad.out"; fail "--fork $bad said more than a line"; }
    done
    # A larger team: a parent of 2, forked at 30 with 3; slot 3 joins at K (admitted then, on its start).
    rc=0
    "$root/deploy/spawn.sh" --scenario "$scenario" --agents 2 --domain "$domain" --out "$work/pair" --max-steps 60 \
      --quiet --timeout 120 || rc=$?
    [ "$rc" -eq 3 ] || fail "the parent of 2 exited $rc, not 3 (max_steps)"
    rc=0
    "$root/deploy/spawn.sh" --fork "$work/pair" --at 30 --agents 3 --domain "$domain" --out "$work/trio" --quiet \
      --timeout 120 >"$work/trio.out" 2>&1 || rc=$?
    [ "$rc" -eq 3 ] || { cat "$work/trio.out"; fail "the fork with a third agent exited $rc, not 3"; }
    grep -q '"step":30,"agent":3,"kind":"admitted"' "$work/trio/events.log" || fail "agent 3 was not admitted at step 30"
    tr -d '\n ' <"$work/trio/summary.json" | grep -q '"joined_agents":\[3\]' || fail "summary.json: no joined_agents"
    [ "$(field slots_missing "$work/trio/summary.json")" = 0 ] || fail "the fork with a third agent misses a slot"
    [ "$("$bin/marsala-monitor" replay "$work/trio" --to-step 30 | tail -1)" = \
      "$("$bin/marsala-monitor" replay "$work/pair" --to-step 30 | tail -1)" ] ||
      fail "the fork with a third agent did not have the parent's terrain at step 30"
    # From its start at x 5.05 m, 30 steps of at most 0.2 m: it drove towards its ramp after joining.
    x3=$(python3 -c 'import json, sys; print(json.load(open(sys.argv[1]))["per_agent"][2]["x_m"])' "$work/trio/summary.json")
    awk -v x="$x3" 'BEGIN { exit !(x > 7.0) }' || fail "agent 3 did not drive after joining (x $x3 m)"
    rc=0
    "$root/deploy/spawn.sh" --fork "$work/none" --at 1 --out "$work/bad" --quiet >/dev/null 2>&1 || rc=$?
    [ "$rc" -eq 2 ] && [ ! -e "$work/bad" ] || fail "a fork of no run exited $rc"
    echo "ok: fork at 100 unchanged ends on the parent's $parent_sha; with a goal it ends after $goal_steps steps as" \
      "the parent stood there; with 2 agents it has the parent's $at_k at step 100 and ends on $fewer_sha, exit 0;" \
      "a third agent joins a fork of 2 at step 30;" \
      "other agents exit 8: $(grep -o 'agent [1-3] at step [0-9]*' "$work/other.out")"
    ;;
  foreign)
    # A foreign type under ActionRequest's name (the 12-byte ScanPoint layout, marsala-foreign-type) flooding every
    # agent's partition for 5 s of a Fast DDS run (world and agents): the world's readers drop it unread with bounded log
    # (docs/runtime.md#foreign-types), no agent is dropped, and the run ends on the terrain of the unflooded run
    # (marsala-lockstep-sim, the same steps in-process).
    "$bin/marsala-lockstep-sim" --scenario "$scenario" --agents 3 --seeds 1 --csv "$work/sim.csv" >/dev/null 2>&1 &
    sim=$!
    "$bin/marsala-foreign-type" "$domain" ActionRequest "ramp-d$domain/agent-*" 5 >"$work/foreign.txt" 2>&1 &
    foreign=$!
    s=$(run_spawn run 3 fastdds)
    wait "$foreign" || fail "the foreign writer failed: $(cat "$work/foreign.txt")"
    grep -q "^wrote [1-9][0-9]* samples of a foreign marsala::wire::ActionRequest" "$work/foreign.txt" ||
      fail "no foreign sample written: $(cat "$work/foreign.txt")"
    expect_completed "$s" 3
    wait "$sim" || fail "marsala-lockstep-sim failed"
    want=$(csv_last "$work/sim.csv" terrain_sha256)
    [ "$(field terrain_sha256 "$s")" = "$want" ] || fail "terrain $(field terrain_sha256 "$s") is not the unflooded $want"
    ! grep -q '"kind":"dropped"' "$work/run/events.log" || fail "the foreign flood dropped an agent"
    said=$(grep -c "does not decode" "$work/run/logs/world.log" || true)
    lines=$(wc -l <"$work/run/logs/world.log")
    [ "$said" -ge 1 ] || fail "the world's log does not say it dropped foreign samples"
    [ "$lines" -le 200 ] || fail "the world's log grew to $lines lines under the foreign flood"
    echo "ok: $(grep -o '^wrote [0-9]*' "$work/foreign.txt" | cut -d' ' -f2) foreign ActionRequest samples in 5 s: the run completed" \
      "on the unflooded terrain ${want:0:8}, nobody dropped, $said 'does not decode' lines in a world log of $lines"
    ;;
  *) echo "unknown case '$case_name'" >&2; exit 2 ;;
esac
