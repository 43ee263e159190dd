#include "processes/check_threads.h"

namespace acyclic::proc {

void CheckThreads::start(std::function<void()> work) {
  auto done = std::make_shared<std::atomic<bool>>(false);
  std::lock_guard<std::mutex> lock(mutex_);
  threads_.emplace_back(std::thread([work = std::move(work), done] {
                          work();
                          *done = true;
                        }),
                        done);
}

void CheckThreads::reap() {
  std::lock_guard<std::mutex> lock(mutex_);
  for (auto it = threads_.begin(); it != threads_.end();)
    if (*it->second) it->first.join(), it = threads_.erase(it);
    else ++it;
}

void CheckThreads::joinAll() {
  std::lock_guard<std::mutex> lock(mutex_);
  for (auto& t : threads_) t.first.join();
  threads_.clear();
}

}  // namespace acyclic::proc
