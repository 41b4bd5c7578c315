#!/usr/bin/env bash
# Loss benchmark (issue 28 deliverable 4, docs/runtime.md#lossy-links): whole runs, seed 1, over this namespace's
# loopback with a share of the DDS datagrams dropped at random on the way out (an nftables rule; tc netem is not in
# every kernel), for each vendor, --runs runs each (default 1), one after the other. The default table is
# path_generated with 5 agents at 0, 5 and 20 % loss and ramp with 3 agents at 50 %. Per case and vendor it reports
# medians over the runs:
#   steps      steps reached
#   end        end_reason of the run (the last run's; "timeout" when it wrote no summary within --timeout S, default 400)
#   wall s     the run's wall time, spawn to summary [s]
#   terrain    the terrain_sha256's first 8 hex digits
# and, on the Fast DDS row, fast/cyc: Fast DDS's median wall time over Cyclone's.
# It changes this namespace's packet filter, so run it inside a private network namespace (needs nft):
#   unshare -n bash -c 'ip link set lo up; bench/loss_bench.sh'
# Usage: bench/loss_bench.sh [--dds "cyclone fastdds"] [--cases "path_generated:5:0 ..."] [--runs N] [--timeout S]
#   a case is SCENARIO:AGENTS:LOSS (deploy/scenarios/SCENARIO.pbtxt, LOSS in percent, 0..99)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${MARSALA_BUILD_DIR:-$root/build}"
vendors="cyclone fastdds" runs=1 timeout=400
cases="path_generated:5:0 path_generated:5:5 path_generated:5:20 ramp:3:50"
while [ $# -gt 0 ]; do
  case "$1" in
    --dds) vendors="$2"; shift 2 ;;
    --cases) cases="$2"; shift 2 ;;
    --runs) runs="$2"; shift 2 ;;
    --timeout) timeout="$2"; shift 2 ;;
    -h|--help) sed -n '2,15p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "loss_bench.sh: unknown argument '$1' (try --help)" >&2; exit 2 ;;
  esac
done
for n in "$runs" "$timeout"; do
  [[ "$n" =~ ^[0-9]+$ ]] && [ "$n" -ge 1 ] || { echo "loss_bench.sh: --runs, --timeout take N >= 1, got '$n'" >&2; exit 2; }
done
for c in $cases; do
  IFS=: read -r scenario agents loss <<<"$c"
  [ -f "$root/deploy/scenarios/$scenario.pbtxt" ] && [[ "$agents" =~ ^[0-9]+$ ]] && [[ "$loss" =~ ^[0-9]{1,2}$ ]] ||
    { echo "loss_bench.sh: --cases: '$c' is not SCENARIO:AGENTS:LOSS with LOSS 0..99" >&2; exit 2; }
done
command -v nft >/dev/null || { echo "loss_bench.sh: nft not found (apt-get install nftables)" >&2; exit 2; }
nft add table inet marsala_loss 2>/dev/null || { echo "loss_bench.sh: cannot use nft here: run it inside unshare -n" >&2; exit 2; }
nft delete table inet marsala_loss
[ -x "$build/bin/marsala-world" ] || "$root/deploy/build.sh" >/dev/null
work="$(mktemp -d "${TMPDIR:-/tmp}/marsala-loss.XXXXXX")"
trap 'nft delete table inet marsala_loss 2>/dev/null || true; rm -rf "$work"' EXIT
export MARSALA_BUILD_DIR="$build"
median() { sort -g | awk '{ v[NR] = $1 } END { print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }

# lose DOMAIN PERCENT: drop PERCENT % of the UDP datagrams sent to the domain's RTPS ports (7400 + 250 * DOMAIN ...
# + 249), discovery and user traffic alike, as they leave any process of this namespace.
lose() {
  nft delete table inet marsala_loss 2>/dev/null || true
  [ "$2" -gt 0 ] || return 0
  local low=$((7400 + 250 * $1))
  nft add table inet marsala_loss
  nft add chain inet marsala_loss out '{ type filter hook output priority 0; }'
  nft add rule inet marsala_loss out udp dport "$low-$((low + 249))" numgen random mod 100 '<' "$2" drop
}

printf '%-20s %-5s %-8s %6s %-11s %7s %-8s %8s\n' case loss vendor steps end "wall s" terrain fast/cyc
domain=40
for c in $cases; do
  IFS=: read -r scenario agents loss <<<"$c"
  cyclone_wall=""
  for dds in $vendors; do
    : >"$work/rows"
    for run in $(seq 1 "$runs"); do
      domain=$((domain + 1))
      out="$work/$scenario-$agents-$loss-$dds-$run"
      lose "$domain" "$loss"
      t0=$(date +%s.%N)
      "$root/deploy/spawn.sh" --scenario "$root/deploy/scenarios/$scenario.pbtxt" --agents "$agents" --dds "$dds" \
        --domain "$domain" --seed 1 --out "$out" --quiet --timeout "$timeout" >/dev/null 2>&1 || true
      t1=$(date +%s.%N)
      lose "$domain" 0
      s=$(jq -r '.steps // 0' "$out/summary.json" 2>/dev/null || echo 0)
      end=$(jq -r '.end_reason // "timeout"' "$out/summary.json" 2>/dev/null || echo timeout)
      sha=$(jq -r '.terrain_sha256 // "none"' "$out/summary.json" 2>/dev/null || echo none)
      echo "$s $(echo "$t1 - $t0" | bc) $end $sha" >>"$work/rows"
    done
    col() { awk -v c="$1" '{ print $c }' "$work/rows" | median; }
    wall=$(col 2)
    ratio="-"
    [ "$dds" = cyclone ] && cyclone_wall=$wall
    [ "$dds" != cyclone ] && [ -n "$cyclone_wall" ] && ratio=$(printf '%.2f' "$(echo "$wall / $cyclone_wall" | bc -l)")
    sha=$(awk '{ print $4 }' "$work/rows" | sort | uniq -c | sort -rn | head -1 | awk '{ print $2 }')
    printf '%-20s %-5s %-8s %6s %-11s %7.1f %-8s %8s\n' "$scenario $agents" "$loss%" "$dds" "$(col 1)" \
      "$(tail -1 "$work/rows" | awk '{ print $3 }')" "$wall" "${sha:0:8}" "$ratio"
  done
done
