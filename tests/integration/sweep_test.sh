#!/usr/bin/env bash
# deploy/sweep.sh (deploy/marsala_tools/sweep.py) end to end: bad arguments and a scenario marsala-world --check
# rejects, the per-team aggregation on a hand-made CSV, a real two-run sweep of the ramp scenario (teams 1 and 2, one
# seed), a re-run that appends nothing, a resume after a lost row, a sweep stopped mid-run, and the plot. ctest runs it
# inside run_isolated.sh (a private network namespace with only lo, when permitted); the sweep runs its processes
# through spawn.sh with the loopback DDS configs.
#
# Usage: sweep_test.sh
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
sweep="$root/deploy/sweep.sh"
scenario="$root/deploy/scenarios/ramp.pbtxt"
header="team_size,seed,completed,completion_steps,wall_seconds,deposited_m3,path_length_m,idle_steps,"
header+="idle_fraction,end_reason,sites,site_spans_m,material_deposited_m3,material_needed_m3,material_ratio,"
header+="material_off_band_m3"

work="$(mktemp -d "${TMPDIR:-/tmp}/marsala-it-sweep.XXXXXX")"
trap 'rm -rf "$work"' EXIT

fail() { echo "FAIL (sweep): $*" >&2; exit 1; }
. "$root/tests/integration/lib.sh"  # field, is_png
csv_field() {  # csv_field CSV TEAM SEED COLUMN: one value of the row of (team, seed)
  awk -F, -v t="$2" -v s="$3" -v c="$4" 'NR > 1 && $1 == t && $2 == s { print $c }' "$1"
}

# --- 1. bad arguments: exit 2, a message that names the problem, nothing written --------------------------------
expect_usage_error() {  # expect_usage_error PATTERN ARGS...
  local pattern="$1" rc=0
  shift
  "$sweep" --out "$work/bad" "$@" >"$work/stdout.txt" 2>"$work/stderr.txt" || rc=$?
  [ "$rc" -eq 2 ] || { cat "$work/stderr.txt"; fail "sweep.sh $* exited $rc, expected 2"; }
  grep -q -- "$pattern" "$work/stderr.txt" || { cat "$work/stderr.txt"; fail "sweep.sh $*: no '$pattern' message"; }
  [ ! -e "$work/bad" ] || fail "sweep.sh $* wrote $work/bad despite the usage error"
}
expect_usage_error "unrecognized arguments: --bogus" --scenario "$scenario" --bogus
expect_usage_error "argument --teams: expected one argument" --scenario "$scenario" --teams
expect_usage_error "'x' is not a team size" --scenario "$scenario" --teams "1 x"
expect_usage_error "'0' is not a team size" --scenario "$scenario" --teams "0 1"
expect_usage_error "lists a team size twice" --scenario "$scenario" --teams "2 1 2"
expect_usage_error "has 3 agent slots, fewer than the largest team (4)" --scenario "$scenario" --teams "1 4"
expect_usage_error "argument --seeds: '0' is not an integer" --scenario "$scenario" --seeds 0
expect_usage_error "not allowed with argument --seeds" --scenario "$scenario" --seeds 2 --seed-list "1 2"
expect_usage_error "'-3' is not a seed" --scenario "$scenario" --seed-list "1 -3"
expect_usage_error "invalid choice: 'opensplice'" --scenario "$scenario" --dds opensplice
expect_usage_error "argument --max-steps: '1.5' is not an integer" --scenario "$scenario" --max-steps 1.5
expect_usage_error "argument --jobs: '0' is not an integer in \[1, 64\]" --scenario "$scenario" --jobs 0
expect_usage_error "not found" --scenario "$work/none.pbtxt"
# A scenario the world would reject: exit 2 with marsala-world --check's message (file and field), nothing started.
sed 's/robot_type: "husky" start { x_m: 5.05 y_m: 10.05 }/robot_type: "rover" start { x_m: 5.05 y_m: 10.05 }/' \
  "$scenario" >"$work/rover.pbtxt"
expect_usage_error "scenario $work/rover.pbtxt: agent\[1\] (agent 2).robot_type: unknown robot type 'rover'" \
  --scenario "$work/rover.pbtxt" --teams 1
echo "ok: 14 bad argument lists exit 2 with their message"

