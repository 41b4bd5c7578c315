#pragma once
// The short account of a finished run for people, from its output folder: whether it completed and why not, steps,
// wall time, volume, progress, and where the pictures are. `marsala-monitor summary DIR` prints it and
// deploy/spawn.sh shows it at the end of a run; summary.json stays the complete record.
//
//   path_generated completed after 1460 steps in 3.6 s (admission 0.4 s)
//     agents 5 (5 admitted, 0 dropped), 21.241 m3 deposited, payload path 26.2 m
//     progress 100.0 %: the payload's path is navigable
//     pictures in /tmp/run: final.png, final_zoom.png, final_3d.png
//     everything else in /tmp/run: summary.json, events.log, run.log, logs/

#include <string>

namespace marsala::monitor {

/// The account of the run in `dir`, read from dir/summary.json (and the pictures in dir). Throws Error when the file
/// is missing or is not a run summary (naming the file).
std::string run_report(const std::string& dir);

}  // namespace marsala::monitor
