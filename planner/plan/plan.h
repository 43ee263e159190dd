#pragma once
// A contact plan and its file format, acyclic.plan/1 (JSON, docs/design.md section 8).
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "planner/scene/scenario.h"

namespace acyclic {

struct PlanContact {
  ContactSpec spec;
  // World pose of the contact frame on the surface, and (supporting only)
  // the world corner points and the forces on them.
  Eigen::Isometry3d frame = Eigen::Isometry3d::Identity();
  std::vector<Eigen::Vector3d> points, forces;
};

struct PlanStance {
  std::vector<PlanContact> contacts;
  Configuration configuration;
  double potential = 0;
  std::vector<ContactSpec> specs() const;
};

struct PlanStats {
  long nodes_generated = 0, nodes_expanded = 0, posture_calls = 0, posture_failures = 0;
  double seconds = 0;
};

struct Plan {
  std::string scenario;   // the scenario file it answers (as given to the planner)
  std::string robot;      // the robot description it uses
  // The planner-section keys given on the planner's command line (`--set
  // KEY=VALUE`, in order), which its scenario file does not hold: the
  // interpolator applies them before its own, so that the plan is
  // interpolated as it was verified. Empty: the file's keys alone.
  std::vector<std::string> planner_settings;
  std::vector<PlanStance> stances;
  PlanStats stats;
};

// Writes a plan; joint and contact names come from the scenario's robot and scene.
void writePlan(const Plan& plan, const Scenario& sc, const std::string& path);
std::string planToJson(const Plan& plan, const Scenario& sc);
// Reads a plan against a scenario; FormatError naming the file and field on bad input.
Plan readPlan(const std::string& path, const Scenario& sc);
Plan planFromJson(const std::string& text, const std::string& origin, const Scenario& sc);

// How two stances differ: contacts (spot, surface, placement within 1 mm and
// 1 degree) added, removed, or kept with their supporting flag changed.
struct StanceDiff {
  int added = 0, removed = 0, flipped = 0;
  int changes() const { return added + removed + flipped; }
};
StanceDiff diffStances(const std::vector<ContactSpec>& a, const std::vector<ContactSpec>& b);

// What changes between two consecutive stances (docs/design.md section 8): exactly
// one contact added, one removed, or one contact's supporting flag flipped.
// Returns an empty string when the step is one of those, otherwise why not.
std::string checkStep(const PlanStance& a, const PlanStance& b, const Scenario& sc);

}  // namespace acyclic
