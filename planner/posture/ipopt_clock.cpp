// Ipopt 3.11 times every step of its algorithm (each TimedTask's Start and
// End, several per iteration) with Ipopt::CpuTime() and Ipopt::SysTime(),
// each a getrusage(RUSAGE_SELF): a system call that, in a process with
// several threads, sums every thread's time under the thread group's lock.
// perf on the interpolator with two threads: about 5% of all CPU in that
// lock alone. And what it measures is not what a posture generator's
// max_cpu_time means: with two generators on two threads, each one's budget
// was spent by both.
// libipopt calls both through its PLT, so these definitions, in a shared
// library linked before it (planner/CMakeLists.txt), are the ones used:
// CpuTime is the calling thread's CPU time; SysTime is 0 (it only fills
// Ipopt's timing-statistics table, print_level >= 4).
// The thread's CPU clock is a system call too (not in the vDSO): it is read
// at most once a millisecond, and between two reads the wall clock's advance
// (vDSO) stands in for it. A running thread's CPU time advances as fast; one
// that was descheduled is overcharged by less than a millisecond.
#include <algorithm>
#include <ctime>

namespace Ipopt {
double CpuTime();
double SysTime();
}  // namespace Ipopt

namespace {
double seconds(clockid_t clock) {
  timespec ts{};
  clock_gettime(clock, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}
constexpr double kRefresh = 1e-3;  // s of wall time between reads of the thread's CPU clock
}  // namespace

double Ipopt::CpuTime() {
  thread_local double cpu = -1, wall_at_read = 0, returned = 0;
  const double wall = seconds(CLOCK_MONOTONIC);
  if (cpu < 0 || wall - wall_at_read > kRefresh) {
    cpu = seconds(CLOCK_THREAD_CPUTIME_ID);
    wall_at_read = wall;
  }
  returned = std::max(returned, cpu + (wall - wall_at_read));  // never backwards
  return returned;
}

double Ipopt::SysTime() { return 0.0; }
