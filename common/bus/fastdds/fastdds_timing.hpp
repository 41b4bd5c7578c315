#pragma once
// Reliability timing of the Fast DDS endpoints (docs/runtime.md#lossy-links): how fast a lost sample is repaired.
// The shipped profiles set it in their default <data_writer> / <data_reader>; a profile that leaves Fast DDS's
// defaults gets the same values from here.

#include <chrono>
#include <string>

namespace eprosima::fastrtps::rtps {
struct WriterTimes;
struct ReaderTimes;
}  // namespace eprosima::fastrtps::rtps

namespace marsala::bus::fastdds {

/// Heartbeat period of a reliable writer whose profile leaves Fast DDS's default (3 s) [ms].
inline constexpr std::chrono::milliseconds kRepairHeartbeat{50};

/// A writer's timing: the profile's when it sets a heartbeat period, else kRepairHeartbeat and repairs at once.
void fast_repair(eprosima::fastrtps::rtps::WriterTimes& times);
/// A reader's timing: the profile's when it sets a heartbeat response delay, else answers heartbeats at once.
void fast_repair(eprosima::fastrtps::rtps::ReaderTimes& times);

/// A writer that serves one reader heartbeats this many times as often as the profile's period [count]: the
/// profile's period is the one of a writer that serves the team (the world's status, events and admissions, read by
/// every agent and monitor, and an agent's hellos); the writers in an agent's partition serve one reader: the agent's
/// requests the world, the world's frames (the critical path of every step) that agent.
inline constexpr int kOneReaderHeartbeatDivisor = 10;
/// The shortest heartbeat period follow_team() gives [ms].
inline constexpr std::chrono::milliseconds kShortestHeartbeat{5};

/// Heartbeat period of a writer [ns] under the profile's (or fast_repair's) period `period_ns` [ns]: as it is for a
/// writer that serves the team (`serves_team`), else (one reader) divided by kOneReaderHeartbeatDivisor but not below
/// kShortestHeartbeat nor above `period_ns` (docs/runtime.md#lossy-links).
long long team_heartbeat_ns(long long period_ns, bool serves_team);
/// Sets `times`' heartbeat period to team_heartbeat_ns() of it.
void follow_team(eprosima::fastrtps::rtps::WriterTimes& times, bool serves_team);

/// The reliability timing endpoints get [ns].
struct RepairTiming {
  long long heartbeat_period_ns = 0;          ///< writer serving the team: heartbeat period while a reader lags [ns]
  long long one_reader_heartbeat_ns = 0;      ///< a writer serving one reader: its heartbeat period [ns]
  long long nack_response_delay_ns = 0;       ///< writer: wait before repairing what a reader asked for [ns]
  long long heartbeat_response_delay_ns = 0;  ///< reader: wait before answering a heartbeat [ns]
  bool from_profile = false;  ///< the profile set both the writer's and the reader's timing (fast_repair left them)
};

/// The timing endpoints get under the Fast DDS profile file `path` (its default data writer and reader, as Fast DDS
/// parses them, then fast_repair). Throws InvalidArgument naming the file when Fast DDS cannot load it.
RepairTiming repair_timing_of_profile(const std::string& path);

}  // namespace marsala::bus::fastdds
