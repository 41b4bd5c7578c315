#!/usr/bin/env bash
# Resume benchmark: a 3-agent ramp run, the world SIGKILLed once it has logged step 120, `marsala-world --resume` started at once;
# reports how long from the kill until the resumed world has logged 3 more steps, the state rebuild time the world
# logs, the world's peak RSS before the kill and after the resume, and that the run ends on its usual digest.
# Run inside a private network namespace: unshare -n sh -c 'ip link set lo up; bench/resume_bench.sh [RUNS]'
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bin="${MARSALA_BUILD_DIR:-$root/build}/bin"
runs="${1:-3}"
scenario="$root/deploy/scenarios/ramp.pbtxt"
export CYCLONEDDS_URI="file://$root/deploy/dds/cyclone-lo.xml"
work="$(mktemp -d "${TMPDIR:-/tmp}/marsala-resume.XXXXXX")"
trap 'rm -rf "$work"' EXIT
rss() { awk '/^VmRSS/ { print $2 }' "/proc/$1/status" 2>/dev/null || echo 0; }
last_step() { sed -n 's/^{"step":\([0-9]*\),.*/\1/p' "$1" | awk '{ s = $1 } END { print s + 0 }'; }  # events.log: JSON Lines
for run in $(seq 1 "$runs"); do
  out="$work/run-$run"
  mkdir -p "$out/logs"
  "$bin/marsala-world" --scenario "$scenario" --agents 3 --domain 44 --out "$out" >"$out/logs/world.log" 2>&1 &
  world=$!
  for id in 1 2 3; do "$bin/marsala-agent" --scenario "$scenario" --id "$id" --domain 44 >/dev/null 2>&1 & done
  peak=0
  until [ -f "$out/events.log" ] && [ "$(last_step "$out/events.log")" -ge 120 ]; do
    r=$(rss "$world"); [ "${r:-0}" -gt "$peak" ] && peak=$r; sleep 0.01
  done
  last=$(last_step "$out/events.log")
  kill -KILL "$world"
  killed=$(date +%s%N)
  wait "$world" 2>/dev/null || true
  "$bin/marsala-world" --resume "$out" --domain 44 >"$out/logs/resume.log" 2>&1 &
  world=$!
  until [ "$(last_step "$out/events.log")" -ge $((last + 3)) ]; do sleep 0.005; done
  back_ms=$((($(date +%s%N) - killed) / 1000000))
  peak2=0
  while kill -0 "$world" 2>/dev/null; do r=$(rss "$world"); [ "${r:-0}" -gt "$peak2" ] && peak2=$r; sleep 0.05; done
  wait
  rebuild=$(grep -o "[0-9]* records replayed.* in [0-9.]* s" "$out/logs/resume.log" | head -1)
  sha=$(grep -o '"terrain_sha256": *"[0-9a-f]*"' "$out/summary.json" | cut -d'"' -f4)
  echo "run $run: killed after step $last; 3 more steps logged ${back_ms} ms after the kill; $rebuild;" \
    "world RSS peak ${peak} kB before, ${peak2} kB resumed; terrain_sha256 ${sha:0:8}"
done
