#pragma once
// A simulated HRP-2 controller (no LCM, no clock: `now` in microseconds is
// passed in): position-controlled joints that track the latest command with
// a first-order law and velocity feed-forward, within the model's velocity
// limits; the base follows the streamed waist reference with the same law.
// Contact forces come from the quasi-static model (contact_forces.h); the LP
// takes milliseconds, so the caller computes them off the control loop and
// attaches them to the state. Fault options: latency, dropped commands, a
// freeze (the controller hangs: no motion, no state).
//
// Like a real controller it keeps the model's limits whatever it is sent: a
// command with a position outside the joint limits or a velocity beyond the
// velocity limits is refused (counted; the previous reference stays), and the
// joints never leave their position limits. It has no joint torques (the
// joints are kinematic), so it enforces no torque limit: a dynamic simulation
// compares its torques with RobotModel::effortLimits(). And like the
// controller a lab should run, it holds by itself when the command stream
// stops: after hold_after_missed periods without a command it holds the last
// commanded posture, with no velocity feed-forward and the base where it
// stands (the bridge that sent the stream may have died).
#include <cstdint>
#include <deque>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "hrp2_bridge/sim/contact_forces.h"
#include "planner/scene/scenario.h"

namespace acyclic::hrp2 {

struct SimOptions {
  double dt = 0.005;               // s, controller period
  double time_constant = 0.02;     // s, first-order joint tracking
  double latency = 0;              // s, a command is applied this long after it arrives
  double drop_rate = 0;            // fraction of commands lost (seeded: deterministic)
  std::uint64_t seed = 1;
  double freeze_after = -1;        // s after the first command the controller hangs; < 0: never
  bool servo_on = true;
  // Periods without a command, once commands have come, after which the
  // controller holds the last commanded posture (velocity reference zero,
  // the base where it stands); 0: never.
  int hold_after_missed = 20;
  void validate() const;           // std::invalid_argument naming the bad value
};

struct SimCommand {
  std::int64_t request_id = -1, sequence = -1;
  int mode = 0;                    // 0 stream, 1 hold, 2 freeze (hrp2_command_t)
  Eigen::VectorXd q, dq;
  Eigen::Vector3d waist_position = Eigen::Vector3d::Zero(), waist_rpy = Eigen::Vector3d::Zero();
  bool stabilizer = true;
};

struct SimState {
  std::int64_t request_id = -1, command_sequence = -1;
  Eigen::VectorXd q, dq;
  Configuration configuration;     // base pose and joints
  std::vector<ContactWrench> wrenches;  // attached by the caller (ContactForces)
  bool equilibrium = false;        // the quasi-static LP found forces
  bool servo_on = true, stabilizer = true;
};

class SimulatedController {
 public:
  SimulatedController(std::shared_ptr<const RobotModel> robot, const Configuration& start, SimOptions options);

  // A command arrives (dropped or delayed as the options say). A command of
  // the wrong size or not finite is ignored and counted: a real controller
  // would refuse it too.
  void receive(const SimCommand& c, std::int64_t now);
  // Advances to `now`: applies the commands that are due, integrates the
  // tracking law (sub-steps of at most dt).
  void step(std::int64_t now);
  // True once the freeze time has passed: no motion, no state.
  bool frozen(std::int64_t now) const;
  SimState state() const;

  long received() const { return received_; }
  long dropped() const { return dropped_; }
  long rejected() const { return rejected_; }
  long applied() const { return applied_; }
  // Commands refused for a position outside the joint limits, or a velocity
  // beyond the velocity limits (a command with both counts as a position).
  long refusedPosition() const { return refused_position_; }
  long refusedVelocity() const { return refused_velocity_; }
  // Times the command stream stopped for hold_after_missed periods (each
  // started a hold), and whether the controller holds for that reason now.
  long missedHolds() const { return missed_holds_; }
  bool holdingForMissedCommands() const { return holding_missed_; }

 private:
  void apply(const SimCommand& c);
  void integrate(double h);

  std::shared_ptr<const RobotModel> robot_;
  SimOptions opt_;
  Configuration q_;
  Eigen::VectorXd dq_;
  Eigen::VectorXd vmax_, qmin_, qmax_;
  std::deque<std::pair<std::int64_t, SimCommand>> pending_;  // due time, command
  SimCommand current_;
  bool has_command_ = false;
  std::int64_t first_command_at_ = -1, last_step_ = -1, last_command_at_ = -1;
  bool holding_missed_ = false;
  std::mt19937_64 rng_;
  long received_ = 0, dropped_ = 0, rejected_ = 0, applied_ = 0;
  long refused_position_ = 0, refused_velocity_ = 0, missed_holds_ = 0;
};

}  // namespace acyclic::hrp2