# --- 2. aggregation on a hand-made CSV (no runs: every pair is there) ---------------------------------------------
# team 1: steps 100 and 140, idle 50 and 28 -> mean 120 [100, 140], idle fractions 0.5 and 0.2 -> 0.35 [0.2, 0.5];
# team 3: one completed run (60 steps, idle 0) and one that hit max_steps, which stays out of the means.
hand="$work/hand"
mkdir -p "$hand"
cat >"$hand/sweep.csv" <<EOF
$header
1,1,true,100,2.0,4,0,50,0.500000,completed,0,
1,2,true,140,3.0,4,0,28,0.200000,completed,0,
3,1,true,60,1.5,12,0,0,0.000000,completed,1,0.0-2.5
3,2,false,4000,9.5,7,0,900,0.225000,max_steps,0,
EOF
cp "$hand/sweep.csv" "$work/hand.csv"
"$sweep" --scenario "$scenario" --teams "1 3" --seeds 2 --out "$hand" >"$work/hand.txt" 2>&1 ||
  { cat "$work/hand.txt"; fail "sweep.sh on a complete hand-made CSV failed"; }
grep -q "0 of 4 runs to do" "$work/hand.txt" || { cat "$work/hand.txt"; fail "it started runs for pairs it had"; }
cmp -s "$hand/sweep.csv" "$work/hand.csv" || fail "a sweep with nothing to do changed the CSV"
stats_row() { grep "^$1," "$hand/sweep_stats.csv" | cut -d, -f1-12; }
[ "$(stats_row 1)" = "1,2,2,120,100,140,2.5,2,3,0.35,0.2,0.5" ] || fail "team 1 stats: $(stats_row 1)"
[ "$(stats_row 3)" = "3,2,1,60,60,60,1.5,1.5,1.5,0,0,0" ] || fail "team 3 stats: $(stats_row 3)"
grep -Eq '^ +1 +2/2 +120\.0 +100 +140 +2\.50 +2\.00 +3\.00 +35\.0%' "$work/hand.txt" ||
  { cat "$work/hand.txt"; fail "no table line for team 1"; }
grep -Eq '^ +3 +1/2 +60\.0 ' "$work/hand.txt" || { cat "$work/hand.txt"; fail "no table line for team 3"; }
echo "ok: per-team means, minima and maxima of a hand-made CSV (incomplete runs left out)"

# --- 3. a real sweep: ramp scenario, teams 1 and 2, one seed --------------------------------------------------------
out="$work/sweep"
"$sweep" --scenario "$scenario" --teams "1 2" --seeds 1 --out "$out" --timeout 300 >"$work/sweep1.txt" 2>&1 ||
  { cat "$work/sweep1.txt"; fail "the sweep failed"; }
csv="$out/sweep.csv"
[ -f "$csv" ] || fail "no $csv"
[ "$(head -n 1 "$csv")" = "$header" ] || fail "header is '$(head -n 1 "$csv")'"
[ "$(wc -l <"$csv")" -eq 3 ] || { cat "$csv"; fail "expected the header and 2 rows"; }
for team in 1 2; do
  s="$out/n$team-s1/summary.json"
  [ -f "$s" ] || fail "no summary for team $team"
  [ "$(csv_field "$csv" "$team" 1 3)" = "true" ] || { cat "$csv"; fail "team $team did not complete"; }
  [ "$(csv_field "$csv" "$team" 1 10)" = "completed" ] || { cat "$csv"; fail "team $team end_reason"; }
  [ "$(field agents "$s")" = "$team" ] || fail "the run of team $team had $(field agents "$s") agents"
  # The row holds what the world wrote, and the numbers are plausible.
  steps=$(csv_field "$csv" "$team" 1 4)
  [ "$steps" = "$(field steps "$s")" ] || fail "team $team: CSV steps $steps, summary $(field steps "$s")"
  awk -v v="$(csv_field "$csv" "$team" 1 6)" -v w="$(field deposited_volume_m3 "$s")" 'BEGIN { exit !(v == w) }' ||
    fail "team $team: CSV volume differs from the summary"
  awk -F, -v t="$team" 'NR > 1 && $1 == t {
        ok = NF == 16 && $4 > 0 && $5 > 0 && $5 < 300 && $6 > 0 && $8 >= 0 && $8 <= $4 && $9 >= 0 && $9 <= 1 &&
             ($9 - $8 / $4) ^ 2 < 1e-10 && $11 == 0 && $12 == "" &&  # a ramp run has no construction sites
             ($13 - $6) ^ 2 < 1e-10 && $14 > 0 && ($15 - $13 / $14) ^ 2 < 1e-8 && $16 >= 0  # the material score
        exit !ok }' "$csv" || { cat "$csv"; fail "implausible row for team $team"; }
  grep -Eq "team +$team, seed 1: completed in $steps steps" "$work/sweep1.txt" ||
    { cat "$work/sweep1.txt"; fail "no run line for team $team"; }
done
grep -Eq '^ +2 +1/1 ' "$work/sweep1.txt" || { cat "$work/sweep1.txt"; fail "no table line for team 2"; }
echo "ok: two runs, two rows: $(tail -n 2 "$csv" | tr '\n' ' ')"

