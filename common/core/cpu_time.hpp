#pragma once
// CPU clocks for the timings a run reports (the world's CPU per step, an agent's decision CPU).

#include <ctime>

namespace marsala {

/// CPU time consumed so far by every thread of this process (DDS's too) [ms].
inline double process_cpu_ms() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return 1e3 * static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_nsec);
}

/// CPU time consumed so far by the calling thread [ms].
inline double thread_cpu_ms() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return 1e3 * static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_nsec);
}

}  // namespace marsala
