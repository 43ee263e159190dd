#pragma once
// A model of HRP-2's stabilizer for the dynamics simulation. The real robot
// runs its stabilizer whenever only coplanar feet touch (the paper, section
// 4; hrp2_bridge/stabilizer_schedule.h decides when) and plays the
// references open-loop otherwise. Without it, the simulation judges the
// feet-only phases harsher than the robot would: a position-servoed foot
// keeps whatever load the legs' geometry gives it (a foot the plan has
// unloaded still carries 150-240 N when it is lifted), and nothing moves the
// zero-moment point back when the soles' and servos' compliance tilts the
// robot toward the edge the plan's centre of mass is close to.
//
// The structure of Kajita et al.'s HRP-2 stabilizer (IROS 2010), reduced to
// what a slow quasi-static plan needs:
// - ZMP from the centre of mass: the wanted ZMP is the planned centre of
//   mass's projection plus zmp_com_gain times the centre of mass's error and
//   zmp_velocity_gain times its velocity's (measured minus planned, the
//   linear inverted pendulum's state feedback; the real robot estimates them
//   from its IMU and encoders, here they are the simulation's). The error is
//   taken relative to the supporting feet, as the robot's own estimate is:
//   the measured centre of mass is moved by the mean of the supporting soles'
//   offsets from their planned places (footholds drift a few millimetres per
//   step, and a world-frame error would count that drift as the body's);
// - distribution: a single supporting foot takes the whole load with its
//   centre of pressure at the wanted ZMP; two or more spread it over their
//   soles' corners (shrunk by cop_edge) with weights of least norm that put
//   the combined centre of pressure at the ZMP (the ZMP first moved into the
//   corners' hull): a sole's share is its corners' weights, its centre of
//   pressure their weighted mean. Staggered feet so share as the plan's
//   statics do (a ZMP just behind the front heel is held mostly by the rear
//   sole), where sharing by the ZMP's place between the soles' origins left
//   the front heel alone. A foot touching but not supporting wants no load;
// - foot damping control: each foot on the ground rises along its normal at
//   (f - f*) / force_damping (only when two or more feet are down: a single
//   foot's force is the weight) and turns about its own x and y axes at
//   cop_gain times its centre of pressure's error, so that its load goes
//   where it is wanted; each offset returns to the plan with its leak time;
// - swing foot placement: a sole in the air is moved toward the pose the plan
//   gives it relative to the supporting sole, measured (the body's tilt and
//   the legs' compliance otherwise carry it 2-4 mm off at each landing, and
//   the footholds drift from the plan step after step); a sole that meets
//   the floor early yields to the load it measures, as a landing foot's
//   force control does.
// Joint offsets come from the leg's Jacobian at the reference posture, the
// waist held. Switched off, or a foot in the air, offsets fade out with
// time constant off_time.
#include <memory>
#include <optional>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "planner/model/kinematics.h"
#include "planner/scene/scenario.h"

namespace acyclic::hrp2 {

// A spot's measured contact force and its moment about the spot's origin (world).
struct SpotWrench {
  Eigen::Vector3d force = Eigen::Vector3d::Zero();
  Eigen::Vector3d moment = Eigen::Vector3d::Zero();
  // The spot's frame (world), when measured: the stabilizer then judges the
  // centre of mass relative to where the supporting feet are, not to where
  // the plan put them, and places a swinging sole relative to them.
  std::optional<Eigen::Isometry3d> frame;
};

struct FeetStabilizerOptions {
  // Poles of the pendulum's error at about -3 /s for a 0.8 m high centre of
  // mass: s^2 + w^2 kv s + w^2 (kx - 1), w^2 = g / 0.8.
  double zmp_com_gain = 1.73;       // -
  double zmp_velocity_gain = 0.49;  // s
  double cop_gain = 5.0;            // rad/s per m of centre-of-pressure error
  double cop_leak = 2.0;            // s
  double max_tilt = 0.05;           // rad, a foot's turn at most
  double force_damping = 2e4;       // N s/m
  double force_leak = 1.0;          // s
  double max_lift = 0.01;           // m, a foot's rise (or fall) at most
  double cop_edge = 0.005;          // m, wanted centres of pressure this far inside a sole's edges
  double off_time = 0.3;            // s
  // A sole in the air is moved to its planned pose relative to the
  // supporting sole (measured frames, through the measured waist), the move
  // followed with this time constant and bounded by max_place (m) and
  // max_place_turn (rad); on the ground it returns to the plan with
  // place_leak.
  double place_time = 0.1;          // s
  double max_place = 0.03;          // m
  double max_place_turn = 0.1;      // rad
  double place_leak = 2.0;          // s
  void validate() const;            // std::invalid_argument naming the bad value
};

class FeetStabilizer {
 public:
  FeetStabilizer(std::shared_ptr<const RobotModel> robot, std::shared_ptr<const Scene> scene,
                 const FeetStabilizerOptions& options);

  // One control period of dt s. `on`: the schedule's flag for this sample;
  // `plan`: the reference configuration; `contacts`: its phase's contacts;
  // `com`: the measured centre of mass (world); `wrenches`: the measured
  // wrench on each spot (robot.spots() order); `waist`: the measured base
  // pose, if known (a swinging sole is placed only then). Returns the offsets
  // to add to the joint references (controller order).
  Eigen::VectorXd update(double dt, bool on, const Configuration& plan, const std::vector<ContactSpec>& contacts,
                         const Eigen::Vector3d& com, const std::vector<SpotWrench>& wrenches,
                         const std::optional<Eigen::Isometry3d>& waist = std::nullopt);

  double lift(int spot) const { return lift_.at(spot); }             // m, a foot's rise
  Eigen::Vector2d tilt(int spot) const { return tilt_.at(spot); }    // rad, a foot's turn about its x and y
  // A sole's move toward its planned place relative to the supporting sole
  // (world: m, then a rotation vector in rad).
  Eigen::Matrix<double, 6, 1> placement(int spot) const { return place_.at(spot); }
  Eigen::Vector2d wantedZmp() const { return zmp_; }                 // world x-y, the last period's
  // The last period's wanted normal force on a sole and its wanted centre of
  // pressure (world x-y); zero for a sole not down.
  double wantedLoad(int spot) const { return want_load_.at(spot); }
  Eigen::Vector2d wantedCop(int spot) const { return want_cop_.at(spot); }

 private:
  std::shared_ptr<const RobotModel> robot_;
  std::shared_ptr<const Scene> scene_;
  FeetStabilizerOptions opt_;
  Kinematics kin_;
  std::vector<int> feet_;                 // the sole spots
  std::vector<std::vector<int>> leg_;     // per foot: its joints, base to foot
  std::vector<double> lift_;              // per spot
  std::vector<Eigen::Vector2d> tilt_;     // per spot
  std::vector<Eigen::Matrix<double, 6, 1>> place_;  // per spot: a swinging sole's move (world, translation then rotation)
  std::vector<double> want_load_;         // per spot
  std::vector<Eigen::Vector2d> want_cop_; // per spot, world x-y
  Eigen::Vector2d zmp_ = Eigen::Vector2d::Zero();
  // Centre-of-mass velocities by differences, measured and planned.
  bool has_last_ = false;
  Eigen::Vector3d last_com_, last_plan_com_;
  Eigen::Vector3d com_velocity_ = Eigen::Vector3d::Zero();
};

}  // namespace acyclic::hrp2
