#!/usr/bin/env bash
# The README's main job: installs what is missing, builds, and runs the ramp scenario (paper Fig. 2) as real
# processes: one marsala-world and 3 marsala-agent processes over DDS (loopback only), then prints the summary and
# the picture paths. --scenario runs another scenario of deploy/scenarios the same way, e.g. path_generated (the
# paper's path construction, 5 robots by default) or site_prep (site preparation, 11 robots). With --terrain it
# runs the terrain demo instead (MARS gap and navigability of a generated site).
# Usage: deploy/demo.sh [--scenario NAME|FILE] [--agents N] [--dds cyclone|fastdds] [--out DIR] [--terrain [--seed S]]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
out="$root/out/demo"
seed=7
agents=""
dds=cyclone
mode=scenario
scenario=ramp
while [ $# -gt 0 ]; do
  case "$1" in
    --out|--seed|--agents|--dds|--scenario)
      [ $# -ge 2 ] || { echo "demo.sh: $1 needs a value (try --help)" >&2; exit 2; }
      case "$1" in
        --out) out="$2" ;;
        --seed) seed="$2" ;;
        --agents) agents="$2" ;;
        --dds) dds="$2" ;;
        --scenario) scenario="$2" ;;
      esac
      shift 2 ;;
    --terrain) mode=terrain; shift ;;
    -h|--help) sed -n '2,7p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "demo.sh: unknown argument '$1' (try --help)" >&2; exit 2 ;;
  esac
done

if [ "$mode" = scenario ]; then
  file="$scenario"
  [ -f "$file" ] || file="$root/deploy/scenarios/$scenario.pbtxt"
  if [ ! -f "$file" ]; then
    names="$(cd "$root/deploy/scenarios" && ls *.pbtxt | sed 's/\.pbtxt$//' | tr '\n' ' ')"
    echo "demo.sh: no scenario '$scenario' (a file, or one of: $names)" >&2
    exit 2
  fi
fi

"$root/deploy/install-deps.sh"
"$root/deploy/build.sh" --programs  # the tests and benchmarks are deploy/test.sh's

if [ "$mode" = scenario ]; then
  name="$(basename "$file" .pbtxt)"
  case "$name" in
    ramp*) default_agents=3; what="robots build ramps to climb a 1.5 m platform (paper Fig. 2)" ;;
    path_*) default_agents=5; what="builders build a navigable path for a payload robot (paper §V-A)" ;;
    site_*) default_agents=11; what="robots level a site for kappa 0.1 (paper §V-B)" ;;
    hetero) default_agents=5; what="robots of four kinds (layer, cube and cone builders, a laser and an RGB-D scout) build one structure and climb it" ;;
    *)  # every agent slot, as the world counts them (marsala-world --check prints the scenario as JSON)
      facts="$("${MARSALA_BUILD_DIR:-$root/build}/bin/marsala-world" --check --json "$file")" || exit $?
      default_agents="$(jq '.slots | length' <<<"$facts")"; what="agents, every slot of $file" ;;
  esac
  agents="${agents:-$default_agents}"
  echo "== $name: $agents $what"
  exec "$root/deploy/spawn.sh" --scenario "$file" --agents "$agents" --dds "$dds" --out "$out" --replace
fi

terrain="${MARSALA_BUILD_DIR:-$root/build}/bin/marsala-terrain"
mkdir -p "$out"

# Robot: Husky-like, body length 1 m, climbs slopes up to 0.3, drives over 5 cm steps.
nav=(--kappa 0.3 --eps 0.05 --delta 1.0)

echo "== 1. A generated site: 60 x 60 m of mixed terrain at 0.1 m cells (seed $seed)"
"$terrain" generate --method mix --seed "$seed" --rows 600 --cols 600 --cell-size 0.1 -o "$out/site.asc"
"$terrain" info "$out/site.asc"
"$terrain" mars --kappa 0.3 --gap "$out/site.asc" -o "$out/site_gap.asc"
"$terrain" navigable "${nav[@]}" --origin-cell 300 300 "$out/site.asc" -o "$out/site_navigable.asc"
"$terrain" render "$out/site.asc" -o "$out/site.png" --title "generated site, seed $seed"
"$terrain" render "$out/site.asc" -o "$out/site_navigable.png" "${nav[@]}" --navigable-from 300 300 --gap \
  --title "navigable from the centre (green), MARS gap at kappa 0.3 (heat)"

echo
echo "== 2. The paper's platform test: a 1.5 m platform on flat ground, MARS ramps for three slopes"
"$terrain" generate --method platform --rows 300 --cols 300 --cell-size 0.1 -o "$out/platform.asc"
for kappa in 0.2 0.3 0.5; do
  "$terrain" mars --kappa "$kappa" "$out/platform.asc" -o "$out/platform_mars_k$kappa.asc"
  "$terrain" render "$out/platform_mars_k$kappa.asc" -o "$out/platform_mars_k$kappa.png" \
    --kappa "$kappa" --eps 0.05 --delta 1.0 --navigable-from 5 5 --title "MARS of the platform, kappa $kappa"
done

echo
echo "Pictures:"
ls -1 "$out"/*.png | sed 's/^/  /'
