#include "hrp2_bridge/sim/simulated_controller.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "planner/common/geometry.h"

namespace acyclic::hrp2 {

void SimOptions::validate() const {
  auto bad = [](const std::string& what) { throw std::invalid_argument("simulator option " + what); };
  if (!(dt > 0)) bad("dt: expected a positive period (s)");
  if (!(time_constant > 0)) bad("time_constant: expected a positive time (s)");
  if (!(latency >= 0)) bad("latency: expected a non-negative time (s)");
  if (!(drop_rate >= 0 && drop_rate < 1)) bad("drop_rate: expected a fraction in [0, 1)");
  if (hold_after_missed < 0) bad("hold_after_missed: expected a number of periods >= 0 (0: never)");
}

SimulatedController::SimulatedController(std::shared_ptr<const RobotModel> robot, const Configuration& start,
                                         SimOptions options)
    : robot_(robot), opt_(options), q_(start), rng_(options.seed) {
  opt_.validate();
  if (start.joints.size() != robot->numJoints()) throw std::invalid_argument("simulator: start has the wrong joint count");
  dq_ = Eigen::VectorXd::Zero(robot->numJoints());
  vmax_ = robot->velocityLimits();
  qmin_ = robot->lowerLimits();
  qmax_ = robot->upperLimits();
}

bool SimulatedController::frozen(std::int64_t now) const {
  return opt_.freeze_after >= 0 && first_command_at_ >= 0 &&
         now - first_command_at_ >= std::llround(opt_.freeze_after * 1e6);
}

void SimulatedController::receive(const SimCommand& c, std::int64_t now) {
  ++received_;
  if (first_command_at_ < 0) first_command_at_ = now;
  if (frozen(now)) return;
  if (opt_.drop_rate > 0 && std::uniform_real_distribution<double>(0, 1)(rng_) < opt_.drop_rate) {
    ++dropped_;
    return;
  }
  if (c.q.size() != robot_->numJoints() || c.dq.size() != robot_->numJoints() || !c.q.allFinite() ||
      !c.dq.allFinite() || !c.waist_position.allFinite() || !c.waist_rpy.allFinite()) {
    ++rejected_;
    return;
  }
  // A real controller refuses a reference beyond the joint's limits rather
  // than drive into its stops (a rounding's worth of tolerance).
  constexpr double kTolerance = 1e-9;
  if ((c.q.array() < qmin_.array() - kTolerance).any() || (c.q.array() > qmax_.array() + kTolerance).any()) {
    ++refused_position_;
    return;
  }
  if ((c.dq.array().abs() > vmax_.array() + kTolerance).any()) {
    ++refused_velocity_;
    return;
  }
  last_command_at_ = now;
  pending_.emplace_back(now + std::llround(opt_.latency * 1e6), c);
}

void SimulatedController::apply(const SimCommand& c) {
  current_ = c;
  has_command_ = true;
  holding_missed_ = false;
  ++applied_;
}

void SimulatedController::integrate(double h) {
  if (!has_command_) {
    dq_.setZero();
    return;
  }
  const double T = opt_.time_constant;
  // dq = dq_ref + (q_ref - q) / T, within the velocity limits; explicit Euler
  // with h <= dt < T is stable.
  Eigen::VectorXd v = current_.dq + (current_.q - q_.joints) / T;
  v = v.cwiseMax(-vmax_).cwiseMin(vmax_);
  // The joint stops: a joint never moves past its limits (one that starts
  // outside them may only move back).
  for (Eigen::Index i = 0; i < v.size(); ++i) {
    const double next = q_.joints[i] + h * v[i];
    const double lo = std::min(qmin_[i], q_.joints[i]), hi = std::max(qmax_[i], q_.joints[i]);
    if (next < lo || next > hi) v[i] = (std::clamp(next, lo, hi) - q_.joints[i]) / h;
  }
  q_.joints += h * v;
  dq_ = v;
  if (current_.mode == 0) {
    // The base follows the streamed waist reference (a holding or frozen
    // robot stays where it stands).
    const double a = std::min(1.0, h / T);
    q_.base_position += a * (current_.waist_position - q_.base_position);
    const Eigen::Quaterniond target = rpyToQuaternion(current_.waist_rpy);
    q_.base_orientation = q_.base_orientation.slerp(a, target).normalized();
  }
}

void SimulatedController::step(std::int64_t now) {
  if (last_step_ < 0) last_step_ = now;
  if (frozen(now)) {
    dq_.setZero();
    last_step_ = now;
    return;
  }
  // The latest due command wins (a position controller keeps only the latest reference).
  while (!pending_.empty() && pending_.front().first <= now) {
    apply(pending_.front().second);
    pending_.pop_front();
  }
  // The command stream stopped (its sender died or hangs): hold the last
  // commanded posture without its velocity feed-forward, the base where it
  // stands, rather than go on with a reference nobody updates.
  if (opt_.hold_after_missed > 0 && has_command_ && !holding_missed_ && pending_.empty() &&
      now - last_command_at_ > std::llround(opt_.hold_after_missed * opt_.dt * 1e6)) {
    holding_missed_ = true;
    ++missed_holds_;
    current_.mode = 1;
    current_.dq.setZero();
  }
  double elapsed = (now - last_step_) * 1e-6;
  last_step_ = now;
  while (elapsed > 1e-9) {
    const double h = std::min(elapsed, opt_.dt);
    integrate(h);
    elapsed -= h;
  }
}

SimState SimulatedController::state() const {
  SimState s;
  if (has_command_) {
    s.request_id = current_.request_id;
    s.command_sequence = current_.sequence;
    s.stabilizer = current_.stabilizer;
  }
  s.q = q_.joints;
  s.dq = dq_;
  s.configuration = q_;
  s.servo_on = opt_.servo_on;
  return s;
}

}  // namespace acyclic::hrp2
