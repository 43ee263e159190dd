#pragma once
// What every Acyclic process shares on LCM (DESIGN.md section 2): the URL,
// SIGINT/SIGTERM handling, a thread-safe publisher, the 1 Hz status heartbeat
// on ACYCLIC_STATUS with errors reported there and on stderr, and a loop that
// serves LCM until a signal arrives.
#include <lcm/lcm-cpp.hpp>

#include <atomic>
#include <cstdint>
#include <functional>
#include <mutex>
#include <string>

#include "acyclic/process_status_t.hpp"

namespace acyclic::proc {

// The default LCM URL: $LCM_DEFAULT_URL if set, else LCM's own default.
// Documented in every --help as the default of --lcm-url.
std::string defaultLcmUrl();

// SIGINT and SIGTERM set a flag (and nothing else: async-signal-safe).
void installSignalHandlers();
bool stopRequested();
const std::atomic<bool>& stopFlag();

// One LCM instance; publish() may be called from any thread.
class Bus {
 public:
  explicit Bus(const std::string& url);  // throws std::runtime_error if LCM cannot start
  lcm::LCM& lcm() { return lcm_; }
  template <class Msg>
  void publish(const std::string& channel, const Msg& msg) {
    std::lock_guard<std::mutex> lock(mutex_);
    lcm_.publish(channel, &msg);
  }
  void publishRaw(const std::string& channel, const void* data, unsigned size) {
    std::lock_guard<std::mutex> lock(mutex_);
    lcm_.publish(channel, data, size);
  }

 private:
  lcm::LCM lcm_;
  std::mutex mutex_;
};

// The process's state as others see it on ACYCLIC_STATUS: published at 1 Hz by
// tick(), and at once on every change of state and on every error.
class StatusReporter {
 public:
  StatusReporter(Bus& bus, std::string process);
  void idle();
  void busy(std::int64_t request_id);
  // An error answering request_id (-1: none): status message and a log line.
  void error(std::int64_t request_id, const std::string& reason);
  void served() { ++served_; }
  void stopping();
  void tick();  // publishes if a second has passed since the last message
  std::int64_t errors() const { return errors_; }

 private:
  void publish();
  Bus& bus_;
  std::mutex mutex_;
  process_status_t msg_;
  std::int64_t served_ = 0, errors_ = 0;
  std::int64_t last_publish_us_ = 0;
};

std::int64_t nowMicros();  // wall clock, for utime

// Serves LCM (handleTimeout) until a signal or until done() returns true,
// calling on_tick() every period_ms. Returns 0, or 1 when LCM failed.
int spin(Bus& bus, const std::function<void()>& on_tick, const std::function<bool()>& done = {},
         int period_ms = 50);

// Logs "process: message" to stderr with a timestamp (the process's log).
void log(const std::string& process, const std::string& message);

}  // namespace acyclic::proc
