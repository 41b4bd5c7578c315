#!/usr/bin/env bash
# The paper's scenarios (paper §V) small and fast, as real multi-process runs (marsala-world + marsala-agent over
# DDS through deploy/spawn.sh, each case on its own domain with the loopback configs; ctest runs it inside
# run_isolated.sh). Every outcome is checked again on the authoritative terrain the world wrote, with
# marsala-terrain, independently of the world's own completion test.
#
# Usage: scenario_test.sh CASE DOMAIN
#   path   tests/integration/scenarios/path_small.pbtxt, 3 path builders (Cyclone DDS): the payload (kappa 0.2,
#          body 1.5 m) reaches the target on terrain_final.asc and did not on terrain_initial.asc, the target's cell
#          at most one cube layer higher; builders refilled
#          (each carries 0.5 m^3); the summary's volume equals the terrain's change
#   site   tests/integration/scenarios/site_small.pbtxt, 3 levellers on a goal vector map (Fast DDS): every cell of
#          the site, cropped from terrain_final.asc, is occupiable at kappa 0.1 and all are connected; it was not
#          so on terrain_initial.asc; goal_vector_map.png and final.png written
#   site_noisy the same site with localisation error (spawn.sh --set robot_type.localisation.noise_sd_m=0.1, Cyclone
#          DDS): level as above, summary.json lists the override; a misspelt override is refused before anything runs
#          (exit 2, naming the field and the valid ones)
#   three_gaps tests/integration/scenarios/path_three_gaps.pbtxt, 3 path builders (Cyclone DDS): the payload reaches the
#          target on terrain_final.asc (not before), the target's cell at most one cube layer higher, and what was
#          built forms three separate sites, one past each cliff (found on terrain_initial.asc), natural ground between
#   depositors tests/integration/scenarios/ramp_depositors.pbtxt run three times, one robot with the "layer", "cube"
#          (0.1 m cubes; Cyclone DDS) and "cone" (34 deg; Fast DDS) depositor: each completes (no request rejected),
#          the summary's volume equals the terrain's change, the target is navigable for the body from the start on
#          terrain_final.asc (not before), and `marsala-monitor replay` rebuilds the same terrain_sha256 from run.log;
#          cube: every raised cell rose by whole cubes (a multiple of 0.1 m: columns on cell centres); cone: no
#          raised cell stands above a neighbour by more than tan(34 deg) times their distance (the angle of repose);
#          every kind: no cell of terrain_final.asc above the initial terrain's MARS bound by more than 0.1 eps
#          (docs/runtime.md#deposit-bound); the cone's volume at most 1.65 x the layer's. Prints steps and m^3 of each.
#
# Usage: scenario_test.sh shipped DOMAIN NAME AGENTS DDS
#   shipped deploy/scenarios/NAME.pbtxt as shipped, AGENTS agents on DDS, to its end: completed, no request of an exact
#          robot rejected (a scanning robot's under 1 % of its own),
#          no close pass (bodies never came to overlap), the summary's volume equals the terrain's change, and its
#          completion re-checked with marsala-terrain on
#          terrain_final.asc from what `marsala-world --check --json` says of the scenario: payload_path, the payload
#          navigable from base to target (and not before), the target's cell at most one cube layer above its
#          initial height, and at least 90 % of the target's initial region navigable from the base; level_site, every site cell occupiable and connected (and
#          not before) and no cell raised above the terrain's MARS bound at the site's kappa; agents_at_goal, every agent inside the goal box at least min_height_m high
#          and, with a goal.target_radius_m, each within it of its own target, on a cell of terrain_final.asc at least
#          min_height_m high, its target navigable for its body from its start on terrain_final.asc (not before). Exit 77 (skipped)
#          when the scenario's terrain file is absent (../shared/data).
#   sensors tests/integration/scenarios/slope_sensors.pbtxt, a laser robot and an RGB-D robot (Cyclone world, Fast DDS
#          agents) climb a natural slope to their targets on maps from their own scans: completed, both at their
#          targets, at most 16 cubes built (map noise), no frame refused; run twice, the same number of steps
#   crowd  deploy/scenarios/crowd_120.pbtxt with 120 agents on DDS (arg 3), 100 steps: all 120 admitted and connected
#          at the first frame, none dropped, no deadline missed, every step applied.
set -euo pipefail
case_name="$1"
domain="$2"
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
bin="${MARSALA_BUILD_DIR:-$root/build}/bin"
scenarios="$root/tests/integration/scenarios"

work="$(mktemp -d "${TMPDIR:-/tmp}/marsala-it-scenario-$case_name.XXXXXX")"
trap 'rm -rf "$work"' EXIT

