#!/usr/bin/env bash
# Scalability sweep (paper Fig. 5): runs a scenario as real processes (deploy/spawn.sh, loopback DDS, a fresh domain
# per run) for every team size and seed, collects one CSV row per run, prints a table per team size and plots the
# completion steps and the idle fraction against the team size.
#
# Usage: deploy/sweep.sh [--scenario FILE] [--teams "1 3 5 9 12"] [--seeds N | --seed-list "1 2"] [--out DIR]
#                        [--dds cyclone|fastdds] [--max-steps N] [--timeout S] [--jobs N] [--force] [--no-plot]
#   --scenario   scenario file (default deploy/scenarios/path_gale.pbtxt); needs as many agent slots as the largest team
#   --teams      team sizes (default "1 3 5 9 12")
#   --seeds      seeds 1..N (default 2); --seed-list gives them explicitly (non-negative integers)
#   --out        output folder (default out/sweep): OUT/sweep.csv, OUT/sweep_stats.csv, OUT/sweep.png, OUT/n<T>-s<S>/
#   --dds        DDS vendor of every process (default cyclone)
#   --max-steps  override the scenario's max_steps; --timeout: wall seconds per run (default 1800)
#   --jobs       runs at a time (default 1; more share the cores, so wall times grow)
#   --force      re-run the requested runs and replace their rows; by default a re-run into the same OUT runs only
#                the (team, seed) pairs missing from sweep.csv, so an interrupted sweep resumes
#   --no-plot    skip OUT/sweep.png
# CSV columns: team_size,seed,completed,completion_steps,wall_seconds,deposited_m3,path_length_m,idle_steps,
#              idle_fraction,end_reason (idle_fraction = idle_steps / completion_steps).
# Exit codes: 0 ok, 1 a run failed (no summary) or the binaries are missing, 2 usage error, 130 interrupted.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bin="${MARSALA_BUILD_DIR:-$root/build}/bin"
me="sweep.sh"
readonly csv_header="team_size,seed,completed,completion_steps,wall_seconds,deposited_m3,path_length_m,idle_steps,\
idle_fraction,end_reason"

usage() { sed -n '2,20p' "$0" | sed 's/^# \{0,1\}//'; }
die_usage() { echo "$me: $*" >&2; exit 2; }
die() { echo "$me: $*" >&2; exit 1; }

scenario="$root/deploy/scenarios/path_gale.pbtxt" teams="1 3 5 9 12" seeds_n="" seed_list="" out="$root/out/sweep"
dds="cyclone" max_steps="" timeout_s=1800 jobs=1 force=0 plot=1
while [ $# -gt 0 ]; do
  case "$1" in
    --scenario|--teams|--seeds|--seed-list|--out|--dds|--max-steps|--timeout|--jobs)
      [ $# -ge 2 ] && [[ "$2" != --* ]] || die_usage "$1 needs a value (try --help)"
      case "$1" in
        --scenario) scenario="$2" ;;
        --teams) teams="$2" ;;
        --seeds) seeds_n="$2" ;;
        --seed-list) seed_list="$2" ;;
        --out) out="$2" ;;
        --dds) dds="$2" ;;
        --max-steps) max_steps="$2" ;;
        --timeout) timeout_s="$2" ;;
        --jobs) jobs="$2" ;;
      esac
      shift 2 ;;
    --force) force=1; shift ;;
    --no-plot) plot=0; shift ;;
    -h|--help) usage; exit 0 ;;
    *) die_usage "unknown argument '$1' (try --help)" ;;
  esac
done

# --- arguments -------------------------------------------------------------------------------------------------------
is_uint() { [[ "$1" =~ ^[0-9]+$ ]]; }
is_pos() { [[ "$1" =~ ^[0-9]+$ ]] && [ "$((10#$1))" -ge 1 ]; }

