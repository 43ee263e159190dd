#pragma once
// What every Acyclic process shares on LCM (docs/design.md section 2): the URL,
// SIGINT/SIGTERM handling, a thread-safe publisher, the 1 Hz status heartbeat
// on ACYCLIC_STATUS with errors reported there and on stderr, and a loop that
// serves LCM until a signal arrives.
#include <lcm/lcm-cpp.hpp>

#include <atomic>
#include <cstdint>
#include <functional>
#include <mutex>
#include <string>
#include <thread>

#include "acyclic/process_status_t.hpp"
#include "processes/guarded_decode.h"

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
  // The first status: call it once the process has subscribed to its inputs,
  // since others take a process's first status as "ready for requests".
  void ready();
  void idle();
  void busy(std::int64_t request_id);
  // An error answering request_id (-1: none): status message and a log line.
  void error(std::int64_t request_id, const std::string& reason);
  void served() { ++served_; }
  // A message on `channel` that does not decode (`what` says why): counted,
  // a status error and a log line. Past 10 in a second, only counted until
  // the next second, whose first report says how many went unreported.
  void undecodable(const std::string& channel, const std::string& what);
  std::int64_t undecodableCount() const { return undecodable_.load(); }
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
  std::atomic<std::int64_t> undecodable_{0};
  std::int64_t undecodable_window_us_ = 0, undecodable_in_window_ = 0, undecodable_unreported_ = 0;
};

std::int64_t nowMicros();  // wall clock, for utime

// A service busy with one request refuses another with this reason
// ("refused: busy with request N (one W at a time)"); isBusyWith tells a
// client that such a refusal names its own request: it answers a second
// copy of that work, whose first copy is still being done.
std::string busyRefusal(std::int64_t current_request, const std::string& what);
bool isBusyWith(const std::string& reason, std::int64_t request_id);

// Decodes a raw LCM message (the one decode path of every subscription): a
// message that does not decode is counted and reported (status error naming
// the channel and the reason, and a log line) and false returned, so a
// malformed message never kills a process and never passes silently.
template <class Msg>
bool decode(const void* data, std::size_t size, const std::string& channel, Msg& out, StatusReporter& status) {
  const std::string why = whyNotDecoded(data, size, out);
  if (why.empty()) return true;
  status.undecodable(channel, "a message of " + std::to_string(size) + " bytes does not decode as " +
                                  Msg::getTypeName() + ": " + why);
  return false;
}
template <class Msg>
bool decode(const lcm::ReceiveBuffer* rb, const std::string& channel, Msg& out, StatusReporter& status) {
  return decode(rb->data, rb->data_size, channel, out, status);
}

// One request at a time, served on a worker thread while the LCM loop goes
// on (heartbeat, cancellation). A second request while one runs is refused by
// the caller (start() returns false): documented in each process's --help.
class Worker {
 public:
  ~Worker() { stop(); }
  // Starts job(cancel) for request_id on a thread; false when one is running.
  bool start(std::int64_t request_id, std::function<void(const std::atomic<bool>& cancel)> job);
  bool busy() const { return running_.load(); }
  std::int64_t current() const { return current_.load(); }
  // Cancels the running job if it serves request_id (or any job for -1).
  bool cancel(std::int64_t request_id);
  void reap();  // joins a finished job; call from the loop
  // Cancels and joins, and the job is abandoned: a process that stops does
  // not answer for work it did not finish (nobody cancelled that request).
  void stop();
  // True once stop() was called: a job checks it before it publishes its answer.
  bool abandoned() const { return abandoned_.load(); }

 private:
  std::thread thread_;
  std::atomic<bool> running_{false}, cancel_{false}, abandoned_{false};
  std::atomic<std::int64_t> current_{-1};
};

// Serves LCM (handleTimeout) until a signal or until done() returns true,
// calling on_tick() every period_ms. Returns 0, or 1 when LCM failed. A
// handler that throws costs its message, not the process: on_handler_error
// gets what it threw (without one, the exception goes on to the caller).
int spin(Bus& bus, const std::function<void()>& on_tick, const std::function<bool()>& done = {},
         int period_ms = 50, const std::function<void(const std::string&)>& on_handler_error = {});

// Waits up to wait_ms for a message, then dispatches every message already
// queued (max_messages at most, so that a flood cannot starve the caller).
// A loop that does other work between calls (a supervisor's poll) must drain
// so: one message per pass lets a burst overflow the socket's receive buffer,
// and UDP then drops the message the loop was waiting for. Returns the number
// dispatched, or < 0 when LCM failed.
int handlePending(Bus& bus, int wait_ms, int max_messages = 10000);

// Logs "process: message" to stderr with a timestamp (the process's log).
void log(const std::string& process, const std::string& message);

// What a request-serving process holds: the bus, its status, one worker.
// tick() is called by the loop, stop() on SIGINT/SIGTERM.
class Service {
 public:
  Service(Bus& bus, const std::string& process) : bus_(bus), status_(bus, process) {}
  virtual ~Service() = default;
  virtual void tick() {
    worker_.reap();
    status_.tick();
  }
  virtual void stop() {
    worker_.stop();
    status_.stopping();
  }
  void handlerFailed(const std::string& what) { status_.error(-1, "a message's handler failed: " + what); }

 protected:
  Bus& bus_;
  StatusReporter status_;
  Worker worker_;
};

// Runs a Service (constructed from the bus and the options) until a signal:
// the LCM loop, the log lines, the exit status (0, or 1 when LCM fails).
template <class S, class Options>
int serve(const std::string& url, const std::string& process, const std::string& serving, const Options& options) {
  try {
    Bus bus(url);
    S service(bus, options);
    log(process, "serving " + serving + " on " + (url.empty() ? std::string("LCM's default URL") : url));
    const int rc = spin(
        bus, [&] { service.tick(); }, {}, 50, [&](const std::string& what) { service.handlerFailed(what); });
    service.stop();
    log(process, "stopped");
    return rc;
  } catch (const std::exception& e) {
    // The service (and its worker: abandoned, see Worker::stop) is gone by now.
    log(process, std::string("fatal: ") + e.what());
    return 1;
  }
}

}  // namespace acyclic::proc
