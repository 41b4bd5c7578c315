#!/usr/bin/env bash
# Four-host benchmark: deploy/scenarios/crowd_240.pbtxt over five network-namespace hosts on one bridge
# (tests/integration/lib.sh bridge_hosts and no_multicast: h1..h5 at 10.78.0.1-5, multicast off and dropped), the
# world on h1, --per-host N agents on each of h2..h5 (ids 1..N on h2, N+1..2N on h3, ...), every process with the
# unicast profile of its vendor (Fast DDS from 48 agents in all: fastdds-unicast-crowd.xml, as deploy/spawn.sh picks
# it) and --peers 10.78.0.1 (the world's address), insecure, --steps steps (default 200).
# One run per vendor, one after the other. Per run it reports (table on stdout, one CSV row per run in --csv FILE):
#   admit s        from the world's start of admission to its first frame (summary.json admit_seconds)
#   adm/conn/drop  agents admitted, connected at the first frame, dropped at the end (summary.json)
#   missed         steps a live agent sent no request for before the deadline (summary.json missed_deadlines)
#   step med/p90   wall time of one lockstep step [ms]
#   world CPU      the world process's CPU time per step, DDS threads included [ms]
#   agents CPU     all agents' CPU time per step, summed [ms]
#   disc kB h1..h5 bytes of discovery traffic (SPDP and SEDP: UDP to the domain's metatraffic unicast ports, RTPS
#                  7400 + 250 d + 10 + 2 i) each host sent and received during the whole run, by nftables counters
#                  on the host's eth0 (loopback traffic left out) [kB]
#   eth0 kB h1..h5 all bytes each host's interface sent and received during the run (/sys/class/net statistics) [kB]
#   profile        the DDS profile every process had (deploy/dds/)
# Needs root for namespaces, a bridge and nftables; makes its own private namespaces (nothing outside is touched).
# Usage: bench/multihost_bench.sh [--dds "cyclone fastdds"] [--per-host N] [--steps S] [--csv FILE] [--domain D]
#        [--keep DIR]   (keep each run's folder, logs and summary.json, in DIR/VENDOR)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${MARSALA_BUILD_DIR:-$root/build}"
vendors="cyclone fastdds" per_host=60 steps=200 csv="" domain=46 keep=""
while [ $# -gt 0 ]; do
  case "$1" in
    --dds) vendors="$2"; shift 2 ;;
    --per-host) per_host="$2"; shift 2 ;;
    --steps) steps="$2"; shift 2 ;;
    --csv) csv="$2"; shift 2 ;;
    --domain) domain="$2"; shift 2 ;;
    --keep) keep="$2"; shift 2 ;;
    -h|--help) sed -n '2,21p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "multihost_bench.sh: unknown argument '$1' (try --help)" >&2; exit 2 ;;
  esac
done
[[ "$per_host" =~ ^[0-9]+$ ]] && [ "$per_host" -ge 1 ] && [ "$per_host" -le 60 ] ||
  { echo "multihost_bench.sh: --per-host N (1 <= N <= 60: crowd_240 has 240 slots), got '$per_host'" >&2; exit 2; }
[[ "$steps" =~ ^[0-9]+$ ]] && [ "$steps" -ge 1 ] || { echo "multihost_bench.sh: --steps S (S >= 1), got '$steps'" >&2; exit 2; }
[[ "$domain" =~ ^[0-9]+$ ]] && [ "$domain" -le 200 ] || { echo "multihost_bench.sh: --domain D (0..200), got '$domain'" >&2; exit 2; }
for v in $vendors; do
  case "$v" in cyclone|fastdds) ;; *) echo "multihost_bench.sh: --dds: '$v' is not cyclone or fastdds" >&2; exit 2 ;; esac
done
[ -x "$build/bin/marsala-world" ] && [ -x "$build/bin/marsala-agent" ] ||
  { echo "multihost_bench.sh: no marsala-world / marsala-agent in $build/bin (MARSALA_BUILD_DIR)" >&2; exit 1; }

# Private network and mount namespaces of our own: the bridge, the hosts and /run/netns exist only there.
if [ "${MARSALA_MULTIHOST_BENCH_INNER:-}" != 1 ]; then
  exec env MARSALA_MULTIHOST_BENCH_INNER=1 unshare -n -m --propagation private bash "$0" --dds "$vendors" \
    --per-host "$per_host" --steps "$steps" --csv "$csv" --domain "$domain" --keep "$keep"
fi
bin="$build/bin"
scenario="$root/deploy/scenarios/crowd_240.pbtxt"
work="$(mktemp -d "${TMPDIR:-/tmp}/marsala-multihost-bench.XXXXXX")"
trap 'rm -rf "$work"' EXIT
. "$root/tests/integration/lib.sh"  # bridge_hosts, no_multicast, field
bridge_hosts 10.78.0 5
no_multicast 5
unset CYCLONEDDS_URI FASTRTPS_DEFAULT_PROFILES_FILE MARSALA_DDS_CONFIG MARSALA_PEERS
team=$((4 * per_host))
# shellcheck source=deploy/dds/crowd.sh
source "$root/deploy/dds/crowd.sh"  # as deploy/spawn.sh: from marsala_crowd_agents on, Fast DDS takes the crowd's timing

