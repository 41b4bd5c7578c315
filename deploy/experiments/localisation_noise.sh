#!/usr/bin/env bash
# Site preparation with localisation error (issue: the paper's authors ran site preparation with and without it):
# site_rough.pbtxt (11 robots, kappa 0.1, 46 % level at the start) with pose noise of 0, 5, 10 and 20 cm (sd per
# axis, robot_type.localisation.noise_sd_m), seeds 1..3 by default. Extra arguments go to deploy/experiment.sh
# (e.g. --seeds 5 --jobs 2 --out DIR). Outputs: OUT/experiment.csv, experiment_stats.csv, experiment.png.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
exec "$root/deploy/experiment.sh" --scenario "$root/deploy/scenarios/site_rough.pbtxt" \
  --vary robot_type.localisation.noise_sd_m --values "0 0.05 0.1 0.2" --label "localisation noise sd [m]" \
  --out out/localisation_noise "$@"
