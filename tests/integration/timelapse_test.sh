#!/usr/bin/env bash
# The world's time-lapse (marsala-world --frames-every K, through spawn.sh), inside run_isolated.sh:
#   world: a ramp run with 3 agents and K = 100: OUT/frames holds frame_<step>.png for exactly the steps 0, K, 2K, ...
#          up to the last and the last step itself, each a PNG, the first and last different; with ffmpeg on PATH
#          OUT/frames/timelapse.mp4 has as many frames (ffprobe), without it the world's log says it was skipped.
#   usage: a K that is 0, negative, not a number or missing exits 2 with a message naming --frames-every, before
#          anything starts (marsala-world and spawn.sh alike).
# Usage: timelapse_test.sh CASE DOMAIN
set -euo pipefail
case_name="$1"
domain="$2"
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
# shellcheck source=lib.sh
. "$here/lib.sh"
test_workspace timelapse

case "$case_name" in
  world)
    every=100
    "$root/deploy/spawn.sh" --scenario "$root/deploy/scenarios/ramp.pbtxt" --agents 3 --dds cyclone \
      --domain "$domain" --out "$work/run" --timeout 300 --frames-every "$every" >"$work/spawn.txt" ||
      { tail -20 "$work/run/logs/world.log"; fail "spawn.sh --frames-every $every"; }
    steps=$(field steps "$work/run/summary.json")
    [ "$steps" -gt $((2 * every)) ] || fail "a run of $steps steps is too short to test frames every $every"
    expected=$( { seq 0 "$every" "$steps"; echo "$steps"; } | sort -un | awk '{ printf "frame_%06d.png\n", $1 }')
    actual=$(cd "$work/run/frames" && ls frame_*.png | sort)
    [ "$actual" = "$expected" ] ||
      fail "frames $(echo "$actual" | tr '\n' ' ') for $steps steps; expected $(echo "$expected" | tr '\n' ' ')"
    count=$(echo "$actual" | wc -l)
    [ "$count" -eq $((steps / every + (steps % every != 0 ? 2 : 1))) ] || fail "$count frames for $steps steps"
    for f in $actual; do is_png "$work/run/frames/$f" || fail "$f is not a PNG"; done
    first=$(echo "$actual" | head -1) last=$(echo "$actual" | tail -1)
    ! cmp -s "$work/run/frames/$first" "$work/run/frames/$last" || fail "the first and last frames are the same picture"
    ! ls "$work/run/frames" | grep -q '\.tmp$' || fail "temporary files left in frames/"
    if command -v ffmpeg >/dev/null; then
      [ -s "$work/run/frames/timelapse.mp4" ] || fail "ffmpeg is installed but no timelapse.mp4"
      if command -v ffprobe >/dev/null; then
        video=$(ffprobe -v error -select_streams v:0 -count_frames -show_entries stream=nb_read_frames -of csv=p=0 \
          "$work/run/frames/timelapse.mp4")
        [ "$video" -eq "$count" ] || fail "timelapse.mp4 has $video frames, the folder $count"
      fi
      grep -q "time-lapse: $count frames in .*timelapse.mp4" "$work/run/logs/world.log" || fail "the world's log does not say"
    else
      grep -q "skipped timelapse.mp4: ffmpeg is not installed" "$work/run/logs/world.log" ||
        fail "no ffmpeg, and the world's log does not say the video was skipped"
    fi
    echo "ok: $count frames for $steps steps every $every ($(echo "$actual" | tr '\n' ' '))," \
      "$(ls "$work/run/frames" | grep -c mp4) timelapse.mp4"
    ;;
  usage)
    for k in 0 -3 abc 2.5 ""; do
      rc=0
      "$bin/marsala-world" --scenario "$root/deploy/scenarios/ramp.pbtxt" --agents 1 --domain "$domain" \
        --out "$work/run" --frames-every "$k" >"$work/out.txt" 2>"$work/err.txt" || rc=$?
      [ "$rc" -eq 2 ] || fail "marsala-world --frames-every '$k' exited $rc, not 2"
      grep -q -- "--frames-every" "$work/err.txt" || fail "the message for K '$k' does not name --frames-every: $(cat "$work/err.txt")"
      [ ! -e "$work/run" ] || fail "marsala-world --frames-every '$k' started a run"
      echo "ok: K '$k': $(head -1 "$work/err.txt")"
    done
    rc=0
    "$root/deploy/spawn.sh" --scenario "$root/deploy/scenarios/ramp.pbtxt" --agents 1 --domain "$domain" \
      --out "$work/spawned" --frames-every 0 >/dev/null 2>"$work/err.txt" || rc=$?
    [ "$rc" -eq 2 ] || fail "spawn.sh --frames-every 0 exited $rc, not 2"
    grep -q -- "--frames-every" "$work/err.txt" || fail "spawn.sh did not say what was wrong: $(cat "$work/err.txt")"
    echo "ok: spawn.sh --frames-every 0 exits 2 before starting anything"
    ;;
  *) echo "unknown case '$case_name'" >&2; exit 2 ;;
esac