# discovery_counters D: on every host a table `disc` counting UDP to domain D's metatraffic unicast ports (participant
# indices 0..127), in and out.
discovery_counters() {
  local base=$((7400 + 250 * $1)) ports="" i h
  for i in $(seq 0 127); do ports="$ports${ports:+, }$((base + 10 + 2 * i))"; done
  for h in 1 2 3 4 5; do
    ip netns exec "h$h" nft delete table inet disc 2>/dev/null || true
    ip netns exec "h$h" nft -f - <<NFT
table inet disc {
  chain out { type filter hook output priority 0; oifname "eth0" udp dport { $ports } counter; }
  chain in { type filter hook input priority 0; iifname "eth0" udp dport { $ports } counter; }
}
NFT
  done
}
# discovery_kb HOST: bytes counted by HOST's `disc` table, in and out [kB].
discovery_kb() {
  ip netns exec "$1" nft list table inet disc | grep -o 'bytes [0-9]*' | awk '{ t += $2 } END { printf "%.0f", t / 1000 }'
}
# eth0_bytes HOST: bytes HOST's eth0 sent plus received so far.
eth0_bytes() {
  ip netns exec "$1" sh -c 'echo $(( $(cat /sys/class/net/eth0/statistics/rx_bytes) + $(cat /sys/class/net/eth0/statistics/tx_bytes) ))'
}

printf '%-8s %6s %7s %-13s %6s %8s %8s %9s %10s  %-29s %-34s %s\n' vendor agents "admit s" adm/conn/drop missed "step med" \
  "step p90" "world CPU" "agents CPU" "disc kB h1/h2/h3/h4/h5" "eth0 kB h1/h2/h3/h4/h5" profile
[ -z "$csv" ] || [ -s "$csv" ] || echo "vendor,per_host,agents,admitted,connected,dropped,missed_deadlines,admit_s,steps,end_reason,step_median_ms,step_p90_ms,world_cpu_ms_per_step,agents_cpu_ms_per_step,disc_kb_h1,disc_kb_h2,disc_kb_h3,disc_kb_h4,disc_kb_h5,eth0_kb_h1,eth0_kb_h2,eth0_kb_h3,eth0_kb_h4,eth0_kb_h5,profile" >"$csv"
for dds in $vendors; do
  domain=$((domain + 1))
  out="$work/$dds"
  mkdir -p "$out/logs"
  discovery_counters "$domain"
  declare -A eth0_start=()
  for h in 1 2 3 4 5; do eth0_start[$h]=$(eth0_bytes "h$h"); done
  config="$root/deploy/dds/$dds-unicast.xml"
  [ "$dds" = fastdds ] && config=$(marsala_crowd_profile "$config" "$team")
  profile=${config##*/}
  peers=(--peers 10.78.0.1 --domain "$domain" --dds "$dds" --dds-config "$config")
  ip netns exec h1 "$bin/marsala-world" --scenario "$scenario" --agents "$team" "${peers[@]}" --max-steps "$steps" \
    --admit-timeout 600 --out "$out" >"$out/logs/world.log" 2>&1 &
  world=$!
  pids=()
  for id in $(seq 1 "$team"); do
    ip netns exec "h$(( (id - 1) / per_host + 2 ))" "$bin/marsala-agent" --scenario "$scenario" --id "$id" "${peers[@]}" \
      --admit-timeout 600 >"$out/logs/agent-$id.log" 2>&1 &
    pids+=($!)
  done
  rc=0
  wait "$world" || rc=$?
  for pid in "${pids[@]}"; do wait "$pid" || true; done
  # 3 (max_steps) is the benchmark's own end; 0 if the site happened to be level first.
  if [ "$rc" -ne 0 ] && [ "$rc" -ne 3 ] || [ ! -f "$out/summary.json" ]; then
    echo "multihost_bench.sh: the $dds run with $team agents failed (world exit $rc):" >&2
    tail -5 "$out/logs/world.log" >&2 || true
    [ -z "$keep" ] || { mkdir -p "$keep" && rm -rf "${keep:?}/$dds" && cp -a "$out" "$keep/$dds"; }
    exit 1
  fi
  disc=() eth=()
  for h in 1 2 3 4 5; do
    disc+=("$(discovery_kb "h$h")")
    eth+=("$(( ($(eth0_bytes "h$h") - ${eth0_start[$h]}) / 1000 ))")
  done
  unset eth0_start
  s="$out/summary.json"
  num() { jq -r ".$1 // 0" "$s"; }
  agents_cpu=$(grep -ho 'process CPU [0-9.]* ms per step' "$out"/logs/agent-*.log | awk '{ t += $3 } END { printf "%.1f", t }')
  printf '%-8s %6s %7.2f %-13s %6s %8.1f %8.1f %9.2f %10s  %-29s %-34s %s\n' "$dds" "$team" "$(num admit_seconds)" \
    "$(num admitted)/$(num connected)/$(num dropped)" "$(num missed_deadlines)" "$(num step_wall_median_ms)" \
    "$(num step_wall_p90_ms)" "$(num world_cpu_ms_per_step)" "$agents_cpu" "$(IFS=/; echo "${disc[*]}")" \
    "$(IFS=/; echo "${eth[*]}")" "$profile"
  [ -z "$csv" ] || echo "$dds,$per_host,$team,$(num admitted),$(num connected),$(num dropped),$(num missed_deadlines),$(num admit_seconds),$(num steps),$(num end_reason),$(num step_wall_median_ms),$(num step_wall_p90_ms),$(num world_cpu_ms_per_step),$agents_cpu,$(IFS=,; echo "${disc[*]}"),$(IFS=,; echo "${eth[*]}"),$profile" >>"$csv"
  [ -z "$keep" ] || { mkdir -p "$keep" && rm -rf "${keep:?}/$dds" && cp -a "$out" "$keep/$dds"; }
done
