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
#include <cmath>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "hrp2_bridge/sim/feet_stabilizer.h"
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
  // transition_velocity * t / (mu N). Coulomb friction does not creep: the
  // smaller, the closer (and the stiffer the equations). Simbody's default,
  // 0.01, lets the internal squeeze between a foot and a thigh on a seat
  // (100 N, from the servos' sag when the thigh lands) creep 17-20 mm over
  // sit_down's 8 s seated phase; 0.001 leaves 4 mm.
  double transition_velocity = 0.001; // m/s
  // Integration: a Simbody variable-step integrator with error control
  // ("cpodes", "semi-explicit-euler2", "rk-merson" or "rk3"), this accuracy
  // (relative local error), steps at most max_step. CPodes' BDF (implicit,
  // Newton iterations) is made for stiff equations, and the stiction above
  // is stiff: on sit_down's 86.7 s trajectory it takes 2.3 ms steps and runs
  // 5.9x faster than real time where SemiExplicitEuler2 (explicit, made for
  // stiff contact) needs 0.09 ms steps at 0.002 m/s and runs at 0.6x; both
  // give the same verdict and figures within 0.2 mm.
  std::string integrator = "cpodes";
  double accuracy = 1e-3;
  double max_step = 0.005;           // s
  // HRP-2's stabilizer (feet_stabilizer.h) where the bridge's schedule runs
  // it (only coplanar feet touch; hrp2_bridge/stabilizer_schedule.h); the
  // references are played open-loop elsewhere, and everywhere when false.
  bool stabilizer = true;
  FeetStabilizerOptions stabilizer_options;
  // The robot's body meets the scene, not only its contact spots: each
  // link's collision shapes (box corners, capsule ends) against the surfaces
  // the plan brings them within body_contact_range of (bodyContactPairs),
  // but those its own spots meet (modelled by the spots, as planned).
  // Elsewhere the body still passes through surfaces and obstacles. A
  // seated robot that tips back lands on its waist as the real one does
  // (the planner's thigh patches end 6 cm short of the hip). Their forces
  // are not in spotWrenches: the stabilizer's sensors do not see them.
  bool body_contacts = true;
  double body_contact_range = 0.02;  // m
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
  bool never_loaded = false;         // supporting in the plan, no force on it through the whole phase
  Eigen::Vector3d force = Eigen::Vector3d::Zero();       // N, world, simulated, at the phase's middle sample
  Eigen::Vector3d plan_force = Eigen::Vector3d::Zero();  // N, world, quasi-static LP at the same sample
  bool plan_force_known = false;     // the LP found forces there
};

// A contact the plan does not make: a link's collision shape on a surface.
struct BodyContactOutcome {
  std::string link, surface;
  double max_force = 0;              // N, the largest force it carried
  double first_time = 0;             // s, when it first carried any
  double loaded_time = 0;            // s, how long it carried any
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
  double stabilizer_on_time = 0;     // s of the trajectory with the stabilizer on
  double stabilizer_max_tilt = 0;    // rad, a foot's largest turn
  double stabilizer_max_lift = 0;    // m, a foot's largest rise (or fall)
  std::vector<BodyContactOutcome> body_contacts;  // those that carried force, by first time
  DynamicsOptions options;
  bool executed() const { return verdict == Verdict::Executed; }
};

const char* toString(SimulationReport::Verdict v);
std::string reportToJson(const SimulationReport& r);
void writeReport(const SimulationReport& r, const std::string& path);

// Progress: simulated time and the total to simulate.
using SimulationProgress = std::function<void(double t, double total)>;

// One controller period as simulated, for a trace (acyclic-simulate --trace).
struct SimulationSample {
  double t = 0;                      // s
  int phase = 0;
  bool stabilizer_on = false;
  Eigen::Vector3d com = Eigen::Vector3d::Zero(), plan_com = Eigen::Vector3d::Zero();   // world
  Eigen::Vector3d base = Eigen::Vector3d::Zero(), plan_base = Eigen::Vector3d::Zero(); // world
  double tilt = 0;                   // rad, base orientation against the plan
  // The same as a rotation vector in the world (simulated times the plan's
  // inverse): its x and y are the lean, its z the yaw.
  Eigen::Vector3d tilt_vector = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector3d> spot_forces;   // world, per robot spot
  // The zero-moment point of every contact wrench on the plane z = 0 (world
  // x-y; NaN without load), and the stabilizer's wanted one (NaN when it is
  // off or not modelled).
  Eigen::Vector2d zmp = Eigen::Vector2d::Constant(NAN), wanted_zmp = Eigen::Vector2d::Constant(NAN);
  // Each sole's turn by the stabilizer about its own x and y, rad (robot
  // spots order, soles only: hrp2::isFootSpot).
  std::vector<Eigen::Vector2d> foot_tilts;
};
using SimulationTrace = std::function<void(const SimulationSample&)>;

// Plays the trajectory at its controller rate (dt) from its first sample at
// rest, then holds the last reference for options.settle; stops early at a fall.
SimulationReport simulate(const Scenario& sc, const Trajectory& tr, const DynamicsOptions& options = {},
                          const SimulationProgress& progress = {}, const SimulationTrace& trace = {});

// The same simulator driven by a stream of references (the simulated
// controller's dynamic mode). Contacts: every spot against the floor (the
// lowest surfaces facing up), plus `pairs`.
struct JointSample {
  Eigen::VectorXd q, dq;
};

class DynamicsSimulator {
 public:
  // `pairs`: (spot, surface) the spots may touch besides the floor;
  // `body_pairs`: (link, surface) whose collision shapes may touch it
  // (bodyContactPairs).
  DynamicsSimulator(const Scenario& sc, const Configuration& start, const DynamicsOptions& options,
                    const std::vector<std::pair<int, int>>& pairs = {},
                    const std::vector<std::pair<int, int>>& body_pairs = {});
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
  // The same with their moment about each spot's origin (world).
  std::vector<SpotWrench> spotWrenches() const;
  // Sum of the contact forces on each of the body pairs given (world).
  std::vector<Eigen::Vector3d> bodyForces() const;
  long steps() const;

  struct Impl;
  Impl& impl() { return *impl_; }

 private:
  std::unique_ptr<Impl> impl_;
};

// The spot-surface pairs a trajectory's phases name (deduplicated).
std::vector<std::pair<int, int>> contactPairs(const Trajectory& tr);

// The link-surface pairs whose collision shapes (as the simulation's
// contact spheres: box corners of options.sphere_radius, capsule ends) come
// within options.body_contact_range of the surface, a sphere's centre over
// its polygon, at some sample of the trajectory (every tenth, each phase's
// first and the last), leaving out a link whose spots meet that surface
// (the pairs of contactPairs, and every spot the floor).
std::vector<std::pair<int, int>> bodyContactPairs(const Scenario& sc, const Trajectory& tr,
                                                  const DynamicsOptions& options);

}  // namespace acyclic::hrp2
