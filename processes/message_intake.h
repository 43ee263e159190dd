#pragma once
// Large messages (trajectories: tens to hundreds of kB) off the LCM receive
// thread: it only copies the bytes (push), and the intake's own thread
// decodes and handles them one at a time, so that small urgent messages
// (HRP2_STATE, HRP2_ESTOP) are never queued behind one. Messages still
// queued when it stops are dropped: the process is ending.
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace acyclic::proc {

class MessageIntake {
 public:
  using Take = std::function<void(const std::vector<char>& bytes)>;
  // `prepare` runs first on the intake's thread (e.g. its priority).
  MessageIntake(Take take, std::function<void()> prepare);
  MessageIntake(const MessageIntake&) = delete;
  MessageIntake& operator=(const MessageIntake&) = delete;
  ~MessageIntake() { stop(); }

  void push(const void* data, std::size_t size);
  void stop();

 private:
  void run(const std::function<void()>& prepare);

  Take take_;
  std::mutex mutex_;
  std::condition_variable cv_;
  std::deque<std::vector<char>> queue_;
  bool quit_ = false;
  std::thread thread_;
};

}  // namespace acyclic::proc