fail() { echo "FAIL (scenario $case_name): $*" >&2; exit 1; }
. "$root/tests/integration/lib.sh"  # field, is_png
agent_fields() {  # agent_fields NAME FILE: NAME of every per_agent entry, one per line
  grep -o "\"$1\": *[^,}]*" "$2" | sed 's/^[^:]*: *//; s/"//g'
}
extra=()       # more spawn.sh arguments for run_spawn (--set ...)
run_spawn() {  # run_spawn SCENARIO AGENTS DDS: runs it into $work/run, prints the summary's path
  local out="$work/run"
  "$root/deploy/spawn.sh" --scenario "$1" --agents "$2" --dds "$3" --domain "$domain" --out "$out" --quiet \
    --timeout 300 "${extra[@]}" >&2 || fail "spawn.sh failed (logs: $out/logs)"
  [ -f "$out/summary.json" ] || fail "no summary.json in $out"
  echo "$out/summary.json"
}
expect_completed() {  # expect_completed SUMMARY AGENTS
  [ "$(field completed "$1")" = "true" ] || { cat "$1"; fail "run did not complete"; }
  [ "$(field end_reason "$1")" = "completed" ] || { cat "$1"; fail "end_reason is not 'completed'"; }
  [ "$(field agents "$1")" = "$2" ] || { cat "$1"; fail "expected $2 agents in the summary"; }
  # A robot that reads exact heights is never refused; one that builds from its own scans (laser, rgbd) learns from a
  # refusal (docs/runtime.md#refused-requests), under 1 % of its requests (issue 24's bar). $scanning_types: the robot
  # types that scan (default: none).
  jq -e --argjson scanning "${scanning_types:-[]}" '
    [.per_agent[] | select(.admitted) | . as $a
     | if ($scanning | index($a.robot_type)) then ($a.rejected * 100 >= $a.accepted + $a.rejected) else ($a.rejected > 0) end]
    | any | not' "$1" >/dev/null && [ "$(field unattributed_rejections "$1")" = "0" ] ||
    { cat "$1"; fail "the world rejected requests (exact robots: none allowed; scanning robots: under 1 %)"; }
  # Rule 2.5: no two bodies came to overlap (docs/runtime.md#collisions), and the agents planned for it (no motion
  # rejected above).
  [ "$(field close_passes "$1")" = "0" ] || { cat "$1"; fail "robot bodies came to overlap"; }
}
asc_cell() {  # asc_cell FILE ROW COL: the value of one cell (row 0 = north)
  awk -v r="$2" -v c="$3" 'NR == 7 + r { print $(c + 1); exit }' "$1"
}

