#include "hrp2_bridge/periodic_loop.h"

#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>

#include <cerrno>
#include <cstring>
#include <cmath>
#include <stdexcept>

namespace acyclic::hrp2 {

namespace {
std::int64_t toNs(const timespec& t) { return std::int64_t(t.tv_sec) * 1000000000LL + t.tv_nsec; }
timespec fromNs(std::int64_t ns) { return timespec{time_t(ns / 1000000000LL), long(ns % 1000000000LL)}; }
}  // namespace

std::int64_t monotonicMicros() {
  timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return toNs(t) / 1000;
}

bool setRealtimePriority(int priority, std::string* why) {
  sched_param p{};
  p.sched_priority = priority;
  const int e = pthread_setschedparam(pthread_self(), SCHED_FIFO, &p);
  if (e != 0 && why) *why = std::strerror(e);
  return e == 0;
}

bool pinToCpu(int cpu, std::string* why) {
  cpu_set_t set;
  CPU_ZERO(&set);
  if (cpu < 0 || cpu >= CPU_SETSIZE) {
    if (why) *why = "no CPU " + std::to_string(cpu);
    return false;
  }
  CPU_SET(cpu, &set);
  const int e = pthread_setaffinity_np(pthread_self(), sizeof set, &set);
  if (e != 0 && why) *why = std::strerror(e);
  return e == 0;
}

bool lockMemory(std::string* why) {
  if (mlockall(MCL_CURRENT | MCL_FUTURE) == 0) return true;
  if (why) *why = std::strerror(errno);
  return false;
}

void setBackgroundPriority(bool realtime) {
  sched_param p{};
  p.sched_priority = realtime ? 1 : 0;
  pthread_setschedparam(pthread_self(), realtime ? SCHED_FIFO : SCHED_OTHER, &p);
}

std::string enterRealtime(int priority) {
  if (priority <= 0) return "normal priority";
  std::string why;
  if (!setRealtimePriority(priority, &why)) return "normal priority (SCHED_FIFO refused: " + why + ")";
  // No page faults in the loop: everything mapped now and later stays in memory.
  return "SCHED_FIFO " + std::to_string(priority) +
         (lockMemory(&why) ? ", memory locked" : ", memory not locked (" + why + ")");
}

PeriodicLoop::PeriodicLoop(double period_s) : period_ns_(std::llround(period_s * 1e9)) {
  if (period_ns_ <= 0) throw std::invalid_argument("PeriodicLoop: the period must be positive");
  clock_gettime(CLOCK_MONOTONIC, &next_);
}

std::int64_t PeriodicLoop::wait() {
  std::int64_t next = toNs(next_) + period_ns_;
  timespec now;
  clock_gettime(CLOCK_MONOTONIC, &now);
  // More than a period behind: skip to the next future deadline rather than
  // firing a burst of catch-up periods.
  if (toNs(now) - next > period_ns_) {
    const std::int64_t missed = (toNs(now) - next) / period_ns_;
    skipped_ += missed;
    next += missed * period_ns_;
  }
  next_ = fromNs(next);
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &next_, nullptr) == EINTR) {
  }
  return monotonicMicros();
}

std::int64_t PeriodicLoop::deadline() const { return toNs(next_) / 1000; }

}  // namespace acyclic::hrp2
