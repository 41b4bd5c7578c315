#!/usr/bin/env bash
# Configures and builds MARSala (Release) into build/; binaries land in build/bin/.
# Usage: deploy/build.sh [--programs] [extra cmake arguments]
#   --programs  only the four programs (marsala-world, -agent, -monitor, -terrain): what the demo runs, about a third
#               of a full build; the tests and benchmarks are built by a plain deploy/build.sh (deploy/test.sh)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="${MARSALA_BUILD_DIR:-$root/build}"
targets=()
if [ "${1:-}" = --programs ]; then
  shift
  targets=(--target marsala-world marsala-agent marsala-monitor marsala-terrain)
fi
cmake -S "$root" -B "$build_dir" -DCMAKE_BUILD_TYPE=Release "$@" >/dev/null
cmake --build "$build_dir" -j"$(nproc)" "${targets[@]}"
