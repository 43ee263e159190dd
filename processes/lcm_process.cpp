#include "processes/lcm_process.h"

#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <stdexcept>

#include "lcmtypes/channels.hpp"

namespace acyclic::proc {

namespace {
std::atomic<bool> g_stop{false};
void onSignal(int) { g_stop = true; }
}  // namespace

std::string defaultLcmUrl() {
  const char* env = std::getenv("LCM_DEFAULT_URL");
  return env && *env ? env : "";
}

void installSignalHandlers() {
  struct sigaction sa {};
  sa.sa_handler = onSignal;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
}
bool stopRequested() { return g_stop.load(); }
const std::atomic<bool>& stopFlag() { return g_stop; }

std::int64_t nowMicros() {
  return std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

namespace {
std::string busyPrefix(std::int64_t request) { return "refused: busy with request " + std::to_string(request) + " "; }
}  // namespace

std::string busyRefusal(std::int64_t current_request, const std::string& what) {
  return busyPrefix(current_request) + "(one " + what + " at a time)";
}

bool isBusyWith(const std::string& reason, std::int64_t request_id) {
  const std::string prefix = busyPrefix(request_id);
  return reason.compare(0, prefix.size(), prefix) == 0;
}

void log(const std::string& process, const std::string& message) {
  const std::time_t t = std::time(nullptr);
  char stamp[32];
  std::strftime(stamp, sizeof stamp, "%H:%M:%S", std::localtime(&t));
  std::fprintf(stderr, "%s %s[%d]: %s\n", stamp, process.c_str(), static_cast<int>(getpid()), message.c_str());
  std::fflush(stderr);
}

Bus::Bus(const std::string& url) : lcm_(url) {
  if (!lcm_.good()) throw std::runtime_error("LCM could not start on '" + url + "'" +
                                             (url.rfind("udpm", 0) == 0 || url.empty()
                                                  ? " (udpm needs a multicast route: see docs/troubleshooting.md)"
                                                  : ""));
}

StatusReporter::StatusReporter(Bus& bus, std::string process) : bus_(bus) {
  msg_.process = std::move(process);
  msg_.pid = getpid();
  msg_.request_id = -1;
  msg_.state = process_status_t::IDLE;
}

void StatusReporter::publish() {
  msg_.utime = nowMicros();
  msg_.requests_served = served_;
  msg_.errors = errors_;
  last_publish_us_ = msg_.utime;
  bus_.publish(channels::kStatus, msg_);
}

void StatusReporter::ready() {
  std::lock_guard<std::mutex> lock(mutex_);
  publish();
}

void StatusReporter::idle() {
  std::lock_guard<std::mutex> lock(mutex_);
  msg_.state = process_status_t::IDLE;
  msg_.request_id = -1;
  msg_.reason.clear();
  publish();
}

void StatusReporter::busy(std::int64_t request_id) {
  std::lock_guard<std::mutex> lock(mutex_);
  msg_.state = process_status_t::BUSY;
  msg_.request_id = request_id;
  msg_.reason.clear();
  publish();
}

void StatusReporter::error(std::int64_t request_id, const std::string& reason) {
  log(msg_.process, "error" + (request_id >= 0 ? " (request " + std::to_string(request_id) + ")" : std::string()) +
                        ": " + reason);
  std::lock_guard<std::mutex> lock(mutex_);
  ++errors_;
  // An error is reported on its own message; the state the process is in
  // (idle or busy with another request) comes back with the next one.
  process_status_t e = msg_;
  e.state = process_status_t::ERROR;
  e.request_id = request_id;
  e.reason = reason;
  e.utime = nowMicros();
  e.requests_served = served_;
  e.errors = errors_;
  bus_.publish(channels::kStatus, e);
}

void StatusReporter::undecodable(const std::string& channel, const std::string& what) {
  const std::int64_t total = ++undecodable_;
  std::int64_t unreported = 0;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const std::int64_t now = nowMicros();
    if (now - undecodable_window_us_ >= 1000000) {
      undecodable_window_us_ = now;
      undecodable_in_window_ = 0;
    }
    if (++undecodable_in_window_ > 10) {
      ++undecodable_unreported_;
      ++errors_;
      return;
    }
    unreported = undecodable_unreported_;
    undecodable_unreported_ = 0;
  }
  error(-1, channel + ": " + what + " (" + std::to_string(total) + " refused so far" +
                (unreported > 0 ? ", " + std::to_string(unreported) + " of them not reported one by one" : "") + ")");
}

void StatusReporter::stopping() {
  std::lock_guard<std::mutex> lock(mutex_);
  msg_.state = process_status_t::STOPPING;
  msg_.reason = "signal";
  publish();
}

void StatusReporter::tick() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (nowMicros() - last_publish_us_ >= 1000000) publish();
}

int spin(Bus& bus, const std::function<void()>& on_tick, const std::function<bool()>& done, int period_ms,
         const std::function<void(const std::string&)>& on_handler_error) {
  while (!stopRequested() && !(done && done())) {
    // handleTimeout returns < 0 on error (and, in LCM 1.3.1, when interrupted
    // by a signal: then the stop flag is set and the loop ends).
    int r = 0;
    try {
      r = bus.lcm().handleTimeout(period_ms);
    } catch (const std::exception& e) {
      if (!on_handler_error) throw;
      on_handler_error(e.what());
    }
    if (r < 0 && !stopRequested()) return 1;
    if (on_tick) on_tick();
  }
  return 0;
}

int handlePending(Bus& bus, int wait_ms, int max_messages) {
  int r = bus.lcm().handleTimeout(wait_ms);
  if (r <= 0) return r;
  int n = 1;
  while (n < max_messages && (r = bus.lcm().handleTimeout(0)) > 0) ++n;
  return r < 0 ? r : n;
}

bool Worker::start(std::int64_t request_id, std::function<void(const std::atomic<bool>&)> job) {
  if (running_) return false;
  reap();
  cancel_ = false;
  current_ = request_id;
  running_ = true;
  thread_ = std::thread([this, job = std::move(job)] {
    job(cancel_);
    running_ = false;
  });
  return true;
}

bool Worker::cancel(std::int64_t request_id) {
  if (!running_ || (request_id != -1 && request_id != current_)) return false;
  cancel_ = true;
  return true;
}

void Worker::reap() {
  if (!running_ && thread_.joinable()) {
    thread_.join();
    current_ = -1;
  }
}

void Worker::stop() {
  abandoned_ = true;
  cancel_ = true;
  if (thread_.joinable()) thread_.join();
  running_ = false;
  current_ = -1;
}

}  // namespace acyclic::proc
