#pragma once
// Cyclone DDS's log, bounded (docs/runtime.md#foreign-types): Cyclone writes a line to stderr for every sample it
// cannot deserialize, so a foreign type of a MARSala type's name on a topic (or any undecodable flood) grew a
// world's log by hundreds of MB. From the first participant on, its log (info, warning, error, fatal; never its
// trace) still goes to stderr as before, but each kind of message only at its 1st, 10th, 100th ... occurrence, with
// the count so far.

namespace marsala::bus::cyclone {

/// Installs the bounded log sink, once per process (later calls do nothing).
void bound_cyclone_log();

}  // namespace marsala::bus::cyclone
