#!/usr/bin/env bash
# A run's progress as people see it, on real processes over DDS (inside run_isolated.sh):
#   path: path_generated with 5 agents. spawn.sh on a terminal (a pseudo-terminal made by script(1)) keeps one line
#         up to date with \r (step, progress, steps/s, ETA) and ends with the account of the run; beside it
#         `marsala-monitor progress --lines` sees the progress rise steadily (never down, through the middle values,
#         not 0 then 100 %) to 100 % at the last step, and `tail --every 100` prints a step line per 100 steps.
#   pipe: a ramp run whose output is a file: no \r, no progress line, the account at the end; --quiet: nothing.
# Usage: progress_test.sh CASE DOMAIN
set -euo pipefail
case_name="$1"
domain="$2"
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
# shellcheck source=lib.sh
. "$here/lib.sh"
test_workspace progress

case "$case_name" in
  path)
    command -v script >/dev/null || { echo "SKIP: no script(1) to make a terminal"; exit 77; }
    "$bin/marsala-monitor" progress --lines --interval 0.02 --dds cyclone --domain "$domain" --timeout 120 \
      >"$work/progress.txt" 2>&1 &
    progress=$!
    "$bin/marsala-monitor" tail --every 100 --dds cyclone --domain "$domain" --timeout 120 >"$work/tail.txt" 2>&1 &
    tail_pid=$!
    # script(1) gives spawn.sh a terminal for stdout; what it printed lands in the typescript file.
    SHELL=/bin/sh script -qefc "'$root/deploy/spawn.sh' --scenario '$root/deploy/scenarios/path_generated.pbtxt' \
      --agents 5 --dds cyclone --domain $domain --out '$work/run' --timeout 300" "$work/tty.txt" >/dev/null 2>&1 ||
      { cat "$work/tty.txt"; fail "spawn.sh failed (logs: $work/run/logs)"; }
    wait "$progress" || { cat "$work/progress.txt"; fail "marsala-monitor progress exited non-zero"; }
    wait "$tail_pid" || { cat "$work/tail.txt"; fail "marsala-monitor tail exited non-zero"; }
    s="$work/run/summary.json"
    [ "$(field completed "$s")" = true ] || fail "the run did not complete"
    steps=$(field steps "$s")
    [ "$(field progress "$s")" = 1 ] || fail "summary.json progress $(field progress "$s"), expected 1"

    # The terminal: updates in place, each with the step rate and an ETA, then the account.
    updates=$(tr '\r' '\n' <"$work/tty.txt" | grep -cE '^step [0-9]+ \| [0-9.]+ % \| [0-9]+ steps/s \| ETA ') || true
    [ "$updates" -ge 5 ] || { cat -v "$work/tty.txt"; fail "only $updates progress updates on the terminal"; }
    grep -q "completed at step $steps in [0-9.]* s | 100.0 %" "$work/tty.txt" || fail "no final progress line"
    grep -q "^path_generated completed after $steps steps in " "$work/tty.txt" || fail "no account of the run"
    grep -q "pictures in $work/run: final.png" "$work/tty.txt" || fail "the account does not say where the pictures are"
    ! grep -q '"terrain_sha256"' "$work/tty.txt" || fail "spawn.sh still prints summary.json"

    # The progress, from its own lines: never down, through the middle, 100 % at the end.
    awk -v steps="$steps" '
      /^step [0-9]+ \| / { p = $4 + 0; n++
        if (p < last - 1e-9) { print "progress fell from " last " to " p " at step " $2; bad = 1 }
        if (p > 20 && p < 80) middle++
        last = p }
      /^completed at step / { done = ($4 == steps && $9 == "100.0") }
      END { if (bad) exit 1
            if (n < 20) { print "only " n " progress lines"; exit 1 }
            if (middle < 5) { print "only " middle " lines between 20 and 80 %: not a steady rise"; exit 1 }
            if (!done) { print "no 100 % at step " steps; exit 1 } }' "$work/progress.txt" ||
      { head -50 "$work/progress.txt"; fail "the progress did not rise steadily to 100 %"; }
    mid=$(awk '/^step [0-9]+ \| / && $4 + 0 > 40 && $4 + 0 < 60 { print; exit }' "$work/progress.txt")
    echo "ok: e.g. '$mid'"

    # tail --every 100: one step line per hundred steps (the first seen, then each multiple), the last one.
    awk -v steps="$steps" '
      $1 ~ /^[0-9]+$/ && $3 ~ /[0-9.]+/ && $0 ~ / \| / { n++; step = $1 + 0
        if (n > 1 && step != steps && step % 100 > 20) { print "line at step " step; bad = 1 } }
      END { if (bad || n < steps / 100 - 2 || n > steps / 100 + 3) { print n " step lines"; exit 1 } }' \
      "$work/tail.txt" || { cat "$work/tail.txt"; fail "tail --every 100 printed the wrong lines"; }
    echo "ok: progress line on a terminal, a steady rise to 100 % at step $steps, tail --every 100"
    ;;
  pipe)
    "$root/deploy/spawn.sh" --scenario "$root/deploy/scenarios/ramp.pbtxt" --agents 3 --dds cyclone \
      --domain "$domain" --out "$work/run" --timeout 300 >"$work/out.txt" 2>&1 || { cat "$work/out.txt"; fail "spawn.sh"; }
    ! grep -q $'\r' "$work/out.txt" || fail "carriage returns in a file"
    ! grep -q "steps/s" "$work/out.txt" || fail "a progress line in a file"
    grep -q "^ramp completed after [0-9]* steps in " "$work/out.txt" || { cat "$work/out.txt"; fail "no account"; }
    "$root/deploy/spawn.sh" --scenario "$root/deploy/scenarios/ramp.pbtxt" --agents 3 --dds cyclone \
      --domain "$domain" --out "$work/run" --replace --quiet --timeout 300 >"$work/quiet.txt" ||
      fail "spawn.sh --quiet"
    [ ! -s "$work/quiet.txt" ] || { cat "$work/quiet.txt"; fail "spawn.sh --quiet printed something"; }
    echo "ok: nothing but the account in a file, nothing at all with --quiet"
    ;;
  *) echo "unknown case '$case_name'" >&2; exit 2 ;;
esac
