# The scalability plot of deploy/sweep.sh (paper Fig. 5): completion steps against team size (top) and the idle
# fraction, steps in which no robot deposited (bottom). Each panel: the mean over the completed runs as a line with
# min-max error bars, every seed as a point, runs that did not complete as open red circles at the step they ended.
#
# Usage: gnuplot -c deploy/plot_sweep.gp SWEEP_CSV SWEEP_STATS OUT_PNG [TITLE]
#   SWEEP_CSV    OUT/sweep.csv (team_size,seed,completed,completion_steps,wall_seconds,deposited_m3,path_length_m,
#                idle_steps,idle_fraction,end_reason)
#   SWEEP_STATS  OUT/sweep_stats.csv (team_size,runs,completed,steps_mean,steps_min,steps_max,wall_mean,wall_min,
#                wall_max,idle_mean,idle_min,idle_max after a `#` header line; NaN where a team has no completed run)
if (ARGC < 3) { print "usage: gnuplot -c plot_sweep.gp SWEEP_CSV SWEEP_STATS OUT_PNG [TITLE]"; exit status 2 }
csv = ARG1
stats_file = ARG2
title_text = (ARGC >= 4) ? ARG4 : "scalability sweep"

if (strstrt(GPVAL_TERMINALS, "pngcairo") > 0) {
  set terminal pngcairo size 900,900 noenhanced font "sans,11"
} else {
  set terminal png size 900,900 noenhanced
}
set output ARG3

set datafile separator ","
completed(col) = (strcol(3) eq "true") ? column(col) : NaN
not_completed(col) = (strcol(3) eq "true") ? NaN : column(col)
stats csv every ::1 using (strcol(3) eq "true" ? 1 : 0) nooutput
n_completed = STATS_sum
n_open = STATS_records - STATS_sum
stats csv every ::1 using 1 nooutput
team_lo = STATS_min
team_hi = STATS_max

set xrange [team_lo - 0.6 : team_hi + 0.6]
set xlabel "team size [robots]"
set grid ytics lc rgb "#dddddd"
set key bmargin center horizontal
set lmargin 12
set bars 2
set offsets 0, 0, graph 0.08, 0
set style line 1 lc rgb "#1f5fa8" lw 2 pt 7 ps 1.2
set style line 2 lc rgb "#777777" pt 7 ps 0.7
set style line 3 lc rgb "#c0392b" pt 6 ps 1.4 lw 1.5

set multiplot layout 2, 1 title title_text font ",13"

set ylabel "completion [steps]"
set yrange [0 : *]
if (n_completed > 0 && n_open > 0) {
  plot stats_file using 1:4:5:6:xtic(1) with yerrorlines ls 1 title "mean, min-max (completed)", \
       csv every ::1 using 1:(completed(4)) with points ls 2 title "one seed", \
       csv every ::1 using 1:(not_completed(4)) with points ls 3 title "not completed (step it ended)"
} else {
  if (n_completed > 0) {
    plot stats_file using 1:4:5:6:xtic(1) with yerrorlines ls 1 title "mean, min-max (completed)", \
         csv every ::1 using 1:(completed(4)) with points ls 2 title "one seed"
  } else {
    plot csv every ::1 using 1:(not_completed(4)):xtic(1) with points ls 3 title "not completed (step it ended)"
  }
}

set ylabel "idle fraction [% of steps without a deposition]"
set yrange [0 : *]
if (n_completed > 0) {
  plot stats_file using 1:(100 * $10):(100 * $11):(100 * $12):xtic(1) with yerrorlines ls 1 \
         title "mean, min-max (completed)", \
       csv every ::1 using 1:(100 * completed(9)) with points ls 2 title "one seed"
} else {
  plot csv every ::1 using 1:(100 * not_completed(9)):xtic(1) with points ls 3 title "not completed"
}
unset multiplot
unset output
