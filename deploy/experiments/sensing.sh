#!/usr/bin/env bash
# The sensing experiment (issue 24): ground truth / rgbd / laser robots x localisation noise 0 / 5 / 10 cm on the ramp
# (3 robots) and path_generated (5), seeds 1..3, as real processes over loopback DDS (deploy/experiment.sh with
# --dump-maps): completion steps, volume, refused requests and the robots' map error (marsala-terrain compare).
# Options: deploy/experiments/sensing.sh --help (e.g. --max-steps 900 --scenarios ramp --seeds 1 --out DIR).
# Outputs: OUT/sensing.csv, sensing_stats.csv, sensing.png (default OUT: out/sensing).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
PYTHONPATH="$root/deploy${PYTHONPATH:+:$PYTHONPATH}" exec python3 -m marsala_tools.sensing "$@"
