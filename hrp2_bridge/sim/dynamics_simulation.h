#pragma once
// A dynamics simulation of executing a trajectory (Simbody multibody
// dynamics, not kinematics): the floating base is free; every joint is
// position-controlled by a PD servo toward a reference (the trajectory's q,
// its dq as feed-forward), torque clamped to the joint's effort limit;
// contacts are compliant Hunt-Crossley forces (Simbody's
// CompliantContactSubsystem) on small spheres at the corners of every contact
// spot's polygon against the scene's surfaces, with each surface's friction.
//
// No LCM, no clock: the caller plays a whole trajectory (simulate()) or
// streams references and advances time (DynamicsSimulator).
//
// Simbody is hidden behind this header (docs/design.md section 4).
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "planner/plan/trajectory.h"
#include "planner/scene/scenario.h"

namespace acyclic::hrp2 {

struct DynamicsOptions {
  // Servo: kp_j = effort_j / full_torque_error (the joint's whole torque at
  // this error), kd_j = 2 damping_ratio sqrt(kp_j m_jj), m_jj the joint's
  // diagonal of the mass matrix at the start (its own inertia, others held).
  double full_torque_error = 0.01;   // rad
  double damping_ratio = 1.0;
  // Contact spheres and material (Hunt-Crossley, Hertz on a sphere).
  double sphere_radius = 0.01;       // m
  double stiffness = 5e7;            // Pa, the material's "k" (both sides)
  double dissipation = 2.0;          // s/m, Hunt-Crossley c
  // Simbody's friction is regularized: below this slip speed it is viscous,
  // so a contact under a tangential load t creeps at about
  // transition_velocity * t / (mu N). Simbody's default; 0.05 runs 3x faster
  // but lets a foot creep centimetres over a few seconds of standing.
  double transition_velocity = 0.01; // m/s
  // Integration: a Simbody variable-step integrator with error control
  // ("semi-explicit-euler2", "rk-merson" or "rk3"), this accuracy (relative
  // local error), steps at most max_step. SemiExplicitEuler2 (velocities
  // first, then positions with them; two evaluations a step) is made for
  // stiff contact: on step_forward it takes the same verdicts and figures as
  // Runge-Kutta-Merson in half its wall time.
  std::string integrator = "semi-explicit-euler2";
  double accuracy = 1e-3;
  double max_step = 0.005;           // s
  // After the last sample the final reference is held this long.
  double settle = 0.5;               // s
  // Verdict thresholds.
  double slip_bound = 0.01;          // m, a supporting contact's slip over its phase
  double fall_height = 0.15;         // m, the base this far below the plan: fell
  double fall_tilt = 0.5;            // rad, the base tilted this far from the plan: fell
  double base_bound = 0.02;          // m, acceptance: base within this of the plan
  void validate() const;             // std::invalid_argument naming the bad value
};

struct ContactOutcome {
  std::string spot, surface;
  bool supporting = false;
  double slip = 0;                   // m, largest tangential displacement of the spot from the phase's start
  double lift = 0;                   // m, largest height of the spot's origin above its start, along the normal
  double unloaded_time = 0;          // s, time within the phase with no contact force on the spot
  bool left_surface = false;         // the spot's origin left the surface polygon
  Eigen::Vector3d force = Eigen::Vector3d::Zero();       // N, world, simulated, at the phase's middle sample
  Eigen::Vector3d plan_force = Eigen::Vector3d::Zero();  // N, world, quasi-static LP at the same sample
  bool plan_force_known = false;     // the LP found forces there
};

struct PhaseOutcome {
  int phase = 0;
  double t_start = 0, t_end = 0;     // s
  double base_drift = 0;             // m, largest |base position - plan|
  double base_drift_end = 0;         // m, at the phase's end
  double tilt = 0;                   // rad, largest base orientation error against the plan
  double tracking = 0;               // rad, largest |q_j - q_ref_j|
  std::string tracking_joint;
  std::vector<ContactOutcome> contacts;
};

struct SimulationReport {
  enum class Verdict { Executed, Fell, Slipped };
  Verdict verdict = Verdict::Executed;
  double verdict_time = 0;           // s, when it fell or slipped (the end when executed)
  std::string reason;                // why it fell or slipped
  std::vector<PhaseOutcome> phases;
  double motion_time = 0;            // s, simulated (trajectory plus settle, or up to a fall)
  double wall_time = 0;              // s
  double worst_slip = 0;             // m, over supporting contacts
  std::string worst_slip_contact;
  double worst_base_drift = 0;       // m
  double worst_tracking = 0;         // rad
  std::string worst_tracking_joint;
  bool base_within_bound = true;     // worst_base_drift <= options.base_bound
  long integrator_steps = 0;
  double mean_step = 0;              // s
  DynamicsOptions options;
  bool executed() const { return verdict == Verdict::Executed; }
};

const char* toString(SimulationReport::Verdict v);
std::string reportToJson(const SimulationReport& r);
void writeReport(const SimulationReport& r, const std::string& path);

// Progress: simulated time and the total to simulate.
using SimulationProgress = std::function<void(double t, double total)>;

// Plays the trajectory at its controller rate (dt) from its first sample at
// rest, then holds the last reference for options.settle; stops early at a fall.
SimulationReport simulate(const Scenario& sc, const Trajectory& tr, const DynamicsOptions& options = {},
                          const SimulationProgress& progress = {});

// The same simulator driven by a stream of references (the simulated
// controller's dynamic mode). Contacts: every spot against the floor (the
// lowest surfaces facing up), plus `pairs`.
struct JointSample {
  Eigen::VectorXd q, dq;
};

class DynamicsSimulator {
 public:
  // `pairs`: (spot, surface) the spots may touch besides the floor.
  DynamicsSimulator(const Scenario& sc, const Configuration& start, const DynamicsOptions& options,
                    const std::vector<std::pair<int, int>>& pairs = {});
  ~DynamicsSimulator();
  DynamicsSimulator(const DynamicsSimulator&) = delete;
  DynamicsSimulator& operator=(const DynamicsSimulator&) = delete;

  // The servo's reference from now on, reached linearly over `ramp` s (so the
  // reference is continuous in time; a step makes the integrator restart).
  void setReference(const Eigen::VectorXd& q, const Eigen::VectorXd& dq, double ramp);
  void advanceTo(double t);          // s, simulated
  double time() const;
  Configuration configuration() const;
  Eigen::VectorXd jointVelocities() const;
  Eigen::Vector3d centerOfMass() const;   // world
  // Sum of the contact forces on each spot (world), zero for spots not touching.
  std::vector<Eigen::Vector3d> spotForces() const;
  long steps() const;

  struct Impl;
  Impl& impl() { return *impl_; }

 private:
  std::unique_ptr<Impl> impl_;
};

// The spot-surface pairs a trajectory's phases name (deduplicated).
std::vector<std::pair<int, int>> contactPairs(const Trajectory& tr);

}  // namespace acyclic::hrp2
