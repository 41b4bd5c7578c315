#!/usr/bin/env bash
# The path scenario with perception ranges of 2.5, 5, 8 and 12 m (robot_type.body.sensing_range_m: the half-side of
# the window a ground-truth sensor sees), path_generated.pbtxt with 5 robots, seeds 1..3 by default. Extra arguments
# go to deploy/experiment.sh (e.g. --seeds 5 --jobs 2 --agents 9 --out DIR, or --scenario for another path scenario).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
exec "$root/deploy/experiment.sh" --scenario "$root/deploy/scenarios/path_generated.pbtxt" --agents 5 \
  --vary robot_type.body.sensing_range_m --values "2.5 5 8 12" --label "perception range [m]" \
  --out out/perception_range "$@"