read -r -a team_sizes <<<"$teams"
[ ${#team_sizes[@]} -gt 0 ] || die_usage "--teams needs at least one team size"
max_team=0
for t in "${team_sizes[@]}"; do
  is_pos "$t" && [ ${#t} -le 6 ] || die_usage "--teams: '$t' is not a team size (an integer >= 1)"
done
mapfile -t team_sizes < <(printf '%s\n' "${team_sizes[@]}" | sed 's/^0*//')
[ -z "$(printf '%s\n' "${team_sizes[@]}" | sort -n | uniq -d)" ] ||
  die_usage "--teams lists a team size twice: '$teams'"
for t in "${team_sizes[@]}"; do [ "$t" -gt "$max_team" ] && max_team=$t; done

[ -z "$seeds_n" ] || [ -z "$seed_list" ] || die_usage "give --seeds N or --seed-list \"...\", not both"
if [ -n "$seed_list" ]; then
  read -r -a seeds <<<"$seed_list"
  [ ${#seeds[@]} -gt 0 ] || die_usage "--seed-list needs at least one seed"
  for s in "${seeds[@]}"; do
    is_uint "$s" && [ ${#s} -le 18 ] || die_usage "--seed-list: '$s' is not a seed (a non-negative integer)"
  done
  mapfile -t seeds < <(printf '%s\n' "${seeds[@]}" | sed 's/^0*\([0-9]\)/\1/')
  [ -z "$(printf '%s\n' "${seeds[@]}" | sort -n | uniq -d)" ] ||
    die_usage "--seed-list lists a seed twice: '$seed_list'"
else
  seeds_n="${seeds_n:-2}"
  is_pos "$seeds_n" && [ ${#seeds_n} -le 6 ] || die_usage "--seeds N needs an integer N >= 1, got '$seeds_n'"
  mapfile -t seeds < <(seq 1 "$((10#$seeds_n))")
fi

case "$dds" in cyclone|fastdds) ;; *) die_usage "--dds must be cyclone or fastdds, got '$dds'" ;; esac
[ -z "$max_steps" ] || { is_pos "$max_steps" && [ ${#max_steps} -le 12 ]; } ||
  die_usage "--max-steps N needs an integer N >= 1, got '$max_steps'"
is_pos "$timeout_s" && [ ${#timeout_s} -le 7 ] || die_usage "--timeout S needs whole seconds >= 1, got '$timeout_s'"
is_pos "$jobs" && [ "$jobs" -le 64 ] || die_usage "--jobs N needs an integer in [1, 64], got '$jobs'"
[ -n "$out" ] || die_usage "--out needs a folder"
timeout_s=$((10#$timeout_s)) jobs=$((10#$jobs))
[ -z "$max_steps" ] || max_steps=$((10#$max_steps))

[ -f "$scenario" ] || die_usage "scenario file '$scenario' not found"
scenario="$(cd "$(dirname "$scenario")" && pwd)/$(basename "$scenario")"

for b in marsala-world marsala-agent; do
  [ -x "$bin/$b" ] || die "$bin/$b not built (run deploy/build.sh)"
done

# Agent slots, as the world reads them (marsala-world --check validates the whole scenario first).
check_json="$("$bin/marsala-world" --check --json "$scenario")" || die_usage "scenario '$scenario' is not valid (see above)"
slots="$(jq '.slots | length' <<<"$check_json")"
[ "$slots" -ge "$max_team" ] ||
  die_usage "scenario '$scenario' has $slots agent slots, fewer than the largest team ($max_team); use smaller --teams"
[ -x "$root/deploy/spawn.sh" ] || die "$root/deploy/spawn.sh missing or not executable"
command -v jq >/dev/null || die "jq is not installed (deploy/install-deps.sh, or apt-get install jq)"

# Seeds reach the processes only where both programs take --seed; otherwise every seed repeats the same run.
pass_seed=1
for b in marsala-world marsala-agent; do
  help_text="$("$bin/$b" --help 2>&1 || true)"
  [[ "$help_text" == *--seed* ]] || pass_seed=0
done
[ "$pass_seed" -eq 1 ] ||
  echo "$me: note: this build's marsala-world/marsala-agent take no --seed: every seed repeats the same run" >&2

# --- the output folder --------------------------------------------------------------------------------------------
mkdir -p "$out"
out="$(cd "$out" && pwd)"
csv="$out/sweep.csv"
conf="$out/sweep.conf"
# What makes rows comparable: a re-run into the same OUT with other settings would mix incomparable rows.
conf_text="scenario=$scenario
scenario_sha256=$(sha256sum "$scenario" | cut -d' ' -f1)
dds=$dds
max_steps=${max_steps:-scenario}
seeds_passed=$pass_seed"
if [ -f "$csv" ] && [ -f "$conf" ] && [ "$(cat "$conf")" != "$conf_text" ]; then
  if [ "$force" -eq 0 ]; then
    echo "$me: $out holds a sweep with other settings:" >&2
    { diff <(cat "$conf") <(echo "$conf_text") || true; } | sed -n 's/^</  there:/p; s/^>/  now:  /p' >&2
    die_usage "use another --out, or --force to start over (the old CSV is kept as sweep.csv.old)"
  fi
  mv -f "$csv" "$csv.old"
fi
if [ -f "$csv" ] && [ "$(head -n 1 "$csv")" != "$csv_header" ]; then
  die_usage "$csv does not start with the sweep header; use another --out"
fi
[ -f "$csv" ] || echo "$csv_header" >"$csv"
echo "$conf_text" >"$conf"

has_row() { awk -F, -v t="$1" -v s="$2" 'NR > 1 && $1 == t && $2 == s { found = 1 } END { exit !found }' "$csv"; }

# Puts the row of (team, seed) in place of an older one, rows sorted by team and seed; the CSV is written whole to a
# temporary file, then renamed, so an interrupted sweep never leaves a partial row.
put_row() {
  local team="$1" seed="$2" row="$3" tmp="$csv.tmp.$$"
  {
    echo "$csv_header"
    { awk -F, -v t="$team" -v s="$seed" 'NR > 1 && !($1 == t && $2 == s)' "$csv"; echo "$row"; } |
      sort -t, -k1,1n -k2,2n
  } >"$tmp"
  mv -f "$tmp" "$csv"
}

# --- runs -------------------------------------------------------------------------------------------------------------
todo=()
for t in "${team_sizes[@]}"; do
  for s in "${seeds[@]}"; do
    if [ "$force" -eq 1 ] || ! has_row "$t" "$s"; then todo+=("$t:$s"); fi
  done
done
total=$(( ${#team_sizes[@]} * ${#seeds[@]} ))
echo "$me: $(basename "$scenario") ($slots slots), teams ${team_sizes[*]}, seeds ${seeds[*]}, $dds;" \
  "${#todo[@]} of $total runs to do; CSV $csv"
[ "$jobs" -eq 1 ] || echo "$me: $jobs runs at a time share the cores: wall times are not comparable to --jobs 1" >&2

running=()        # "pid:team:seed" of the spawn.sh processes under way
failed=0
domain_offset=$(( $$ % 160 ))
run_index=0

stop_runs() {
  local job
  for job in ${running[@]+"${running[@]}"}; do kill -TERM "${job%%:*}" 2>/dev/null || true; done
  for job in ${running[@]+"${running[@]}"}; do wait "${job%%:*}" 2>/dev/null || true; done
  running=()
}
on_interrupt() {
  trap - INT TERM
  echo "$me: interrupted; stopping ${#running[@]} run(s) under way (their rows are not written)" >&2
  stop_runs
  rm -f "$csv.tmp.$$"
  echo "$me: $(($(wc -l <"$csv") - 1)) rows in $csv; the same command resumes the sweep" >&2
  exit 130
}
trap on_interrupt INT TERM
trap 'stop_runs; rm -f "$csv.tmp.$$"' EXIT

start_run() {
  local team="$1" seed="$2"
  local dir="$out/n$team-s$seed"
  rm -rf "$dir"
  mkdir -p "$dir"
  # A fresh domain per run, 20..179 (ctest's runtime cases use 200 and up): concurrent runs never share one, nor
  # does a run share its predecessor's.
  local domain=$(( 20 + (domain_offset + run_index) % 160 ))
  run_index=$((run_index + 1))
  local args=(--scenario "$scenario" --agents "$team" --dds "$dds" --domain "$domain" --out "$dir" --quiet
              --timeout "$timeout_s")
  [ -z "$max_steps" ] || args+=(--max-steps "$max_steps")
  [ "$pass_seed" -eq 0 ] || args+=(--seed "$seed")
  "$root/deploy/spawn.sh" "${args[@]}" >"$dir/spawn.log" 2>&1 &
  running+=("$!:$team:$seed")
}

# Reads a finished run's summary.json into a CSV row and prints the run's line.
finish_run() {
  local team="$1" seed="$2" rc="$3"
  local dir="$out/n$team-s$seed"
  local summary="$dir/summary.json"
  if [ "$rc" -ne 0 ] || [ ! -f "$summary" ]; then
    echo "  team $team, seed $seed: FAILED (spawn.sh exit $rc, no row written; see $dir/spawn.log and $dir/logs)"
    tail -n 5 "$dir/spawn.log" 2>/dev/null | sed 's/^/    /'
    failed=$((failed + 1))
    return
  fi
  # Fields a build may not have yet (idle_steps, path_length_m) read as 0.
  local values
  values="$(jq -r '[(.completed // false), (.steps // 0 | tonumber), (.wall_seconds // 0 | tonumber),
                    (.deposited_volume_m3 // 0 | tonumber), (.path_length_m // 0 | tonumber),
                    (.idle_steps // 0 | tonumber), (.end_reason // "" | gsub("[,\\s]"; "_"))] | @tsv' "$summary")" ||
    { echo "  team $team, seed $seed: FAILED (unreadable $summary)"; failed=$((failed + 1)); return; }
  local completed steps wall volume path idle reason
  IFS=$'\t' read -r completed steps wall volume path idle reason <<<"$values"
  grep -q "no end after" "$dir/spawn.log" && reason="timeout"
  local idle_fraction
  idle_fraction="$(awk -v i="$idle" -v s="$steps" 'BEGIN { printf "%.6f", (s > 0 ? i / s : 0) }')"
  put_row "$team" "$seed" "$team,$seed,$completed,$steps,$wall,$volume,$path,$idle,$idle_fraction,$reason"
  local state="completed"
  [ "$completed" = "true" ] || state="NOT completed ($reason)"
  printf '  team %3d, seed %s: %s in %d steps, %.2f s wall, %.3f m^3 deposited, idle %.1f%%\n' \
    "$team" "$seed" "$state" "$steps" "$wall" "$volume" "$(awk -v f="$idle_fraction" 'BEGIN { print 100 * f }')"
}

next=0
while [ "$next" -lt ${#todo[@]} ] || [ ${#running[@]} -gt 0 ]; do
  while [ "$next" -lt ${#todo[@]} ] && [ ${#running[@]} -lt "$jobs" ]; do
    start_run "${todo[$next]%%:*}" "${todo[$next]#*:}"
    next=$((next + 1))
  done
  still=()
  for job in "${running[@]}"; do
    pid="${job%%:*}" rest="${job#*:}"
    if kill -0 "$pid" 2>/dev/null; then still+=("$job"); continue; fi
    rc=0
    wait "$pid" || rc=$?
    finish_run "${rest%%:*}" "${rest#*:}" "$rc"
  done
  running=(${still[@]+"${still[@]}"})
  if [ ${#running[@]} -ge "$jobs" ] || { [ "$next" -ge ${#todo[@]} ] && [ ${#running[@]} -gt 0 ]; }; then
    sleep 0.2 & wait $! || true   # wait (not a bare sleep) lets Ctrl-C reach the trap at once
  fi
done

# --- table and plot ---------------------------------------------------------------------------------------------------
# Per team size over the completed runs: runs, completed, mean/min/max of steps, wall seconds and idle fraction.
stats="$out/sweep_stats.csv"
awk -F, '
  NR == 1 { next }
  {
    t = $1 + 0; runs[t]++
    if ($3 != "true") next
    n[t]++
    for (k = 0; k < 3; k++) {
      v = (k == 0 ? $4 : (k == 1 ? $5 : $9)) + 0
      sum[t, k] += v
      if (n[t] == 1 || v < lo[t, k]) lo[t, k] = v
      if (n[t] == 1 || v > hi[t, k]) hi[t, k] = v
    }
  }
  END {
    print "# team_size,runs,completed,steps_mean,steps_min,steps_max,wall_mean,wall_min,wall_max,idle_mean,idle_min," \
          "idle_max"
    for (t in runs) {
      line = sprintf("%d,%d,%d", t, runs[t], n[t] + 0)
      for (k = 0; k < 3; k++)
        line = line (n[t] ? sprintf(",%.6g,%.6g,%.6g", sum[t, k] / n[t], lo[t, k], hi[t, k]) : ",NaN,NaN,NaN")
      print line
    }
  }' "$csv" | { read -r head; echo "$head"; sort -t, -k1,1n; } >"$stats"

echo
echo "Completion per team size (completed runs; all rows of $csv):"
awk -F, 'NR == 1 {
       printf "%5s %9s  %10s %8s %8s  %8s %8s %8s  %6s\n", "team", "completed", "steps mean", "min", "max",
              "wall [s]", "min", "max", "idle"
       next }
     $3 == 0 { printf "%5d %5d/%-3d  %10s\n", $1, $3, $2, "-"; next }
     { printf "%5d %5d/%-3d  %10.1f %8d %8d  %8.2f %8.2f %8.2f  %5.1f%%\n",
              $1, $3, $2, $4, $5, $6, $7, $8, $9, 100 * $10 }' "$stats"

if [ "$plot" -eq 1 ]; then
  if ! command -v gnuplot >/dev/null; then
    echo "$me: note: gnuplot is not installed (deploy/install-deps.sh or apt-get install gnuplot-nox): no sweep.png"
  elif [ "$(wc -l <"$csv")" -lt 2 ]; then
    echo "$me: note: no rows yet, no plot"
  else
    title="$(basename "${scenario%.*}"), $dds, $(($(wc -l <"$csv") - 1)) runs"
    if gnuplot -c "$root/deploy/plot_sweep.gp" "$csv" "$stats" "$out/sweep.png" "$title" >"$out/plot.log" 2>&1; then
      echo "Plot: $out/sweep.png"
    else
      echo "$me: gnuplot failed (see $out/plot.log)" >&2
      failed=$((failed + 1))
    fi
  fi
fi

if [ "$failed" -gt 0 ]; then
  echo "$me: $failed run(s) failed and have no row; the same command retries them" >&2
  exit 1
fi
