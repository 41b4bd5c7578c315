#!/usr/bin/env bash
# Builds (Release) and runs the micro-benchmarks, printing medians over repetitions.
# Timing is noisy on shared machines: compare ratios measured in the same run, not absolute numbers across runs.
# Usage: bench/run.sh [BENCH_NAME_REGEX] [extra google-benchmark flags]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$root/deploy/install-deps.sh" >/dev/null
"$root/deploy/build.sh" >/dev/null
filter="${1:-.}"
shift || true
for bench in "${MARSALA_BUILD_DIR:-$root/build}"/bench/*_bench; do
  echo "== $(basename "$bench")"
  "$bench" --benchmark_filter="$filter" --benchmark_repetitions=5 --benchmark_report_aggregates_only=true \
    --benchmark_display_aggregates_only=true "$@" 2>&1 | grep -E '_median|^Benchmark|^-' || true
done
