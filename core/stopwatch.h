#pragma once
// Timing stages for statistics: milliseconds since a steady-clock time point.

#include <chrono>

namespace ihs {

using SteadyClock = std::chrono::steady_clock;

/// Milliseconds elapsed since `start` on the steady clock.
inline double MillisecondsSince(SteadyClock::time_point start) {
  return std::chrono::duration<double, std::milli>(SteadyClock::now() - start).count();
}

}  // namespace ihs
