#pragma once
// Work that must not hold up a control loop (the bridge's check of a
// trajectory: its references take a while on a long one), each piece on a
// thread of its own. Started from any thread; the loop reaps the finished
// ones now and then, so that threads do not pile up over a long run.
#include <atomic>
#include <functional>
#include <list>
#include <memory>
#include <mutex>
#include <thread>
#include <utility>

namespace acyclic::proc {

class CheckThreads {
 public:
  CheckThreads() = default;
  CheckThreads(const CheckThreads&) = delete;
  CheckThreads& operator=(const CheckThreads&) = delete;
  ~CheckThreads() { joinAll(); }

  void start(std::function<void()> work);
  // Joins the threads whose work is done (never waits for one still working).
  void reap();
  // Waits for every thread (stopping: work in progress is finished, not abandoned).
  void joinAll();

 private:
  std::mutex mutex_;
  std::list<std::pair<std::thread, std::shared_ptr<std::atomic<bool>>>> threads_;
};

}  // namespace acyclic::proc
