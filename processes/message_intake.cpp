#include "processes/message_intake.h"

#include <chrono>

namespace acyclic::proc {

MessageIntake::MessageIntake(Take take, std::function<void()> prepare) : take_(std::move(take)) {
  thread_ = std::thread([this, prepare = std::move(prepare)] { run(prepare); });
}

void MessageIntake::push(const void* data, std::size_t size) {
  const char* bytes = static_cast<const char*>(data);
  std::lock_guard<std::mutex> lock(mutex_);
  queue_.emplace_back(bytes, bytes + size);
  cv_.notify_one();
}

void MessageIntake::stop() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    quit_ = true;
  }
  cv_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void MessageIntake::run(const std::function<void()>& prepare) {
  if (prepare) prepare();
  std::unique_lock<std::mutex> lock(mutex_);
  while (!quit_) {
    cv_.wait_for(lock, std::chrono::milliseconds(50), [&] { return !queue_.empty() || quit_; });
    while (!queue_.empty() && !quit_) {
      std::vector<char> bytes = std::move(queue_.front());
      queue_.pop_front();
      lock.unlock();
      take_(bytes);  // its failures are the caller's to report
      lock.lock();
    }
  }
}

}  // namespace acyclic::proc
