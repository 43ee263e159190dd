#include "interpolator/transition_memo.h"

namespace acyclic {

namespace {

void appendBytes(std::string& key, const void* p, std::size_t n) { key.append(static_cast<const char*>(p), n); }

}  // namespace

std::string transitionKey(const Plan& plan, const TransitionDesign& d) {
  std::string key;
  const int kind = static_cast<int>(d.kind);
  appendBytes(key, &kind, sizeof kind);
  for (int k = d.from; k <= d.to; ++k) {
    const PlanStance& st = plan.stances[static_cast<std::size_t>(k)];
    const Configuration& q = st.configuration;
    appendBytes(key, q.base_position.data(), 3 * sizeof(double));
    appendBytes(key, q.base_orientation.coeffs().data(), 4 * sizeof(double));
    appendBytes(key, q.joints.data(), static_cast<std::size_t>(q.joints.size()) * sizeof(double));
    const std::size_t n = st.contacts.size();
    appendBytes(key, &n, sizeof n);
    for (const PlanContact& c : st.contacts) {
      const ContactSpec& s = c.spec;
      const int ints[3] = {s.spot, s.surface, s.supporting ? 1 : 0};
      const double place[3] = {s.placement.x, s.placement.y, s.placement.theta};
      appendBytes(key, ints, sizeof ints);
      appendBytes(key, place, sizeof place);
    }
  }
  return key;
}

std::optional<TransitionOutcome> TransitionMemo::find(const std::string& key) const {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = known_.find(key);
  if (it == known_.end()) return std::nullopt;
  return it->second;
}

void TransitionMemo::store(const std::string& key, const TransitionOutcome& outcome) {
  if (outcome.cancelled) return;
  std::lock_guard<std::mutex> lock(mutex_);
  const auto [it, fresh] = known_.emplace(key, outcome);
  if (fresh && !keep_motion_) it->second.pieces.clear();
}

std::size_t TransitionMemo::size() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return known_.size();
}

}  // namespace acyclic
