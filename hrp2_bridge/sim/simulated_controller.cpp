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
}

SimulatedController::SimulatedController(std::shared_ptr<const RobotModel> robot, const Configuration& start,
                                         SimOptions options)
    : robot_(robot), opt_(options), q_(start), rng_(options.seed) {
  opt_.validate();
  if (start.joints.size() != robot->numJoints()) throw std::invalid_argument("simulator: start has the wrong joint count");
  dq_ = Eigen::VectorXd::Zero(robot->numJoints());
  vmax_ = robot->velocityLimits();
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
  pending_.emplace_back(now + std::llround(opt_.latency * 1e6), c);
}

void SimulatedController::apply(const SimCommand& c) {
  current_ = c;
  has_command_ = true;
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
