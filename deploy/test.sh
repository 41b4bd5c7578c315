#!/usr/bin/env bash
# The README's test command: installs what is missing, builds (Release) and runs every test with ctest.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
# The container test runs real containers with podman; the live view's test drives a headless chromium; the metrics
# test scrapes the world with Debian's prometheus; the Slurm sweep test starts a two-node slurm-wlm cluster.
"$root/deploy/install-deps.sh" --containers --browser --prometheus --npm --slurm
"$root/deploy/build.sh"
cd "${MARSALA_BUILD_DIR:-$root/build}"
ctest --output-on-failure -j"$(nproc)" --timeout 600
