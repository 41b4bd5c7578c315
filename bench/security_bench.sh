#!/usr/bin/env bash
# What DDS Security costs: crowd_120 with 3 and 12 agents, 200 steps, on each vendor, unsecured and secured
# (spawn.sh --secure: authentication, access control, everything encrypted), one run after the other. Reports the
# admission time (summary.json admit_seconds) and the step median and p90 of each, and the secured/unsecured ratio.
# Run it inside a private network namespace: unshare -n sh -c 'ip link set lo up; bench/security_bench.sh'
# Usage: bench/security_bench.sh [--dds "cyclone fastdds"] [--teams "3 12"] [--steps N]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${MARSALA_BUILD_DIR:-$root/build}"
vendors="cyclone fastdds" teams="3 12" steps=200
while [ $# -gt 0 ]; do
  case "$1" in
    --dds) vendors="$2"; shift 2 ;;
    --teams) teams="$2"; shift 2 ;;
    --steps) steps="$2"; shift 2 ;;
    -h|--help) sed -n '2,6p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "security_bench.sh: unknown argument '$1' (try --help)" >&2; exit 2 ;;
  esac
done
[ -x "$build/bin/marsala-world" ] || "$root/deploy/build.sh" >/dev/null
work="$(mktemp -d "${TMPDIR:-/tmp}/marsala-security.XXXXXX")"
trap 'rm -rf "$work"' EXIT
export MARSALA_BUILD_DIR="$build"

# One identity folder for every run (every domain, the largest team): spawn.sh reuses it.
largest=$(printf '%s\n' $teams | sort -n | tail -1)
"$root/deploy/security/make-identities.sh" --out "$work/identities" --agents "$largest" >/dev/null
printf '%-8s %6s %-9s %8s %9s %9s\n' vendor agents mode "admit s" "step med" "step p90"
domain=60
for dds in $vendors; do
  for n in $teams; do
    for mode in plain secured; do
      out="$work/$dds-$n-$mode"
      domain=$((domain + 1))
      flags=()
      [ "$mode" = secured ] && flags=(--secure --identities "$work/identities")
      rc=0
      "$root/deploy/spawn.sh" --scenario "$root/deploy/scenarios/crowd_120.pbtxt" --agents "$n" --dds "$dds" \
        --domain "$domain" --out "$out" --max-steps "$steps" --quiet --timeout 600 "${flags[@]}" \
        >"$work/spawn.txt" 2>&1 || rc=$?
      [ "$rc" -eq 0 ] || [ "$rc" -eq 3 ] ||
        { echo "security_bench.sh: $dds, $n agents, $mode: spawn.sh exit $rc" >&2; tail -3 "$work/spawn.txt" >&2; exit 1; }
      printf '%-8s %6s %-9s %8.2f %9.2f %9.2f\n' "$dds" "$n" "$mode" "$(jq .admit_seconds "$out/summary.json")" \
        "$(jq .step_wall_median_ms "$out/summary.json")" "$(jq .step_wall_p90_ms "$out/summary.json")"
    done
  done
done
