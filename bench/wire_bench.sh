#!/usr/bin/env bash
# Wire benchmark (issue 30, docs/runtime.md#resends): ramp 3, seed 1, the first --steps steps (default 100) on each
# vendor, over this namespace's loopback with MTU 1500, unthrottled and limited by tc tbf (e.g. 1mbit: rate 1 Mbit/s,
# burst 32 kbit, latency 400 ms), --runs runs each (default 3), one after the other. Per vendor and rate it reports
# medians over the runs:
#   steps        steps reached (all of them unless the run timed out, --timeout S per run, default 150)
#   wall s       the run's wall time, spawn to summary [s]
#   bytes/step   bytes sent on lo (every process, DDS discovery and heartbeats included) per step reached (all of them
#                when no step was)
#   /agent       the same per agent
#   pkts/step    packets sent on lo per step
#   x clean      bytes/step against the same vendor unthrottled
#   tbf drops    packets the tbf qdisc dropped (0 unthrottled)
#   terrain      the terrain_sha256's first 8 hex digits; "same" when it equals the unthrottled run's
# It changes lo's MTU and qdisc, so run it inside a private network namespace:
#   unshare -n bash -c 'ip link set lo up; bench/wire_bench.sh'
# --fastdds-profile FILE: Fast DDS runs use this profile (MARSALA_DDS_CONFIG), e.g. deploy/dds/fastdds-slow.xml, the
# rate-limited one for slow links (docs/runtime.md#slow-links); default: spawn.sh's loopback profile.
# Usage: bench/wire_bench.sh [--dds "cyclone fastdds"] [--rates "none 1mbit"] [--runs N] [--steps N] [--timeout S]
#                            [--fastdds-profile FILE]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${MARSALA_BUILD_DIR:-$root/build}"
vendors="cyclone fastdds" rates="none 1mbit" runs=3 steps=100 timeout=150 fastdds_profile=""
while [ $# -gt 0 ]; do
  case "$1" in
    --dds) vendors="$2"; shift 2 ;;
    --rates) rates="$2"; shift 2 ;;
    --runs) runs="$2"; shift 2 ;;
    --steps) steps="$2"; shift 2 ;;
    --timeout) timeout="$2"; shift 2 ;;
    --fastdds-profile) fastdds_profile="$(realpath "$2")"; shift 2 ;;
    -h|--help) sed -n '2,20p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "wire_bench.sh: unknown argument '$1' (try --help)" >&2; exit 2 ;;
  esac
done
for n in "$runs" "$steps" "$timeout"; do
  [[ "$n" =~ ^[0-9]+$ ]] && [ "$n" -ge 1 ] || { echo "wire_bench.sh: --runs, --steps, --timeout take N >= 1, got '$n'" >&2; exit 2; }
done
[ "${rates%%none*}" = "" ] || { echo "wire_bench.sh: --rates must start with none (the reference), got '$rates'" >&2; exit 2; }
[ -z "$fastdds_profile" ] || [ -r "$fastdds_profile" ] ||
  { echo "wire_bench.sh: --fastdds-profile: '$fastdds_profile' cannot be read" >&2; exit 2; }
ip link set lo mtu 1500 2>/dev/null || { echo "wire_bench.sh: cannot set lo's MTU: run it inside unshare -n" >&2; exit 2; }
[ -x "$build/bin/marsala-world" ] || "$root/deploy/build.sh" >/dev/null
work="$(mktemp -d "${TMPDIR:-/tmp}/marsala-wire.XXXXXX")"
trap 'tc qdisc del dev lo root 2>/dev/null || true; rm -rf "$work"' EXIT
export MARSALA_BUILD_DIR="$build"
lo() { awk -v f="$1" '/^ *lo:/ { print $f }' /proc/net/dev; }  # 10: bytes sent, 11: packets sent
median() { sort -g | awk '{ v[NR] = $1 } END { print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }

printf '%-8s %-6s %6s %7s %11s %9s %9s %8s %9s %-8s\n' vendor rate steps "wall s" bytes/step /agent pkts/step \
  "x clean" "tbf drops" terrain
domain=60
for dds in $vendors; do
  clean_sha="" clean_bps=""
  for rate in $rates; do
    tc qdisc del dev lo root 2>/dev/null || true
    [ "$rate" = none ] || tc qdisc add dev lo root tbf rate "$rate" burst 32kbit latency 400ms
    : >"$work/rows"
    for run in $(seq 1 "$runs"); do
      domain=$((domain + 1))
      out="$work/$dds-$rate-$run"
      b0=$(lo 10) p0=$(lo 11) t0=$(date +%s.%N)
      profile=()
      [ "$dds" = fastdds ] && [ -n "$fastdds_profile" ] && profile=("MARSALA_DDS_CONFIG=$fastdds_profile")
      env "${profile[@]}" "$root/deploy/spawn.sh" --scenario "$root/deploy/scenarios/ramp.pbtxt" --agents 3 \
        --dds "$dds" --domain "$domain" --max-steps "$steps" --out "$out" --quiet --timeout "$timeout" >/dev/null 2>&1 ||
        true
      b1=$(lo 10) p1=$(lo 11) t1=$(date +%s.%N)
      s=$(jq -r '.steps // 0' "$out/summary.json" 2>/dev/null || echo 0)
      sha=$(jq -r '.terrain_sha256 // "none"' "$out/summary.json" 2>/dev/null || echo none)
      per=$((s > 0 ? s : 1))
      drops=$(tc -s qdisc show dev lo | grep -o 'dropped [0-9]*' | head -1 | cut -d' ' -f2)
      echo "$s $(echo "$t1 - $t0" | bc) $(((b1 - b0) / per)) $(((p1 - p0) / per)) ${drops:-0} $sha" >>"$work/rows"
      [ "$rate" = none ] || { tc qdisc del dev lo root; tc qdisc add dev lo root tbf rate "$rate" burst 32kbit latency 400ms; }
    done
    col() { awk -v c="$1" '{ print $c }' "$work/rows" | median; }
    bps=$(col 3)
    sha=$(awk '{ print $6 }' "$work/rows" | sort | uniq -c | sort -rn | head -1 | awk '{ print $2 }')
    if [ "$rate" = none ]; then clean_sha=$sha clean_bps=$bps; fi
    label=${sha:0:8}
    [ "$rate" != none ] && [ "$sha" = "$clean_sha" ] && label="same"
    printf '%-8s %-6s %6s %7.1f %11.0f %9.0f %9.0f %8.2f %9s %-8s\n' "$dds" "$rate" "$(col 1)" "$(col 2)" "$bps" \
      "$(echo "$bps / 3" | bc -l)" "$(col 4)" "$(echo "$bps / $clean_bps" | bc -l)" "$(col 5)" "$label"
  done
done
