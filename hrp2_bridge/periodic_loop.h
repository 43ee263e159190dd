#pragma once
// A periodic wake-up on absolute CLOCK_MONOTONIC deadlines
// (clock_nanosleep(TIMER_ABSTIME)): a late wake-up does not delay the next
// deadline, so the period does not drift. Used by the bridge and simulator
// loops and by bench_bridge_jitter; the bridge's state machine itself takes
// time as an argument and reads no clock.
#include <cstdint>
#include <ctime>
#include <string>

namespace acyclic::hrp2 {

// CLOCK_MONOTONIC in microseconds.
std::int64_t monotonicMicros();

// The calling thread to SCHED_FIFO at `priority` (1..99): a control loop that
// sleeps almost all the time and must wake on time on a busy machine. Threads
// created afterwards inherit it. False (with the reason) when not permitted.
bool setRealtimePriority(int priority, std::string* why = nullptr);
// The calling thread (and the threads it creates afterwards) to one CPU.
// False (with the reason) when the CPU does not exist or is not allowed.
bool pinToCpu(int cpu, std::string* why = nullptr);

// Locks the process's memory (mlockall, current and future): a page fault
// in a real-time loop costs milliseconds. False (with the reason) when not permitted.
bool lockMemory(std::string* why = nullptr);

// setRealtimePriority then lockMemory when priority > 0, as a real-time
// process starts; returns what it got, for the process's log ("SCHED_FIFO 20,
// memory locked", or "normal priority (SCHED_FIFO refused: ...)").
std::string enterRealtime(int priority);

// For the heavy threads of a real-time process (checks, LPs): SCHED_FIFO 1,
// below the loops, when `realtime`; else the normal time-sharing policy.
// Not SCHED_OTHER in a real-time process: a time-shared thread preempted
// while it holds a lock the loop may need (malloc's arena lock when memory is
// freed across threads) would stall the loop until the scheduler comes back
// to it; at FIFO 1 it gets the CPU back at once and releases the lock. (A
// precaution: the 10-30 ms stalls seen on the shared test machine happened
// with either policy.)
void setBackgroundPriority(bool realtime);

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
