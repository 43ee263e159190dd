#pragma once
// A planning problem: robot, scene, start configuration and stance, allowed
// contacts, goal condition, optional hand-written key postures, seed.
// Format acyclic.scenario/1, documented in docs/design.md section 5.
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "planner/common/yaml_field.h"
#include "planner/model/robot_model.h"
#include "planner/scene/scene.h"

namespace acyclic {

class Kinematics;

struct ContactSpec {
  int spot = -1;
  int surface = -1;
  bool supporting = true;
  SurfacePlacement placement;
};

// The goal: a coordinate of a link's origin within bounds (paper, 3.1: "a
// coordinate the waist must exceed"), and optionally spots that must support
// the goal stance (without them a robot that may lean on its hands can meet a
// waist bound by hanging on them, its feet in the air).
struct GoalCondition {
  int link = 0;
  int axis = 0;  // 0 x, 1 y, 2 z
  double min = -std::numeric_limits<double>::infinity();
  double max = std::numeric_limits<double>::infinity();
  std::vector<int> supporting_spots;  // each in contact and supporting in the goal stance
  // The link bound alone, for a posture without a stance (a guide's last key posture).
  bool linkWithinBounds(const Kinematics& k) const;
  // The whole goal, for the witness k of a stance.
  bool satisfied(const Kinematics& k, const std::vector<ContactSpec>& stance) const;
  std::string describe(const RobotModel& m) const;
};

// Published figures for the problem a scenario reproduces (chair_paper: the
// paper's own run), printed beside the planner's by bench_scenarios; 0 where
// the source gives none.
struct PublishedRun {
  std::string source;   // who published it, where
  long nodes = 0;       // nodes generated
  long stances = 0;     // sets of contacts in the plan
  double seconds = 0;   // planning time
  std::string machine;  // what it ran on
};

struct Scenario {
  std::string path;
  std::string name;
  std::shared_ptr<const RobotModel> robot;
  std::shared_ptr<const Scene> scene;
  Configuration start;
  std::vector<ContactSpec> start_stance;
  std::vector<int> allowed_spots;
  std::vector<int> allowed_surfaces;
  // Pairs (spot, surface) the planner never makes although the spot and the
  // surface are both allowed (chair_paper: the soles and knees never on the
  // chair's seat, as the paper's robot kept them). The start may hold one.
  std::vector<std::pair<int, int>> forbidden_contacts;
  GoalCondition goal;
  std::vector<Configuration> key_postures;
  std::uint64_t seed = 1;
  // The optional `planner:` section, read and validated by the planner
  // (planner/search/planner_parameters.h); absent: the planner's defaults.
  std::optional<YamlField> planner_section;
  std::optional<PublishedRun> published;  // the optional `published:` section

  // Loads a scenario file; robot and scene paths resolve against its folder.
  static Scenario load(const std::string& path);
  // The same from text (e.g. a request message); paths resolve against base_dir.
  static Scenario loadText(const std::string& text, const std::string& origin, const std::string& base_dir);

  std::string describe(const ContactSpec& c) const;  // "r_sole@floor (supporting)"
  // Whether the planner may put `spot` on `surface`: both allowed, the pair
  // not forbidden.
  bool allows(int spot, int surface) const;
};

}  // namespace acyclic
