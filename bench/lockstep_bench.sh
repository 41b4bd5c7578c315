#!/usr/bin/env bash
# Lockstep benchmark: the wall time of one world step with 1, 4 and 12 (--teams: up to 120) idle agent processes
# (behaviour "idle": an empty request, which stands), beside the raw DDS round trip measured in the same run, as a
# ratio. Each team runs twice: with standing answers (the world writes an idle robot no frame while nothing around it
# changes: docs/runtime.md#standing-answers) and with a frame and a request every step (standing_answers: false: the
# lockstep's round trip). Reports the world's per-step median and 90th percentile (summary.json) over --steps steps.
# Usage: bench/lockstep_bench.sh [--dds cyclone|fastdds] [--steps N] [--teams "1 4 12"] [--dds-config FILE]
#   --dds-config  a profile of the vendor for every process (default deploy/dds/<vendor>-lo.xml), e.g.
#                 deploy/dds/fastdds-crowd.xml for Fast DDS with many agents
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${MARSALA_BUILD_DIR:-$root/build}"
dds=cyclone steps=2000 teams="1 4 12" profile=""
while [ $# -gt 0 ]; do
  case "$1" in
    --dds) dds="$2"; shift 2 ;;
    --steps) steps="$2"; shift 2 ;;
    --teams) teams="$2"; shift 2 ;;
    --dds-config) profile="$2"; shift 2 ;;
    -h|--help) sed -n '2,9p' "$0"; exit 0 ;;
    *) echo "lockstep_bench.sh: unknown argument '$1'" >&2; exit 2 ;;
  esac
done
[ -x "$build/bin/marsala-world" ] || "$root/deploy/build.sh" >/dev/null
work="$(mktemp -d "${TMPDIR:-/tmp}/marsala-lockstep.XXXXXX")"
trap 'rm -rf "$work"' EXIT

# A flat 20 x 20 m site with as many idle robots as the largest team, in rows of 12 (1 m apart, rows 1.5 m apart);
# the goal is out of everyone's way, so the run lasts --steps.
slots=12
for n in $teams; do
  [[ "$n" =~ ^[0-9]+$ ]] && [ "$n" -ge 1 ] && [ "$n" -le 120 ] ||
    { echo "lockstep_bench.sh: --teams takes team sizes from 1 to 120, not '$n'" >&2; exit 2; }
  [ "$n" -gt "$slots" ] && slots=$n
done
scenario="$work/idle.pbtxt"
{
  echo 'name: "idle" description: "lockstep benchmark: idle robots on flat ground"'
  echo 'terrain { generator: "flat" rows: 200 cols: 200 cell_size_m: 0.1 seed: 1 }'
  echo 'robot_type { name: "idler" behaviour: "idle" body { kappa: 0.3 delta_m: 1.0 eps_m: 0.05 max_step_m: 0.2'
  echo '  max_deposit_m3: 0.02 material_capacity_m3: 1.0 reach_m: 1.5 sensing_range_m: 4.0 proximity_range_m: 3.0'
  echo '  cube_size_m: 0.05 } }'
  for id in $(seq 1 "$slots"); do
    x=$(((id - 1) % 12 + 3)).05
    y=$(awk -v r=$(((id - 1) / 12)) 'BEGIN { printf "%.2f", 5.05 + 1.5 * r }')
    echo "agent { id: $id robot_type: \"idler\" start { x_m: $x y_m: $y } target { x_m: 10.05 y_m: 15.05 } }"
  done
  echo 'goal { x0_m: 18 y0_m: 18 x1_m: 19 y1_m: 19 min_height_m: 0 }'
  echo "base { x_m: 3.05 y_m: 3.05 radius_m: 1.0 } max_steps: $steps step_deadline_s: 10 tile_size: 16 seed: 1"
} >"$scenario"
every="$work/idle-every.pbtxt"  # the same robots answering a frame every step
{ cat "$scenario"; echo 'standing_answers: false'; } >"$every"

export CYCLONEDDS_URI="file://$root/deploy/dds/cyclone-lo.xml"
export FASTRTPS_DEFAULT_PROFILES_FILE="$root/deploy/dds/fastdds-lo.xml"
if [ -n "$profile" ]; then
  [ -f "$profile" ] || { echo "lockstep_bench.sh: --dds-config: no file '$profile'" >&2; exit 2; }
  profile="$(cd "$(dirname "$profile")" && pwd)/$(basename "$profile")"
  if [ "$dds" = cyclone ]; then export CYCLONEDDS_URI="file://$profile"; else export FASTRTPS_DEFAULT_PROFILES_FILE="$profile"; fi
  export MARSALA_DDS_CONFIG="$profile"  # the world's and agents' (spawn.sh sets the vendors' variables to its own)
fi
field() { grep -o "\"$1\": *[^,}]*" "$2" | head -1 | sed 's/^[^:]*: *//; s/"//g'; }

raw_us=$("$build/bench/bus_pingpong_bench" --benchmark_filter="BM_BusPingPong/$dds/" --benchmark_repetitions=3 \
  --benchmark_report_aggregates_only=true 2>/dev/null | grep median | grep -o 'p50_us=[0-9.]*' | head -1 | cut -d= -f2)
echo "raw DDS round trip ($dds, median of p50): ${raw_us} us"
printf '%-7s %-18s %-18s %-10s %s\n' agents "standing med/p90" "every frame m/p90" ratio "idle agent RSS (MB)"
# One run of `$2` with $1 agents: sets median, p90 [ms] and rss (the largest agent resident set seen) [kB].
run_team() {
  local n=$1 file=$2 out="$work/run-$1-$(basename "$2" .pbtxt)" spawn rc=0 now
  "$root/deploy/spawn.sh" --scenario "$file" --agents "$n" --dds "$dds" --out "$out" --quiet --timeout 600 &
  spawn=$!
  rss=0
  while kill -0 "$spawn" 2>/dev/null; do
    now=$( (ps -C marsala-agent -o rss= || true) | sort -n | tail -1)
    [ -n "$now" ] && [ "$now" -gt "$rss" ] && rss=$now
    sleep 0.05
  done
  wait "$spawn" || rc=$?
  # spawn.sh passes the world's exit code on: 0 completed, 3 max_steps (the idle scenario's end) both measured a run.
  [ "$rc" -eq 0 ] || [ "$rc" -eq 3 ] ||
    { echo "lockstep_bench.sh: the run with $n agents failed (exit $rc); world log:" >&2; tail -5 "$out/logs/world.log" >&2; exit 1; }
  median=$(field step_wall_median_ms "$out/summary.json")
  p90=$(field step_wall_p90_ms "$out/summary.json")
}
for n in $teams; do
  run_team "$n" "$scenario"
  standing=$(printf '%.3f / %.3f' "$median" "$p90")
  run_team "$n" "$every"
  ratio=$(awk -v m="$median" -v r="$raw_us" 'BEGIN { if (r > 0) printf "%.1f", m * 1000 / r; else print "-" }')
  printf '%-7s %-18s %-18s %-10s %s\n' "$n" "$standing" "$(printf '%.3f / %.3f' "$median" "$p90")" "$ratio" \
    "$(awk -v k="${rss:-0}" 'BEGIN{printf "%.1f", k/1024}')"
done