if command -v gnuplot >/dev/null; then
  [ -s "$out/sweep.png" ] && is_png "$out/sweep.png" || fail "no PNG at $out/sweep.png ($(cat "$out/plot.log" 2>&1))"
  [ -s "$hand/sweep.png" ] && is_png "$hand/sweep.png" || fail "no PNG for the hand-made CSV (an incomplete run)"
  echo "ok: sweep.png written"
else
  grep -q "gnuplot is not installed" "$work/sweep1.txt" || fail "no note about the missing gnuplot"
  echo "skipped: gnuplot is not installed, no plot to check"
fi

# --- 4. a re-run appends nothing; a lost row is run again -------------------------------------------------------
cp "$csv" "$work/sweep1.csv"
"$sweep" --scenario "$scenario" --teams "1 2" --seeds 1 --out "$out" >"$work/sweep2.txt" 2>&1 ||
  { cat "$work/sweep2.txt"; fail "the re-run failed"; }
grep -q "0 of 2 runs to do" "$work/sweep2.txt" || { cat "$work/sweep2.txt"; fail "the re-run started runs"; }
cmp -s "$csv" "$work/sweep1.csv" || { diff "$work/sweep1.csv" "$csv"; fail "the re-run changed the CSV"; }

grep -v '^2,1,' "$work/sweep1.csv" >"$csv"
"$sweep" --scenario "$scenario" --teams "1 2" --seeds 1 --out "$out" --no-plot >"$work/sweep3.txt" 2>&1 ||
  { cat "$work/sweep3.txt"; fail "the resume failed"; }
grep -q "1 of 2 runs to do" "$work/sweep3.txt" || { cat "$work/sweep3.txt"; fail "the resume ran other than 1 run"; }
[ "$(wc -l <"$csv")" -eq 3 ] || { cat "$csv"; fail "after the resume: expected 2 rows"; }
[ "$(sed -n 2p "$csv")" = "$(sed -n 2p "$work/sweep1.csv")" ] || fail "the resume changed the row of team 1"
[ "$(csv_field "$csv" 2 1 4)" = "$(csv_field "$work/sweep1.csv" 2 1 4)" ] || fail "team 2 ran again in other steps"
echo "ok: a re-run appends nothing, a resume runs only the missing pair"

# --- 5. stopped mid-run: exit 130, the CSV keeps whole rows only, no process of the run is left ------------------
rm -rf "$out/n1-s1"   # its world.log below says the forced run has started
"$sweep" --scenario "$scenario" --teams "1 2" --seeds 1 --out "$out" --force --no-plot >"$work/sweep4.txt" 2>&1 &
sweep_pid=$!
for _ in $(seq 1 500); do [ -f "$out/n1-s1/logs/world.log" ] && break; sleep 0.02; done
[ -f "$out/n1-s1/logs/world.log" ] || { kill -TERM "$sweep_pid"; fail "the forced sweep never started its run"; }
kill -TERM "$sweep_pid"
rc=0
wait "$sweep_pid" || rc=$?
[ "$rc" -eq 130 ] || { cat "$work/sweep4.txt"; fail "a stopped sweep exited $rc, expected 130"; }
grep -q "the same command resumes" "$work/sweep4.txt" || { cat "$work/sweep4.txt"; fail "no resume hint"; }
[ "$(head -n 1 "$csv")" = "$header" ] || fail "the header is gone after the stop"
awk -F, 'NR > 1 && NF != 16 { bad = 1 } END { exit bad }' "$csv" || { cat "$csv"; fail "a partial row after the stop"; }
[ "$(wc -l <"$csv")" -eq 3 ] || { cat "$csv"; fail "rows lost or added by the stop"; }
ls "$out"/sweep.csv.tmp.* >/dev/null 2>&1 && fail "a temporary CSV was left behind"
# The run was stopped, not waited for: its world ended early (on the signal) or wrote no summary at all.
if [ -f "$out/n1-s1/summary.json" ]; then
  [ "$(field end_reason "$out/n1-s1/summary.json")" != "completed" ] || fail "the stop let the run finish"
fi
# Every process of the run had a log of the run folder open (the world and the agents write into logs/).
holders() {
  local fd
  for fd in /proc/[0-9]*/fd/*; do
    case "$(readlink "$fd" 2>/dev/null)" in "$out"/n1-s1/*) echo "${fd#/proc/}" | cut -d/ -f1 ;; esac
  done | sort -u
}
left=""
for _ in $(seq 1 20); do left="$(holders)"; [ -z "$left" ] && break; sleep 0.1; done
[ -z "$left" ] || fail "processes of the stopped run are still alive: $left"
echo "ok: a stopped sweep exits 130 and leaves a whole CSV and no process behind"
