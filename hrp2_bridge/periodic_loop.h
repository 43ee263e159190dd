#pragma once
// A periodic wake-up on absolute CLOCK_MONOTONIC deadlines
// (clock_nanosleep(TIMER_ABSTIME)): a late wake-up does not delay the next
// deadline, so the period does not drift. Used by the bridge and simulator
// loops and by bench_bridge_jitter; the bridge's state machine itself takes
// time as an argument and reads no clock.
#include <cstdint>
#include <ctime>

namespace acyclic::hrp2 {

// CLOCK_MONOTONIC in microseconds.
std::int64_t monotonicMicros();

class PeriodicLoop {
 public:
  explicit PeriodicLoop(double period_s);
  // Sleeps until the next deadline; returns the wake-up time (monotonic us).
  // When more than one period late, the missed deadlines are skipped (counted).
  std::int64_t wait();
  std::int64_t deadline() const;   // the deadline wait() last slept to (us)
  long skipped() const { return skipped_; }

 private:
  std::int64_t period_ns_;
  timespec next_{};
  long skipped_ = 0;
};

}  // namespace acyclic::hrp2