case "$case_name" in
  path)
    s=$(run_spawn "$scenarios/path_small.pbtxt" 3 cyclone)
    expect_completed "$s" 3
    out="$(dirname "$s")"
    [ "$(field path_found "$s")" = "true" ] || { cat "$s"; fail "summary: no payload path"; }
    # The path joins base and target, 12 m apart: at least that long.
    awk -v l="$(field path_length_m "$s")" 'BEGIN { exit !(l >= 12.0 && l < 30.0) }' ||
      fail "payload path length $(field path_length_m "$s") m, expected [12, 30)"
    # Base (6.125, 6.125) m -> cell row 47 - 24 = 23, col 24; target (18.125, 6.125) m -> row 23, col 72.
    nav() {  # nav TERRAIN OUT: payload-navigable cells from the base
      "$bin/marsala-terrain" navigable --kappa 0.2 --delta 1.5 --eps 0.05 --origin-cell 23 24 "$1" -o "$2" >/dev/null
    }
    nav "$out/terrain_initial.asc" "$work/nav_initial.asc"
    nav "$out/terrain_final.asc" "$work/nav_final.asc"
    [ "$(asc_cell "$work/nav_initial.asc" 23 72)" = "0" ] || fail "the target was navigable before any construction"
    [ "$(asc_cell "$work/nav_final.asc" 23 72)" = "1" ] ||
      fail "marsala-terrain finds no payload path to the target on terrain_final.asc"
    # The target on its own ground: at most one cube layer (0.1^3 / 0.25^2 = 0.016 m) above its initial height.
    awk -v a="$(asc_cell "$out/terrain_initial.asc" 23 72)" -v b="$(asc_cell "$out/terrain_final.asc" 23 72)" \
      'BEGIN { exit !(b - a <= 0.016 + 1e-9) }' || fail "the target's cell rose more than one cube layer"
    # Material: 0.5 m^3 per trip; a builder that deposited more refilled at the base.
    refilled=$(agent_fields deposited_m3 "$s" | awk '$1 > 0.5 + 1e-9 { n++ } END { print n + 0 }')
    [ "$refilled" -ge 2 ] || { cat "$s"; fail "only $refilled builders deposited more than one load (0.5 m^3)"; }
    # Conservation: the summary's volume is the terrain's change (cells of 0.25 m: 0.0625 m^2).
    awk -v v="$(field deposited_volume_m3 "$s")" '
      FNR <= 6 { next }
      NR == FNR { for (i = 1; i <= NF; i++) h[FNR, i] = $i; next }
      { for (i = 1; i <= NF; i++) { d = $i - h[FNR, i]; if (d < -1e-9) neg++; sum += d } }
      END { sum *= 0.0625; if (neg || sum < v - 1e-6 || sum > v + 1e-6) { print "terrain change " sum " m^3, summary " v " m^3, " neg + 0 " cells lowered"; exit 1 } }
    ' "$out/terrain_initial.asc" "$out/terrain_final.asc" || fail "deposited volume does not match the terrain"
    is_png "$out/final.png" || fail "final.png missing or not a PNG"
    echo "ok: path: payload path $(field path_length_m "$s") m after $(field steps "$s") steps," \
      "$(field deposited_volume_m3 "$s") m^3; $refilled builders refilled"
    ;;
  site|site_noisy)
    dds=fastdds
    if [ "$case_name" = site_noisy ]; then
      dds=cyclone
      rc=0
      "$root/deploy/spawn.sh" --scenario "$scenarios/site_small.pbtxt" --agents 3 --domain "$domain" --out "$work/bad" \
        --quiet --set robot_type.localisation.noise=0.1 2>"$work/bad.err" || rc=$?
      [ "$rc" = 2 ] || fail "a misspelt --set: spawn.sh exit $rc, expected 2"
      grep -q "Localisation has no field 'noise'; valid: noise_sd_m, correlation_steps" "$work/bad.err" ||
        fail "a misspelt --set: no clear message: $(cat "$work/bad.err")"
      extra=(--set robot_type.localisation.noise_sd_m=0.1)
    fi
    s=$(run_spawn "$scenarios/site_small.pbtxt" 3 "$dds")
    expect_completed "$s" 3
    out="$(dirname "$s")"
    [ "$(field site_level_fraction "$s")" = "1" ] || { cat "$s"; fail "summary: site level fraction is not 1"; }
    level() {  # level TERRAIN TAG: prints "occupiable navigable total" of the site [4, 12] x [3, 9] m
      "$bin/marsala-terrain" import "$1" --crop 4 3 8 6 -o "$work/$2_site.asc" >/dev/null
      local occ nav
      occ=$("$bin/marsala-terrain" navigable --occupiable --kappa 0.1 --delta 1 --eps 0.05 "$work/$2_site.asc" \
        -o "$work/$2_occ.asc")
      nav=$("$bin/marsala-terrain" navigable --kappa 0.1 --delta 1 --eps 0.05 --origin-cell 12 16 \
        "$work/$2_site.asc" -o "$work/$2_nav.asc")
      # "occupiable N of M cells ..." and "navigable from (r, c): N of M cells ..."
      echo "$(echo "$occ" | awk '{ print $2 }') $(echo "$nav" | awk '{ print $5 }') $(echo "$occ" | awk '{ print $4 }')"
    }
    read -r occ0 nav0 total0 <<<"$(level "$out/terrain_initial.asc" initial)"
    read -r occ1 nav1 total1 <<<"$(level "$out/terrain_final.asc" final)"
    [ "$total1" = 768 ] || fail "the cropped site has $total1 cells, expected 32 x 24 = 768"
    [ "$occ0" -lt "$total0" ] || fail "the site was level before any construction"
    [ "$occ1" = "$total1" ] || fail "$occ1 of $total1 site cells occupiable at kappa 0.1 on terrain_final.asc"
    [ "$nav1" = "$total1" ] || fail "$nav1 of $total1 site cells connected at kappa 0.1 on terrain_final.asc"
    if [ "$case_name" = site_noisy ]; then
      jq -e '.overrides == ["robot_type.localisation.noise_sd_m=0.1"]' "$s" >/dev/null ||
        { cat "$s"; fail "summary.json does not list the override"; }
    fi
    is_png "$out/goal_vector_map.png" || fail "goal_vector_map.png missing or not a PNG"
    is_png "$out/final.png" || fail "final.png missing or not a PNG"
    echo "ok: $case_name: level at kappa 0.1 after $(field steps "$s") steps ($occ0 of $total0 cells before)," \
      "$(field deposited_volume_m3 "$s") m^3"
    ;;
  three_gaps)
    s=$(run_spawn "$scenarios/path_three_gaps.pbtxt" 3 cyclone)
    expect_completed "$s" 3
    out="$(dirname "$s")"
    # Base (5.125, 5.125) m -> row 39 - 20 = 19, col 20; target (56.125, 5.125) m -> row 19, col 224.
    nav() {
      "$bin/marsala-terrain" navigable --kappa 0.2 --delta 1.5 --eps 0.05 --origin-cell 19 20 "$1" -o "$2" >/dev/null
    }
    nav "$out/terrain_initial.asc" "$work/nav_initial.asc"
    nav "$out/terrain_final.asc" "$work/nav_final.asc"
    [ "$(asc_cell "$work/nav_initial.asc" 19 224)" = "0" ] || fail "the target was navigable before any construction"
    [ "$(asc_cell "$work/nav_final.asc" 19 224)" = "1" ] || fail "no payload path to the target on terrain_final.asc"
    awk -v a="$(asc_cell "$out/terrain_initial.asc" 19 224)" -v b="$(asc_cell "$out/terrain_final.asc" 19 224)" \
      'BEGIN { exit !(b - a <= 0.016 + 1e-9) }' || fail "the target's cell rose more than one cube layer"
    # The sites, independently of the world: along the base-target row, the cliffs are where terrain_initial.asc
    # drops by more than 0.5 m from one cell to the next; the built columns are those where any cell of rows
    # 14..24 (the band) rose. Expected: exactly three runs of built columns, each starting within 0.5 m past a cliff
    # and at most 0.8 / 0.2 + 1 = 5 m long, with unbuilt (natural) ground between them and before the target.
    awk 'FNR <= 6 { next }
         NR == FNR { r = FNR - 7; for (i = 1; i <= NF; i++) h0[r, i - 1] = $i; cols = NF; next }
         { r = FNR - 7; if (r >= 14 && r <= 24) for (i = 1; i <= NF; i++) if ($i - h0[r, i - 1] > 1e-9) built[i - 1] = 1 }
         END {
           n = 0; n_cliffs = 0
           for (c = 0; c + 1 < cols; c++) if (h0[19, c] - h0[19, c + 1] > 0.5) cliff[n_cliffs++] = c + 1
           for (c = 0; c < cols; c++) {
             if (built[c] && !(c > 0 && built[c - 1])) start[n] = c
             if (built[c] && !(c + 1 < cols && built[c + 1])) end[n++] = c
           }
           printf "cliffs at columns"; for (k = 0; k < n_cliffs; k++) printf " %d", cliff[k]; printf "; built runs"
           for (k = 0; k < n; k++) printf " [%d, %d]", start[k], end[k]; printf "\n"
           if (n_cliffs != 3 || n != 3) exit 1
           for (k = 0; k < 3; k++) if (start[k] < cliff[k] || start[k] > cliff[k] + 2 || end[k] - start[k] + 1 > 20) exit 1
           if (end[2] >= 224) exit 1
         }' "$out/terrain_initial.asc" "$out/terrain_final.asc" >"$work/sites.txt" ||
      { cat "$work/sites.txt"; fail "not three separate construction sites, one past each cliff"; }
    # The world's own account (summary.json construction_sites) agrees: three sites, and everything built lies in
    # them (their volumes add up to what was deposited).
    sites_json=$(jq -c '[.construction_sites[] | [.from_m, .to_m, .volume_m3]]' "$s")
    jq -e '(.construction_sites | length) == 3 and
           ((([.construction_sites[].volume_m3] | add) - .deposited_volume_m3) | fabs) < 1e-6' "$s" >/dev/null ||
      fail "summary.json's construction_sites $sites_json: not three sites holding all $(field deposited_volume_m3 "$s") m^3"
    echo "ok: three_gaps: $(cat "$work/sites.txt"); sites along the path (from, to, m^3) $sites_json;" \
      "payload path $(field path_length_m "$s") m after $(field steps "$s") steps, $(field deposited_volume_m3 "$s") m^3"
    ;;
  depositors)
    report=""
    declare -A volume_of
    for kind in layer cube cone; do
      dds=cyclone
      [ "$kind" = cone ] && dds=fastdds
      sed "s/depositor { name: \"layer\" }/depositor { name: \"$kind\" }/" "$scenarios/ramp_depositors.pbtxt" \
        >"$work/ramp_$kind.pbtxt"
      grep -q "name: \"$kind\" }" "$work/ramp_$kind.pbtxt" || fail "could not set the $kind depositor"
      out="$work/run_$kind"
      "$root/deploy/spawn.sh" --scenario "$work/ramp_$kind.pbtxt" --agents 1 --dds "$dds" --domain "$domain" \
        --out "$out" --quiet --timeout 120 >&2 || fail "$kind: spawn.sh failed (logs: $out/logs)"
      s="$out/summary.json"
      [ -f "$s" ] || fail "$kind: no summary.json"
      expect_completed "$s" 1
      awk -v v="$(field deposited_volume_m3 "$s")" '
        FNR <= 6 { next }
        NR == FNR { for (i = 1; i <= NF; i++) h[FNR, i] = $i; next }
        { for (i = 1; i <= NF; i++) { d = $i - h[FNR, i]; if (d < -1e-9) neg++; sum += d } }
        END { sum *= 0.01; if (neg || sum < v - 1e-6 || sum > v + 1e-6) { print "terrain change " sum " m^3, summary " v " m^3, " neg + 0 " cells lowered"; exit 1 } }
      ' "$out/terrain_initial.asc" "$out/terrain_final.asc" || fail "$kind: deposited volume does not match the terrain"
      # Start (2.05, 3.05) m -> row 29, col 20; target (9.05, 3.05) m -> row 29, col 90 (60 rows of 0.1 m).
      for t in initial final; do
        "$bin/marsala-terrain" navigable --kappa 0.3 --delta 1 --eps 0.1 --origin-cell 29 20 "$out/terrain_$t.asc" \
          -o "$work/nav_${kind}_$t.asc" >/dev/null
      done
      [ "$(asc_cell "$work/nav_${kind}_initial.asc" 29 90)" = "0" ] || fail "$kind: the target was navigable before"
      [ "$(asc_cell "$work/nav_${kind}_final.asc" 29 90)" = "1" ] || fail "$kind: the target is not navigable after"
      replayed=$("$bin/marsala-monitor" replay "$out" | awk '/^terrain_sha256/ { print $2 }')
      [ "$replayed" = "$(field terrain_sha256 "$s")" ] ||
        fail "$kind: replay rebuilt terrain $replayed, the run ended on $(field terrain_sha256 "$s")"
      # docs/runtime.md#deposit-bound: no cell above the initial terrain's MARS bound by more than 0.1 eps (0.01 m).
      "$bin/marsala-terrain" mars --kappa 0.3 "$out/terrain_initial.asc" -o "$work/mars_$kind.asc" >/dev/null
      awk 'FNR <= 6 { next } NR == FNR { for (i = 1; i <= NF; i++) b[FNR, i] = $i; next }
           { for (i = 1; i <= NF; i++) if ($i - b[FNR, i] > 0.01 + 1e-9) n++ }
           END { if (n) { print n " cells above the initial MARS bound by more than 0.01 m"; exit 1 } }' \
        "$work/mars_$kind.asc" "$out/terrain_final.asc" || fail "$kind: above the deposit bound"
      case "$kind" in
        cube)
          awk 'FNR <= 6 { next } NR == FNR { for (i = 1; i <= NF; i++) h[FNR, i] = $i; next }
               { for (i = 1; i <= NF; i++) { d = $i - h[FNR, i]; k = d / 0.1
                 if (d > 1e-9 && (k - int(k + 0.5) > 1e-6 || int(k + 0.5) - k > 1e-6)) { n++ } } }
               END { if (n) { print n " cells rose by a fraction of a cube"; exit 1 } }' \
            "$out/terrain_initial.asc" "$out/terrain_final.asc" || fail "cube: not whole cubes"
          ;;
        cone)
          # Every raised cell against its 8 neighbours: at most tan(34 deg) = 0.6745 x distance higher (1e-6 m).
          awk 'FNR <= 6 { next } NR == FNR { for (i = 1; i <= NF; i++) h0[FNR, i] = $i; next }
               { for (i = 1; i <= NF; i++) h[FNR, i] = $i; rows = FNR; cols = NF }
               END { t = 0.674508516842; for (r = 7; r <= rows; r++) for (c = 1; c <= cols; c++) {
                       if (h[r, c] - h0[r, c] <= 1e-9) continue
                       for (dr = -1; dr <= 1; dr++) for (dc = -1; dc <= 1; dc++) {
                         if ((dr || dc) && (r + dr, c + dc) in h) {
                           lim = t * 0.1 * sqrt(dr * dr + dc * dc) + 1e-6
                           if (h[r, c] - h[r + dr, c + dc] > lim) n++ } } }
                     if (n) { print n " raised cells steeper than the angle of repose"; exit 1 } }' \
            "$out/terrain_initial.asc" "$out/terrain_final.asc" || fail "cone: steeper than the angle of repose"
          ;;
      esac
      report="$report $kind: $(field steps "$s") steps, $(field deposited_volume_m3 "$s") m^3;"
      volume_of[$kind]="$(field deposited_volume_m3 "$s")"
    done
    # A ramp, not a heap: the cone's flanks at 34 degrees cost material (the least granular volume holding the 1 m
    # band at the MARS height is 0.64 m^3 here, 1.82 x the layer's), but no more than 1.65 x the layer's volume (it
    # was 1.70 x when piles were judged against the current terrain; 1.62 x now).
    awk -v c="${volume_of[cone]}" -v l="${volume_of[layer]}" 'BEGIN { exit !(c <= 1.65 * l) }' ||
      fail "cone: ${volume_of[cone]} m^3, more than 1.65 x the layer's ${volume_of[layer]} m^3"
    echo "ok: depositors (ramp_depositors, one robot):$report"
    ;;
  shipped)
    name="$3" agents="$4" dds="$5"
    scenario="$root/deploy/scenarios/$name.pbtxt"
    check="$work/check.json"
    if ! "$bin/marsala-world" --check --json "$scenario" >"$check" 2>"$work/check.err"; then
      if grep -q "shared/data" "$work/check.err" && grep -qi "not found\|no such\|cannot open\|missing" "$work/check.err"; then
        echo "SKIP: $name needs a terrain from ../shared/data, absent here: $(head -1 "$work/check.err")"
        exit 77
      fi
      cat "$work/check.err" >&2
      fail "marsala-world --check refuses $name"
    fi
    j() { jq -r "$1" "$check"; }
    scanning_types=$(jq -c '[.robot_types[] | select(.sensor == "laser" or .sensor == "rgbd") | .name]' "$check")
    s=$(run_spawn "$scenario" "$agents" "$dds")
    expect_completed "$s" "$agents"
    out="$(dirname "$s")"
    cs=$(j .terrain.cell_size_m) rows=$(j .terrain.rows) x0=$(j .terrain.x0_m) y0=$(j .terrain.y0_m)
    # Conservation: the summary's volume is the terrain's change, and no cell went down.
    awk -v v="$(field deposited_volume_m3 "$s")" -v area="$(awk -v c="$cs" 'BEGIN { print c * c }')" '
      FNR <= 6 { next }
      NR == FNR { for (i = 1; i <= NF; i++) h[FNR, i] = $i; next }
      { for (i = 1; i <= NF; i++) { d = $i - h[FNR, i]; if (d < -1e-9) neg++; sum += d } }
      END { sum *= area; if (neg || sum < v - 1e-6 || sum > v + 1e-6) { print "terrain change " sum " m^3, summary " v " m^3, " neg + 0 " cells lowered"; exit 1 } }
    ' "$out/terrain_initial.asc" "$out/terrain_final.asc" || fail "deposited volume does not match the terrain"
    cell() {  # cell X Y: "ROW COL" of the cell holding (X, Y) m (row 0 = north)
      awk -v x="$1" -v y="$2" -v x0="$x0" -v y0="$y0" -v c="$cs" -v r="$rows" \
        'BEGIN { printf "%d %d\n", r - 1 - int((y - y0) / c), int((x - x0) / c) }'
    }
    case "$(j .completion)" in
      payload_path)
        read -r fr fc <<<"$(cell "$(j .payload_path.from.x_m)" "$(j .payload_path.from.y_m)")"
        read -r tr tc <<<"$(cell "$(j .payload_path.to.x_m)" "$(j .payload_path.to.y_m)")"
        for t in initial final; do
          "$bin/marsala-terrain" navigable --kappa "$(j .payload_path.kappa)" --delta "$(j .payload_path.delta_m)" \
            --eps "$(j .payload_path.eps_m)" --origin-cell "$fr" "$fc" "$out/terrain_$t.asc" -o "$work/nav_$t.asc" >/dev/null
        done
        [ "$(asc_cell "$work/nav_initial.asc" "$tr" "$tc")" = "0" ] || fail "the target was navigable before any construction"
        [ "$(asc_cell "$work/nav_final.asc" "$tr" "$tc")" = "1" ] ||
          fail "marsala-terrain finds no payload path from base to target on terrain_final.asc"
        # The target on its own ground: its cell at most one cube layer (cube^3 / cs^2 of the largest cube of the
        # robot types) above its initial height.
        layer=$(jq -r --argjson cs "$cs" '[.robot_types[].cube_size_m] | max | . * . * . / ($cs * $cs)' "$check")
        h0=$(asc_cell "$out/terrain_initial.asc" "$tr" "$tc") h1=$(asc_cell "$out/terrain_final.asc" "$tr" "$tc")
        awk -v a="$h0" -v b="$h1" -v q="$layer" 'BEGIN { exit !(b - a <= q + 1e-9) }' ||
          fail "the target's cell rose from $h0 m to $h1 m, more than one cube layer ($layer m)"
        # The basin joined: of the cells navigable from the target on terrain_initial.asc (its own region), at least
        # 90 % are navigable from the base on terrain_final.asc.
        "$bin/marsala-terrain" navigable --kappa "$(j .payload_path.kappa)" --delta "$(j .payload_path.delta_m)" \
          --eps "$(j .payload_path.eps_m)" --origin-cell "$tr" "$tc" "$out/terrain_initial.asc" -o "$work/region.asc" >/dev/null
        joined=$(awk 'FNR <= 6 { next } NR == FNR { for (i = 1; i <= NF; i++) a[FNR, i] = $i; next }
                      { for (i = 1; i <= NF; i++) if (a[FNR, i] == 1) { n++; if ($i == 1) m++ } }
                      END { printf "%d %d\n", m, n }' "$work/region.asc" "$work/nav_final.asc")
        read -r joined_cells region_cells <<<"$joined"
        awk -v m="$joined_cells" -v n="$region_cells" 'BEGIN { exit !(m >= 0.9 * n) }' ||
          fail "only $joined_cells of the target's $region_cells initial region cells are navigable from the base"
        what="payload path from ($fr, $fc) to ($tr, $tc), the target's cell $h0 -> $h1 m, $joined_cells of its region's $region_cells cells joined"
        ;;
      level_site)
        sx0=$(j .site.x0_m) sy0=$(j .site.y0_m)
        w=$(awk -v a="$sx0" -v b="$(j .site.x1_m)" 'BEGIN { print b - a }')
        h=$(awk -v a="$sy0" -v b="$(j .site.y1_m)" 'BEGIN { print b - a }')
        for t in initial final; do
          "$bin/marsala-terrain" import "$out/terrain_$t.asc" --crop "$sx0" "$sy0" "$w" "$h" -o "$work/site_$t.asc" >/dev/null
          occ=$("$bin/marsala-terrain" navigable --occupiable --kappa "$(j .site.kappa)" --delta "$(j .site.delta_m)" \
            --eps "$(j .site.eps_m)" "$work/site_$t.asc" -o "$work/occ_$t.asc")
          read -r n total <<<"$(echo "$occ" | awk '{ print $2, $4 }')"
          eval "occ_$t=$n total_$t=$total"
        done
        [ "$total_final" = "$(j .site.cells)" ] || fail "the cropped site has $total_final cells, the world counts $(j .site.cells)"
        [ "$occ_initial" -lt "$total_initial" ] || fail "the site was level before any construction"
        [ "$occ_final" = "$total_final" ] || fail "$occ_final of $total_final site cells occupiable on terrain_final.asc"
        # All occupiable: connected = navigable from one cell reaches them all.
        nav=$("$bin/marsala-terrain" navigable --kappa "$(j .site.kappa)" --delta "$(j .site.delta_m)" \
          --eps "$(j .site.eps_m)" --origin-cell 0 0 "$work/site_final.asc" -o "$work/nav_site.asc" | awk '{ print $5 }')
        [ "$nav" = "$total_final" ] || fail "$nav of $total_final site cells connected on terrain_final.asc"
        # Robots fill the MARS gap of their own map's window, never more than the terrain's MARS bound at the site's
        # kappa (the shipped sites build at that kappa): no cell rises above it.
        "$bin/marsala-terrain" mars --kappa "$(j .site.kappa)" --gap "$out/terrain_initial.asc" -o "$work/gap.asc" >/dev/null
        awk 'FNR <= 6 { next }
             FILENAME == ARGV[1] { for (i = 1; i <= NF; i++) h0[FNR, i] = $i; next }
             FILENAME == ARGV[2] { for (i = 1; i <= NF; i++) gap[FNR, i] = $i; next }
             { for (i = 1; i <= NF; i++) { over = $i - h0[FNR, i] - gap[FNR, i]; if (over > 1e-6) { n++; v += over } } }
             END { if (n) { printf "%d cells above the MARS bound, %.4f m of excess in all\n", n, v; exit 1 } }' \
          "$out/terrain_initial.asc" "$work/gap.asc" "$out/terrain_final.asc" || fail "deposits above the MARS bound"
        what="site level ($occ_initial of $total_initial cells before), nothing above the MARS bound"
        ;;
      agents_at_goal)
        paste <(agent_fields x_m "$s") <(agent_fields y_m "$s") <(agent_fields z_m "$s") |
          awk -v a="$(j .goal.x0_m)" -v b="$(j .goal.y0_m)" -v c="$(j .goal.x1_m)" -v d="$(j .goal.y1_m)" \
            -v zmin="$(j '.goal.min_height_m // 0')" '
            { n++; if ($1 < a || $1 > c || $2 < b || $2 > d || $3 < zmin - 1e-9) { print "agent " n " ends at (" $1 ", " $2 ", " $3 ")"; bad++ } }
            END { exit bad > 0 }' || fail "an agent ends outside the goal box"
        what="every agent in the goal box"
        radius=$(j '.goal.target_radius_m // 0')
        if awk -v r="$radius" 'BEGIN { exit !(r > 0) }'; then
          # Each robot at its own target, on the final terrain: within the radius of the slot's target, on a cell of
          # terrain_final.asc at least min_height_m high, and that target navigable for the robot's body from its
          # start on terrain_final.asc (it drove there over what was built) and not on terrain_initial.asc.
          zmin=$(j '.goal.min_height_m // 0')
          for i in $(seq 0 $((agents - 1))); do
            x=$(agent_fields x_m "$s" | sed -n "$((i + 1))p") y=$(agent_fields y_m "$s" | sed -n "$((i + 1))p")
            tx=$(j ".slots[$i].target.x_m") ty=$(j ".slots[$i].target.y_m")
            type=$(j ".slots[$i].robot_type")
            awk -v x="$x" -v y="$y" -v tx="$tx" -v ty="$ty" -v r="$radius" \
              'BEGIN { exit !(sqrt((x - tx) ^ 2 + (y - ty) ^ 2) <= r + 1e-9) }' ||
              fail "agent $((i + 1)) ends at ($x, $y), farther than $radius m from its target ($tx, $ty)"
            read -r ar ac <<<"$(cell "$x" "$y")"
            z=$(asc_cell "$out/terrain_final.asc" "$ar" "$ac")
            awk -v z="$z" -v m="$zmin" 'BEGIN { exit !(z >= m - 1e-9) }' ||
              fail "agent $((i + 1)) stands on a cell $z m high on terrain_final.asc, below min_height_m $zmin"
            read -r sr sc <<<"$(cell "$(j ".slots[$i].world_start.x_m")" "$(j ".slots[$i].world_start.y_m")")"
            read -r tr tc <<<"$(cell "$tx" "$ty")"
            body() { j ".robot_types[] | select(.name == \"$type\") | .$1"; }
            for t in initial final; do
              "$bin/marsala-terrain" navigable --kappa "$(body kappa)" --delta "$(body delta_m)" --eps "$(body eps_m)" \
                --origin-cell "$sr" "$sc" "$out/terrain_$t.asc" -o "$work/nav_$t.asc" >/dev/null
            done
            [ "$(asc_cell "$work/nav_initial.asc" "$tr" "$tc")" = "0" ] ||
              fail "agent $((i + 1))'s target was navigable from its start before any construction"
            [ "$(asc_cell "$work/nav_final.asc" "$tr" "$tc")" = "1" ] ||
              fail "agent $((i + 1))'s target is not navigable from its start on terrain_final.asc"
          done
          what="every agent on the goal's top at its own target (within $radius m), reached over what was built"
        fi
        ;;
      *) fail "unknown completion '$(j .completion)'" ;;
    esac
    echo "ok: $name, $agents agents ($dds): $what after $(field steps "$s") steps," \
      "$(field deposited_volume_m3 "$s") m^3, terrain_sha256 $(field terrain_sha256 "$s" | cut -c1-8)"
    ;;
  crowd)
    dds="$3"
    out="$work/run"
    "$root/deploy/spawn.sh" --scenario "$root/deploy/scenarios/crowd_120.pbtxt" --agents 120 --dds "$dds" \
      --domain "$domain" --out "$out" --max-steps 100 --quiet --timeout 600 >&2 && rc=0 || rc=$?
    s="$out/summary.json"
    if [ "$rc" != 3 ]; then
      # The folder goes with the test: show the logs of the processes that ended badly (an abort was seen once).
      grep -l -i -E "terminate|abort|assert|fatal|error|exit" "$out"/logs/*.log 2>/dev/null | head -n 5 |
        while read -r log; do echo "--- $log (last lines)" >&2; tail -n 15 "$log" >&2; done
      fail "spawn.sh exit $rc, expected 3 (max_steps)"
    fi
    top() { jq -r ".$1" "$s"; }  # a top-level field (per_agent entries have some of the same names)
    for f in admitted connected; do
      [ "$(top "$f")" = 120 ] || { cat "$s"; fail "$f: $(top "$f") of 120"; }
    done
    for f in dropped missed_deadlines rejected_requests; do
      [ "$(top "$f")" = 0 ] || { cat "$s"; fail "$f: $(top "$f"), expected 0"; }
    done
    [ "$(top steps)" = 100 ] || fail "steps: $(top steps), expected 100"
    echo "ok: crowd: 120 agents ($dds) admitted and connected in $(top admit_seconds) s, 100 steps," \
      "step median $(top step_wall_median_ms) ms"
    ;;
  sensors)
    # A Cyclone world, Fast DDS agents: the scans cross both vendors' converters. Twice: the same run.
    for k in 1 2; do
      "$root/deploy/spawn.sh" --scenario "$scenarios/slope_sensors.pbtxt" --agents 2 --dds cyclone \
        --agent-dds fastdds --domain "$domain" --out "$work/run$k" --quiet --timeout 120 >&2 ||
        fail "spawn.sh failed (logs: $work/run$k/logs)"
      s="$work/run$k/summary.json"
      expect_completed "$s" 2
      # The slope is navigable as it is: at most a few cubes from the maps' noise (one cube: 0.000125 m^3).
      awk -v v="$(field deposited_volume_m3 "$s")" 'BEGIN { exit !(v <= 0.002) }' ||
        { cat "$s"; fail "the robots built $(field deposited_volume_m3 "$s") m^3 on a navigable slope"; }
      [ "$(agent_fields at_goal "$s" | sort -u)" = "true" ] || { cat "$s"; fail "not every robot at its target"; }
      ! grep -h "ignoring a frame" "$work/run$k"/logs/agent-*.log >&2 || fail "an agent refused a frame"
    done
    [ "$(field steps "$work/run1/summary.json")" = "$(field steps "$work/run2/summary.json")" ] ||
      fail "two runs of the same scenario took $(field steps "$work/run1/summary.json") and" \
        "$(field steps "$work/run2/summary.json") steps"
    echo "ok: sensors: a laser robot and an RGB-D robot climbed to their targets in" \
      "$(field steps "$work/run1/summary.json") steps on maps from their own scans, twice alike"
    ;;
  *) echo "usage: scenario_test.sh path|site|three_gaps|sensors DOMAIN | shipped DOMAIN NAME AGENTS DDS | crowd DOMAIN DDS" >&2; exit 2 ;;
esac
