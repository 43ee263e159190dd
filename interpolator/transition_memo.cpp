#include "interpolator/transition_memo.h"

#include <cstdio>

namespace acyclic {

namespace {

void appendBytes(std::string& key, const void* p, std::size_t n) { key.append(static_cast<const char*>(p), n); }

// name=value, the value's bits in hexadecimal floating point.
void appendNumber(std::string& text, const char* name, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%s=%a;", name, v);
  text += buf;
}

}  // namespace

std::string outcomeOptionsText(const InterpolatorOptions& o) {
  // The fields transitionOptions() leaves at their defaults come too: a
  // build whose defaults differ solves differently.
  const TransitionOptions t = transitionOptions(o);
  std::string text = "acyclic.transition-options/1;";
  appendNumber(text, "steps", o.steps);
  appendNumber(text, "fixed_step", o.fixed_step);
  appendNumber(text, "dt", o.dt);
  appendNumber(text, "speed_cap", o.speed_cap);
  appendNumber(text, "velocity_share", o.velocity_share);
  appendNumber(text, "link_acceleration_cap", o.link_acceleration_cap);
  appendNumber(text, "zmp_shift_cap", o.zmp_shift_cap);
  appendNumber(text, "lift", o.lift);
  appendNumber(text, "touch_clearance", o.touch_clearance);
  appendNumber(text, "air_orientation_tolerance", o.air_orientation_tolerance);
  appendNumber(text, "repair_attempts", o.repair_attempts);
  appendNumber(text, "repair_step", o.repair_step);
  appendNumber(text, "plan_body_path", o.plan_body_path);
  appendNumber(text, "free_limb_paths", o.free_limb_paths);
  appendNumber(text, "limb_joint_paths", o.limb_joint_paths);
  appendNumber(text, "wide_clearance", o.wide_clearance);
  appendNumber(text, "refine_depth", o.refine_depth);
  appendNumber(text, "bridge_jumps", o.bridge_jumps);
  appendNumber(text, "order_by_failure", o.order_by_failure);
  appendNumber(text, "verify_samples", o.verify_samples);
  appendNumber(text, "pyramid_edges", o.pyramid_edges);
  appendNumber(text, "support_inset", o.support_inset);
  appendNumber(text, "support_inset_y", o.support_inset_y);
  appendNumber(text, "friction_share", o.friction_share);
  appendNumber(text, "posture_iterations", o.posture_iterations);
  appendNumber(text, "collision_cutoff", o.collision_cutoff);
  appendNumber(text, "posture_lbfgs_in_kkt", o.posture_lbfgs_in_kkt);
  text += "posture_mu_oracle=" + o.posture_mu_oracle + ";";
  for (const std::string& kv : o.posture_ipopt_options) text += "ipopt:" + kv + ";";
  appendNumber(text, "planned_orientation_tolerance", t.planned_orientation_tolerance);
  appendNumber(text, "segment_checks", t.segment_checks);
  appendNumber(text, "collision_margin", t.posture.problem.collision_margin);
  return text;
}

std::vector<RememberedTransition> rememberedTransitions(const Plan& plan, const TransitionMemo& memo) {
  std::vector<TransitionDesign> designs;
  std::vector<RememberedTransition> out;
  if (!designTransitions(plan, designs).empty()) return out;
  for (const TransitionDesign& d : designs)
    if (std::optional<TransitionOutcome> o = memo.find(transitionKey(plan, d)); o && o->ok)
      out.push_back({d, std::move(*o)});
  return out;
}

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
