#pragma once
// What the viewer page shows, computed in C++ with the project's own model:
// the world pose of every robot collision shape, the centre of mass and the
// contacts (outline, corner points, forces) of each plan stance and of each
// displayed trajectory frame. Nothing here changes a posture: stances are the
// plan's, frames are the trajectory's own samples (the nearest one to each
// display time), never interpolated.
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "planner/plan/plan.h"
#include "planner/plan/trajectory.h"
#include "planner/scene/scenario.h"

namespace acyclic {

struct ViewContact {
  int spot = -1, surface = -1;
  bool supporting = false;
  Eigen::Isometry3d frame = Eigen::Isometry3d::Identity();  // world pose of the contact frame
  std::vector<Eigen::Vector3d> outline;  // the spot's polygon, world
  std::vector<Eigen::Vector3d> points, forces;  // supporting only: corners and the forces on them (N, world)
};

struct ViewPosture {
  double t = 0;          // s (frames); 0 for stances
  int stance = -1;       // the plan stance it shows or whose phase it belongs to (-1: none)
  int phase = -1;        // trajectory phase (frames only)
  int sample = -1;       // trajectory sample index (frames only)
  Configuration q;
  std::vector<Eigen::Isometry3d> shape_poses;  // world, in the order of viewShapes()
  Eigen::Vector3d com = Eigen::Vector3d::Zero();
  std::vector<ViewContact> contacts;
  // The independent quasi-static check (planner/check/quasi_static.h) at this
  // posture with its supporting contacts: the friction margin (N) of LP 1.
  bool forces_from_check = false;  // the forces shown are the check's (LP 2), not the plan's
  bool feasible = false;
  double margin = 0;
  double worst_torque_ratio = 0;
  double worst_cone_ratio = 0;  // max ||f_t|| / (mu f_n) of the check's forces (LP 2): at most 1, in the cone
};

// One robot collision shape: its link and its index among the link's shapes.
struct ViewShape {
  int link = -1, index = -1;
};
std::vector<ViewShape> viewShapes(const RobotModel& robot);

// Each plan stance: shapes, CoM, contacts with the plan's own points and forces.
std::vector<ViewPosture> stancePostures(const Scenario& sc, const Plan& plan);

// The trajectory at `fps` frames per second from t = 0 to its end (the last
// sample included): each frame is the sample nearest its time, with its phase's
// contacts and the forces of the independent quasi-static check.
std::vector<ViewPosture> trajectoryFrames(const Scenario& sc, const Trajectory& tr, double fps);

struct ViewSources {
  std::string scenario, plan, trajectory;  // file names, shown on the page
};

// The page's data, format acyclic.view/1, as a JSON object (text). The page
// loads it as `window.ACYCLIC_DATA = ...;` (data.js), which works from file://
// where fetching a JSON file does not.
std::string viewDataJson(const Scenario& sc, const Plan& plan, const std::vector<ViewPosture>& stances,
                         const std::vector<ViewPosture>& frames, double fps, const ViewSources& src);

}  // namespace acyclic
