#!/usr/bin/env bash
# Crowd benchmark: deploy/scenarios/crowd_120.pbtxt (levellers on a 16 x 120 m site) with 12, 48 and 120 agent
# processes on each vendor, --steps steps each (default 200), one run after the other. Per run it reports:
#   admit s        from the world's start of admission to its first frame (summary.json admit_seconds)
#   adm/conn/drop  agents admitted, connected at the first frame, and dropped at the end (summary.json)
#   step med/p90   wall time of one lockstep step [ms]
#   world med      the world's own part of a step (frames out, requests checked, step applied, outputs) [ms]
#   world CPU      the world process's CPU time per step, DDS threads included [ms]
#   agents CPU     all agents' CPU time per step, summed (each agent logs its own at the run's end) [ms]
#   decide         median CPU time of one agent's decision (the behaviour alone, no DDS) [ms]
#   RSS/agent      median over the agents of each one's largest resident set during the run [MB]
# Run it inside a private network namespace: unshare -n sh -c 'ip link set lo up; bench/crowd_bench.sh'
# Usage: bench/crowd_bench.sh [--dds "cyclone fastdds"] [--teams "12 48 120"] [--steps N]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${MARSALA_BUILD_DIR:-$root/build}"
vendors="cyclone fastdds" teams="12 48 120" steps=200
while [ $# -gt 0 ]; do
  case "$1" in
    --dds) vendors="$2"; shift 2 ;;
    --teams) teams="$2"; shift 2 ;;
    --steps) steps="$2"; shift 2 ;;
    -h|--help) sed -n '2,15p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "crowd_bench.sh: unknown argument '$1' (try --help)" >&2; exit 2 ;;
  esac
done
[[ "$steps" =~ ^[0-9]+$ ]] && [ "$steps" -ge 1 ] || { echo "crowd_bench.sh: --steps N (N >= 1), got '$steps'" >&2; exit 2; }
[ -x "$build/bin/marsala-world" ] || "$root/deploy/build.sh" >/dev/null
scenario="$root/deploy/scenarios/crowd_120.pbtxt"
work="$(mktemp -d "${TMPDIR:-/tmp}/marsala-crowd.XXXXXX")"
trap 'rm -rf "$work"' EXIT
export MARSALA_BUILD_DIR="$build"
num() { jq -r "$1" "$2"; }

printf '%-8s %6s %7s %-13s %8s %8s %9s %9s %10s %7s %9s\n' vendor agents "admit s" adm/conn/drop "step med" "step p90" \
  "world med" "world CPU" "agents CPU" decide "RSS/agent"
domain=40
for dds in $vendors; do
  for n in $teams; do
    out="$work/$dds-$n"
    domain=$((domain + 1))
    "$root/deploy/spawn.sh" --scenario "$scenario" --agents "$n" --dds "$dds" --domain "$domain" --out "$out" \
      --max-steps "$steps" --quiet --timeout 900 >"$work/spawn-$dds-$n.txt" 2>&1 &
    spawn=$!
    # Each agent's largest resident set while the run lasts [kB], by pid.
    declare -A peak=()
    while kill -0 "$spawn" 2>/dev/null; do
      while read -r pid rss; do
        [ -n "$rss" ] && [ "$rss" -gt "${peak[$pid]:-0}" ] && peak[$pid]=$rss
      done < <(ps -C marsala-agent -o pid=,rss= 2>/dev/null || true)
      sleep 0.5
    done
    rc=0
    wait "$spawn" || rc=$?
    # 3 (max_steps) is the benchmark's own end; 0 if the site happened to be level first.
    if [ "$rc" -ne 0 ] && [ "$rc" -ne 3 ]; then
      echo "crowd_bench.sh: the $dds run with $n agents failed (exit $rc):" >&2
      tail -3 "$work/spawn-$dds-$n.txt" >&2
      tail -3 "$out/logs/world.log" >&2 || true
      exit 1
    fi
    s="$out/summary.json"
    agents_cpu=$(grep -ho 'process CPU [0-9.]* ms per step' "$out"/logs/agent-*.log | awk '{ t += $3 } END { printf "%.1f", t }')
    decide=$(grep -ho 'decision CPU median [0-9.]* ms' "$out"/logs/agent-*.log | awk '{ print $4 }' | sort -n |
      awk '{ v[NR] = $1 } END { printf "%.3f", NR ? v[int((NR + 1) / 2)] : 0 }')
    rss=$(printf '%s\n' "${peak[@]:-0}" | sort -n | awk '{ v[NR] = $1 } END { printf "%.1f", v[int((NR + 1) / 2)] / 1024 }')
    unset peak
    printf '%-8s %6s %7.2f %-13s %8.1f %8.1f %9.2f %9.2f %10s %7s %9s\n' "$dds" "$n" "$(num .admit_seconds "$s")" \
      "$(num .admitted "$s")/$(num .connected "$s")/$(num .dropped "$s")" "$(num .step_wall_median_ms "$s")" \
      "$(num .step_wall_p90_ms "$s")" "$(num .step_world_median_ms "$s")" "$(num .world_cpu_ms_per_step "$s")" \
      "$agents_cpu" "$decide" "$rss"
  done
done
