#include "planner/guide/guide_author.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <utility>
#include <vector>

#include <ompl/base/spaces/RealVectorStateSpace.h>
#include <ompl/geometric/PathSimplifier.h>
#include <ompl/geometric/SimpleSetup.h>
#include <ompl/geometric/planners/rrt/RRTConnect.h>
#include <ompl/util/Console.h>

#include "planner/check/validity.h"
#include "planner/collision/collision_model.h"
#include "planner/common/fmt.h"
#include "planner/common/geometry.h"
#include "planner/guide/guide_postures.h"
#include "planner/guide/seeded_ompl.h"
#include "planner/guide/stable_path.h"
#include "planner/posture/posture_generator.h"

namespace ob = ompl::base;
namespace og = ompl::geometric;

namespace acyclic {

const char* toString(GuideResult::Status s) {
  switch (s) {
    case GuideResult::Status::Success: return "success";
    case GuideResult::Status::InvalidStart: return "invalid start";
    case GuideResult::Status::NoGoalPosture: return "no goal posture";
    case GuideResult::Status::NoPath: return "no path";
    case GuideResult::Status::Cancelled: return "cancelled";
  }
  return "?";
}

namespace {

double now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

double yawOf(const Eigen::Quaterniond& q) {
  const Eigen::Matrix3d R = q.toRotationMatrix();
  return std::atan2(R(1, 0), R(0, 0));
}

// The reduced space: (x, y, z, yaw, alpha), and with a crouch a sixth
// coordinate c. alpha blends the joints and the base's tilt from the start
// posture (0) to the goal posture (1); c adds c times the crouch's joint
// offsets (the start stance lowered on its feet, crouchOffsets).
struct Lift {
  Configuration start, goal;
  double yaw_start = 0, yaw_goal = 0;
  Eigen::VectorXd crouch;  // joint offsets; empty: no crouch coordinate
  Configuration operator()(const double* s) const {
    const double a = std::clamp(s[4], 0.0, 1.0);
    Configuration q;
    q.base_position = Eigen::Vector3d(s[0], s[1], s[2]);
    const Eigen::Quaterniond tilt = start.base_orientation.slerp(a, goal.base_orientation);
    const double yaw_blend = (1 - a) * yaw_start + a * yaw_goal;
    q.base_orientation = Eigen::Quaterniond(Eigen::AngleAxisd(s[3] - yaw_blend, Eigen::Vector3d::UnitZ())) * tilt;
    q.base_orientation.normalize();
    q.joints = (1 - a) * start.joints + a * goal.joints;
    if (crouch.size()) q.joints += std::clamp(s[5], 0.0, 1.0) * crouch;
    return q;
  }
};

// Valid: every robot-environment pair at least -penetration apart. Self
// pairs are left out: the joints blend between two valid postures.
// A surface whose outward normal is within 10 degrees of straight up: one to stand on.
constexpr double kLevelSurface = 0.985;

// The ground under a point: the highest surface the scenario allows whose
// outward normal is within 45 degrees of straight up and whose polygon holds
// the point's vertical projection (its plane's height there); none: nullopt.
std::optional<double> groundUnder(const Scenario& sc, double x, double y) {
  std::optional<double> best;
  for (int si : sc.allowed_surfaces) {
    const Surface& surf = sc.scene->surfaces()[si];
    const Eigen::Vector3d n = surf.frame.linear().col(2), o = surf.frame.translation();
    if (n.z() < std::cos(M_PI / 4)) continue;
    const double z = o.z() - (n.x() * (x - o.x()) + n.y() * (y - o.y())) / n.z();
    const Eigen::Vector3d local = surf.frame.inverse() * Eigen::Vector3d(x, y, z);
    if (!surf.polygon.contains(local.head<2>())) continue;
    if (!best || z > *best) best = z;
  }
  return best;
}

// Valid: every robot-environment pair at least -penetration apart, and,
// with a ceiling, the base no higher above the ground within a step of it
// than the ceiling (a robot can raise its base above what it stands on only by its
// standing height: a path that floats up before it reaches a step gives the
// planner a valley no stance can follow). Self pairs are left out: the
// joints blend between two valid postures.
class RelaxedValidity : public ob::StateValidityChecker {
 public:
  RelaxedValidity(const ob::SpaceInformationPtr& si, const Scenario& sc, const Lift& lift, double penetration)
      : ob::StateValidityChecker(si), sc_(sc), lift_(lift), kin_(sc.robot), collision_(sc.robot, sc.scene),
        penetration_(penetration) {}
  void setCeiling(double above_ground) { ceiling_ = above_ground; }
  // A ball of the reduced space left out (around a sample that did not
  // project into the statically stable subspace).
  void forbid(Eigen::VectorXd centre, double radius) { forbidden_.push_back({std::move(centre), radius}); }
  const long& checks() const { return checks_; }  // states checked so far
  // The base's height above the ground within a step of it (the highest
  // under its point and the corners and edge middles of a square 2 kStep
  // wide around it: a foot put up there lets the base rise); nullopt: no ground.
  std::optional<double> heightAboveGround(const double* s) const {
    constexpr double kStep = 0.25;  // m
    std::optional<double> g;
    for (int i = -1; i <= 1; ++i)
      for (int j = -1; j <= 1; ++j) {
        const auto h = groundUnder(sc_, s[0] + i * kStep, s[1] + j * kStep);
        if (h && (!g || *h > *g)) g = h;
      }
    if (!g) return std::nullopt;
    return s[2] - *g;
  }
  bool isValid(const ob::State* state) const override {
    ++checks_;
    const double* s = state->as<ob::RealVectorStateSpace::StateType>()->values;
    for (const auto& [centre, radius] : forbidden_)
      if ((Eigen::Map<const Eigen::VectorXd>(s, centre.size()) - centre).norm() < radius) return false;
    if (ceiling_) {
      const auto h = heightAboveGround(s);
      if (h && *h > *ceiling_) return false;
    }
    kin_.setConfiguration(lift_(s));
    DistanceOptions o;
    o.cutoff = 0.0;  // only pairs whose bounding volumes may touch
    for (const auto& d : collision_.distances(kin_, o))
      if (collision_.pairs()[d.pair].kind == CollisionPair::Kind::RobotEnvironment && d.distance < -penetration_)
        return false;
    return true;
  }

 private:
  const Scenario& sc_;
  const Lift& lift_;
  mutable Kinematics kin_;
  CollisionModel collision_;
  double penetration_;
  std::optional<double> ceiling_;
  std::vector<std::pair<Eigen::VectorXd, double>> forbidden_;
  mutable long checks_ = 0;
};

// Each contact placed where kin holds its spot, supporting; false if one
// lies off its surface's polygon (carried off it).
bool placeWhereHeld(const Scenario& sc, const Kinematics& kin, std::vector<ContactSpec>& contacts) {
  bool on = true;
  for (auto& c : contacts) {
    const Surface& surf = sc.scene->surfaces()[c.surface];
    c.placement = projectOnSurface(surf, kin.spotPose(c.spot));
    c.supporting = true;
    on = on && surf.polygon.contains(Eigen::Vector2d(c.placement.x, c.placement.y));
  }
  return on;
}

// The start's contacts that are not among the goal's supports (the soles of
// a robot that sits down).
std::vector<ContactSpec> startContactsBesideSupports(const Scenario& sc) {
  const std::vector<int>& supports = sc.goal.supporting_spots;
  std::vector<ContactSpec> out;
  for (const auto& c : sc.start_stance)
    if (std::find(supports.begin(), supports.end(), c.spot) == supports.end()) out.push_back(c);
  return out;
}

// Whether the scenario lets every goal support rest on surface si
// (forbidden_contacts).
bool supportsAllowedOn(const Scenario& sc, int si) {
  for (int spot : sc.goal.supporting_spots)
    if (!sc.allows(spot, si)) return false;
  return true;
}

// A level surface no start contact is on (a seat to sit on).
bool levelSurfaceOffStart(const Scenario& sc, int si) {
  for (const auto& c : sc.start_stance)
    if (c.surface == si) return false;
  return sc.scene->surfaces()[si].frame.linear().col(2).z() >= kLevelSurface;
}

// A surface's polygon's centroid, in the world.
Eigen::Vector3d surfaceMiddle(const Surface& surf) {
  const Eigen::Vector2d c = surf.polygon.centroid();
  return surf.frame * Eigen::Vector3d(c.x(), c.y(), 0);
}

// A contact of `spot` floating over the whole of `surface` (touching, not
// supporting): added as the planner adds one.
FloatingContact overSurface(const Scenario& sc, int spot, int surface) {
  FloatingContact f;
  f.spot = spot;
  f.surface = surface;
  f.volume.polygon = sc.scene->surfaces()[surface].polygon;
  return f;
}

// A goal posture: a witness of `contacts` (placed where `q` puts their spots)
// from the guess q, accepted by the independent check, in the goal (the
// link's bound, and the supports the goal names).
bool solveGoalStance(const Scenario& sc, PostureGenerator& pg, ValidityChecker& checker, Kinematics& kin,
                     const Configuration& q, std::vector<ContactSpec> contacts, Configuration& out) {
  kin.setConfiguration(q);
  if (!placeWhereHeld(sc, kin, contacts)) return false;
  PostureRequest r;
  r.contacts = contacts;
  r.initial_guess = q;
  const PostureResult res = pg.solve(r);
  if (!res.success()) return false;
  if (!checker.checkPosture(res.configuration, contacts).valid()) return false;
  kin.setConfiguration(res.configuration);
  if (!sc.goal.satisfied(kin, contacts)) return false;
  out = res.configuration;
  return true;
}

// The goal's supports added to a stance one at a time, as the planner adds
// a contact: each floating over `surface` and touching only, from the last
// witness; then the whole stance with every contact supporting, checked and
// in the goal.
bool addSupports(const Scenario& sc, PostureGenerator& pg, ValidityChecker& checker, Kinematics& kin,
                 std::vector<ContactSpec> stance, int surface, Configuration q, Configuration& out) {
  const Surface& surf = sc.scene->surfaces()[surface];
  for (int s : sc.goal.supporting_spots) {
    bool held = false;  // a start contact already (a crouch on the feet)
    for (const auto& c : stance) held = held || c.spot == s;
    if (held) continue;
    PostureRequest r;
    r.contacts = stance;
    r.initial_guess = q;
    r.floating = overSurface(sc, s, surface);
    const PostureResult res = pg.solve(r);
    if (!res.success()) return false;
    q = res.configuration;
    kin.setConfiguration(q);
    ContactSpec c;
    c.spot = s;
    c.surface = surface;
    c.supporting = false;
    c.placement = projectOnSurface(surf, kin.spotPose(s));  // the spot's own in-plane angle (not modulo pi)
    stance.push_back(c);
  }
  return solveGoalStance(sc, pg, checker, kin, q, stance, out);
}

// A posture resting on the goal's supports, for a goal on the link's height
// (sitting down, kneeling), as the planner gets there: the start stance
// carried toward a surface the supports may rest on, lowered on its own
// contacts (a squat), then the supports added (addSupports: touching first,
// the start's contacts holding the robot). Carried by distances around the surface's
// nearest point (where a sitting robot's feet go: in front of the seat),
// nearest that point first, then in front of the surface along the start's
// heading (0 to 40 cm past its front edge, across it at its middle), at
// most `support_attempts` in all. Every
// support on one surface (both thighs on a seat, both knees on the floor).
bool goalPostureOnSupports(const Scenario& sc, const GuideOptions& o, PostureGenerator& pg, ValidityChecker& checker,
                           Kinematics& kin, Configuration& out) {
  const GoalCondition& g = sc.goal;
  if (g.supporting_spots.empty()) return false;
  kin.setConfiguration(sc.start);
  const double link_z = kin.linkPose(g.link).translation().z();
  const double target = std::isfinite(g.max) ? g.max - o.goal_margin : g.min + o.goal_margin;
  const Eigen::Vector2d from = sc.start.base_position.head<2>();
  struct Candidate {
    double order;
    Eigen::Vector2d shift;
    int surface;
  };
  std::vector<Candidate> candidates;
  for (int si : sc.allowed_surfaces) {
    if (!supportsAllowedOn(sc, si)) continue;
    const Surface& surf = sc.scene->surfaces()[si];
    // The surface's point nearest the start's base, in the surface's plane
    // (the base itself when it is over the surface).
    const Eigen::Vector2d local = (surf.frame.inverse() * sc.start.base_position).head<2>();
    const Eigen::Vector2d nearest_local = surf.polygon.contains(local) ? local : surf.polygon.nearestBoundaryPoint(local);
    const Eigen::Vector2d nearest = (surf.frame * Eigen::Vector3d(nearest_local.x(), nearest_local.y(), 0)).head<2>();
    const double best = (nearest - from).norm();  // horizontal
    const Eigen::Vector2d dir = best > 1e-9 ? Eigen::Vector2d((nearest - from) / best) : Eigen::Vector2d::Zero();
    for (double d = std::max(0.0, best - 0.15); d <= best + 0.15 + 1e-9; d += 0.05) {
      candidates.push_back({std::abs(d - best), d * dir, si});
      if (best <= 1e-9) break;  // on it: no direction to carry
    }
    // Then in front of a level surface other than the start's, along the
    // start's heading, the base over the surface's middle across it: where
    // a robot that starts beside the seat (or at an angle to it) sits down
    // from, with its back to the surface. The carried stance keeps its heading.
    if (!levelSurfaceOffStart(sc, si)) continue;
    const double yaw = yawOf(sc.start.base_orientation);
    const Eigen::Vector2d heading(std::cos(yaw), std::sin(yaw));
    const Eigen::Vector2d centre = surfaceMiddle(surf).head<2>();
    double front = 0;  // the surface's extent ahead of its middle along the heading
    for (const auto& v : surf.polygon.vertices())
      front = std::max(front, ((surf.frame * Eigen::Vector3d(v.x(), v.y(), 0)).head<2>() - centre).dot(heading));
    for (double d = 0.0; d <= 0.4 + 1e-9; d += 0.05)
      candidates.push_back({1.0 + d, centre + (front + d) * heading - from, si});
  }
  std::stable_sort(candidates.begin(), candidates.end(),
                   [](const Candidate& a, const Candidate& b) { return a.order < b.order; });
  for (std::size_t i = 0; i < candidates.size() && static_cast<int>(i) < o.support_attempts; ++i) {
    Configuration q = sc.start;
    q.base_position.head<2>() += candidates[i].shift;
    kin.setConfiguration(q);
    std::vector<ContactSpec> stance = sc.start_stance;
    if (!placeWhereHeld(sc, kin, stance)) continue;
    // Lowered on the start's contacts: its goal link pulled to the bound, the
    // joints free to fold (a squat over the feet before the seat is touched).
    Configuration lowered = q;
    lowered.base_position.z() += target - link_z;
    const auto squat = witnessNear(pg, stance, q, lowered);
    if (squat && addSupports(sc, pg, checker, kin, stance, candidates[i].surface, *squat, out)) return true;
  }
  return false;
}

// A seated posture resting on the goal's supports, for a seat at a table
// (where the start stance carried toward the seat meets the table): the
// robot's seated posture (GuideOptions::seated_posture) turned to the start's
// heading, the supports' middle put over the middle of a level surface they
// may rest on (then 5 and 10 cm back and forth along the heading); first
// resting on the supports alone, then each other start contact (a sole) added
// floating over its surface, touching, as the planner adds one; then the
// whole stance supporting, accepted by the check and in the goal.
bool goalPostureSeated(const Scenario& sc, const GuideOptions& o, PostureGenerator& pg, ValidityChecker& checker,
                       Kinematics& kin, Configuration& out) {
  const RobotModel& m = *sc.robot;
  const GoalCondition& g = sc.goal;
  if (g.supporting_spots.empty() || !m.postures().count(o.seated_posture)) return false;
  Configuration seated = m.posture(o.seated_posture);
  const double yaw = yawOf(sc.start.base_orientation);
  seated.base_orientation = Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()));
  seated.base_position.head<2>() = sc.start.base_position.head<2>();
  kin.setConfiguration(seated);
  Eigen::Vector3d supports = Eigen::Vector3d::Zero();
  for (int s : g.supporting_spots) supports += kin.spotPose(s).translation();
  supports /= static_cast<double>(g.supporting_spots.size());
  const Eigen::Vector2d heading(std::cos(yaw), std::sin(yaw));
  const std::vector<ContactSpec> others = startContactsBesideSupports(sc);
  for (int si : sc.allowed_surfaces) {
    if (!levelSurfaceOffStart(sc, si) || !supportsAllowedOn(sc, si)) continue;
    const Eigen::Vector3d middle = surfaceMiddle(sc.scene->surfaces()[si]);
    for (double d : {0.0, -0.05, 0.05, -0.1, 0.1}) {
      Configuration q = seated;
      q.base_position += middle - supports;
      q.base_position.head<2>() += d * heading;
      kin.setConfiguration(q);
      std::vector<ContactSpec> stance;
      for (int s : g.supporting_spots) {
        ContactSpec c;
        c.spot = s;
        c.surface = si;
        stance.push_back(c);
      }
      if (!placeWhereHeld(sc, kin, stance)) continue;
      const auto resting = witnessNear(pg, stance, q, q);
      if (!resting) continue;
      Configuration at = *resting;
      bool added = true;
      for (const auto& other : others) {
        const Surface& on = sc.scene->surfaces()[other.surface];
        PostureRequest a;
        a.contacts = stance;
        a.initial_guess = at;
        a.floating = overSurface(sc, other.spot, other.surface);
        const PostureResult ar = pg.solve(a);
        if (!ar.success()) {
          added = false;
          break;
        }
        at = ar.configuration;
        kin.setConfiguration(at);
        ContactSpec c = other;
        c.supporting = false;
        c.placement = projectOnSurface(on, kin.spotPose(other.spot));
        stance.push_back(c);
      }
      if (added && solveGoalStance(sc, pg, checker, kin, at, stance, out)) return true;
    }
  }
  return false;
}

// A posture in the goal region. First standing: the named standing posture
// moved there, feet put on the start's floor surface or on a level surface
// above it (standingSurfaces). Failing that (a robot
// that cannot stand on its feet alone there, as on the wet ramp), the start
// stance carried there: the start posture moved along the goal's axis, each
// start contact put on its surface where the moved posture holds its spot.
// Each through the posture generator and the independent check, the free
// horizontal coordinate tried around the start's, nearest first.

bool goalPosture(const Scenario& sc, const GuideOptions& o, PostureTools& t, Configuration& out, std::string& why) {
  const RobotModel& m = *sc.robot;
  if (!m.postures().count(o.standing_posture)) {
    why = "the robot has no posture named '" + o.standing_posture + "'";
    return false;
  }
  const int r_sole = m.spotIndex("r_sole"), l_sole = m.spotIndex("l_sole");
  int floor = -1;
  for (const auto& c : sc.start_stance)
    if (c.spot == r_sole || c.spot == l_sole) floor = c.surface;
  if (r_sole < 0 || l_sole < 0 || floor < 0) {
    why = "the start stance has no sole on a surface to stand on";
    return false;
  }
  const GoalCondition& g = sc.goal;
  const double yaw = yawOf(sc.start.base_orientation);
  Kinematics& kin = t.kin;
  PostureGenerator& pg = t.pg;
  ValidityChecker& checker = t.checker;
  if (g.axis == 2) {  // a height: nothing to carry along; only a posture on the goal's supports
    if (goalPostureOnSupports(sc, o, pg, checker, kin, out)) return true;
    if (goalPostureSeated(sc, o, pg, checker, kin, out)) return true;
    why = g.supporting_spots.empty()
              ? "a goal on the vertical axis needs supported_by: the guide author rests the robot on those spots"
              : "no valid posture resting on the goal's supports found in the goal region (" + g.describe(m) +
                    ") in " + std::to_string(o.support_attempts) + " placements of the start stance, nor with the '" +
                    o.seated_posture + "' posture over a level surface they may rest on";
    return false;
  }
  Configuration standing = m.posture(o.standing_posture);
  standing.base_orientation = Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()));
  const double bound = std::isfinite(g.min) ? g.min + o.goal_margin : g.max - o.goal_margin;
  const int free_axis = g.axis == 0 ? 1 : 0;
  std::vector<double> offsets = {0.0};
  for (double d = 0.1; d <= o.goal_search + 1e-9; d += 0.1) offsets.push_back(d), offsets.push_back(-d);
  // Where the goal link sits relative to the base, standing and at the start.
  kin.setConfiguration(standing);
  const Eigen::Vector3d standing_offset = kin.linkPose(g.link).translation() - standing.base_position;
  kin.setConfiguration(sc.start);
  const Eigen::Vector3d start_offset = kin.linkPose(g.link).translation() - sc.start.base_position;
  // Where to stand: the start's floor, or a level surface the scenario
  // allows (a platform, a step) under both feet, the highest first: a goal
  // beyond a step's edge is met standing on the step, not in it.
  const double floor_height = sc.scene->surfaces()[floor].frame.translation().z();
  auto standingSurfaces = [&](const Configuration& q) {
    kin.setConfiguration(q);
    std::vector<std::pair<double, int>> under;  // height, surface
    for (int s : sc.allowed_surfaces) {
      const Surface& surf = sc.scene->surfaces()[s];
      if (s != floor && surf.frame.linear().col(2).z() < kLevelSurface) continue;
      if (!sc.allows(r_sole, s) || !sc.allows(l_sole, s)) continue;  // forbidden_contacts
      bool both = true;
      for (int spot : {r_sole, l_sole}) {
        const Eigen::Vector3d p = surf.frame.inverse() * kin.spotPose(spot).translation();
        both = both && surf.polygon.contains(p.head<2>());
      }
      if (both) under.push_back({surf.frame.translation().z(), s});
    }
    std::sort(under.begin(), under.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
    return under;
  };
  std::vector<ContactSpec> feet(2);
  feet[0].spot = r_sole, feet[1].spot = l_sole;
  for (double off : offsets) {
    Configuration q = standing;
    q.base_position[g.axis] = bound - standing_offset[g.axis];
    q.base_position[free_axis] = sc.start.base_position[free_axis] + off;
    for (const auto& [height, surface] : standingSurfaces(q)) {
      Configuration raised = q;
      raised.base_position.z() += height - floor_height;
      feet[0].surface = feet[1].surface = surface;
      if (solveGoalStance(sc, pg, checker, kin, raised, feet, out)) return true;
    }
  }
  for (double off : offsets) {
    Configuration q = sc.start;
    q.base_position[g.axis] = bound - start_offset[g.axis];
    q.base_position[free_axis] += off;
    if (solveGoalStance(sc, pg, checker, kin, q, sc.start_stance, out)) return true;
  }
  why = "no valid standing posture, nor the start stance carried there, found in the goal region (" +
        g.describe(m) + ") within " + std::to_string(o.goal_search) + " m of the start";
  return false;
}

// A standing posture from which a goal resting on supports the start does
// not have (sitting down) is entered: the robot's standing posture turned to
// the goal's heading, its soles (the start's contacts that are not the
// goal's supports) in line with where the goal posture has them, as far in
// front of them along that heading as the start is (at most 0.3 m), then
// nearer and farther; through the posture generator on those contacts and
// the independent check. A person walks in front of the seat and then backs
// onto it: a path blending standing into sitting on the way from beside the
// seat is clear of the scene, but the planner's stances cannot follow it
// (sit_at_table: no plan in 3,000 nodes). False when there is none or the
// goal needs none: supports among the start's contacts, or the start within
// 0.1 m of it and facing within 20 degrees of the same way (sit_down: the
// straight blend is planned in 81 nodes, walking back to the seat's edge
// first in more than 300).
bool approachPosture(const Scenario& sc, const GuideOptions& o, PostureTools& t, const Configuration& goal,
                     Configuration& out) {
  const RobotModel& m = *sc.robot;
  const GoalCondition& g = sc.goal;
  if (g.supporting_spots.empty() || !m.postures().count(o.standing_posture)) return false;
  const std::vector<ContactSpec> feet = startContactsBesideSupports(sc);
  // Some goal support is not a start contact: fewer start contacts are supports than the goal names.
  const bool new_support = sc.start_stance.size() - feet.size() < g.supporting_spots.size();
  if (!new_support || feet.empty()) return false;
  Kinematics& kin = t.kin;
  auto feetMiddle = [&](const Configuration& q) {
    kin.setConfiguration(q);
    Eigen::Vector3d mid = Eigen::Vector3d::Zero();
    for (const auto& c : feet) mid += kin.spotPose(c.spot).translation();
    return Eigen::Vector3d(mid / static_cast<double>(feet.size()));
  };
  const Eigen::Vector3d goal_feet = feetMiddle(goal);
  const double yaw = yawOf(goal.base_orientation);
  Configuration standing = m.posture(o.standing_posture);
  standing.base_orientation = Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()));
  const Eigen::Vector3d standing_feet = feetMiddle(standing);
  // The start's feet over their surfaces: the height to stand at.
  const Eigen::Vector3d start_feet = feetMiddle(sc.start);
  const Eigen::Vector3d heading(std::cos(yaw), std::sin(yaw), 0);
  // As far in front as the start is (at most 0.3 m): from there the robot
  // backs onto the seat as from sit_down's start; then nearer and farther.
  const double along = std::clamp((start_feet - goal_feet).dot(heading), 0.0, 0.3);
  auto placed = [&](double d) {
    Configuration q = standing;
    q.base_position += goal_feet - standing_feet + (along + d) * heading;
    q.base_position.z() = standing.base_position.z() + start_feet.z() - standing_feet.z();
    return q;
  };
  // In line already: the start stands where the first placement would, facing the same way.
  const double turn = std::abs(std::remainder(yawOf(sc.start.base_orientation) - yaw, 2 * M_PI));
  if ((placed(0).base_position - sc.start.base_position).head<2>().norm() < 0.1 && turn < 0.35) return false;
  for (double d : {0.0, -0.05, 0.05, -0.1, 0.1, -0.15, -0.2, -0.25, -0.3}) {
    if (along + d < -1e-9) continue;
    const Configuration q = placed(d);
    kin.setConfiguration(q);
    std::vector<ContactSpec> stance = feet;
    if (!placeWhereHeld(sc, kin, stance)) continue;
    const auto standing_there = checkedWitnessNear(t, stance, q, q);
    if (!standing_there) continue;
    out = *standing_there;
    return true;
  }
  return false;
}

// A crouch: the start stance lowered on its own contacts (a squat on the
// feet) by the posture generator, as deep as the independent check accepts
// (the base 0.35 m down, then 0.30 ... 0.15); its joints' offsets from the
// start posture and how far the base came down. False when none is valid.
bool crouchOffsets(const Scenario& sc, PostureTools& t, Eigen::VectorXd& offsets, double& drop) {
  for (double d : {0.35, 0.30, 0.25, 0.20, 0.15}) {
    Configuration lowered = sc.start;
    lowered.base_position.z() -= d;
    const auto squat = checkedWitnessNear(t, sc.start_stance, sc.start, lowered);
    if (!squat) continue;
    drop = sc.start.base_position.z() - squat->base_position.z();
    if (drop < 0.1) continue;  // not a crouch
    offsets = squat->joints - sc.start.joints;
    return true;
  }
  return false;
}

// The robot's crawling posture (GuideOptions::crawling_posture) turned to
// the start's heading, its base over `xy`, raised to the start's floor:
// a witness of the contacts it makes there, accepted by the check. nullopt
// when the robot has no such posture, it makes fewer than three contacts
// there, or none is valid.
std::optional<Configuration> crawlingAt(const Scenario& sc, const GuideOptions& o, PostureTools& t, int floor,
                                        const Eigen::Vector2d& xy, std::vector<ContactSpec>& contacts) {
  const RobotModel& m = *sc.robot;
  if (!m.postures().count(o.crawling_posture)) return std::nullopt;
  Configuration q = m.posture(o.crawling_posture);
  const double yaw = yawOf(sc.start.base_orientation);
  q.base_orientation = Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ())) * q.base_orientation;
  q.base_position.head<2>() = xy;
  q.base_position.z() += sc.scene->surfaces()[floor].frame.translation().z();
  contacts = contactsMadeBy(sc, t.kin, q);
  if (contacts.size() < 3) return std::nullopt;
  return checkedWitnessNear(t, contacts, q, q);
}

// A crawling goal posture: where no posture stands in the goal region (under
// a low table), the robot's crawling posture with its goal link past the
// goal's bound, the free horizontal coordinate tried around the start's as
// for standing; in the goal. False when there is none.
bool goalPostureCrawling(const Scenario& sc, const GuideOptions& o, PostureTools& t, int floor, Configuration& out,
                         std::vector<ContactSpec>& contacts) {
  const RobotModel& m = *sc.robot;
  const GoalCondition& g = sc.goal;
  if (!m.postures().count(o.crawling_posture) || g.axis == 2) return false;
  Configuration named = m.posture(o.crawling_posture);
  const double yaw = yawOf(sc.start.base_orientation);
  named.base_orientation = Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ())) * named.base_orientation;
  t.kin.setConfiguration(named);
  const Eigen::Vector3d offset = t.kin.linkPose(g.link).translation() - named.base_position;
  const double bound = std::isfinite(g.min) ? g.min + o.goal_margin : g.max - o.goal_margin;
  const int free_axis = g.axis == 0 ? 1 : 0;
  std::vector<double> offsets = {0.0};
  for (double d = 0.1; d <= o.goal_search + 1e-9; d += 0.1) offsets.push_back(d), offsets.push_back(-d);
  for (double off : offsets) {
    Eigen::Vector2d xy = sc.start.base_position.head<2>();
    xy[g.axis] = bound - offset[g.axis];
    xy[free_axis] += off;
    const auto q = crawlingAt(sc, o, t, floor, xy, contacts);
    if (!q) continue;
    t.kin.setConfiguration(*q);
    if (!sc.goal.satisfied(t.kin, contacts)) continue;
    out = *q;
    return true;
  }
  return false;
}

// Getting down from the start stance onto the crawling posture's contacts,
// as a person does and as the planner can follow (key postures, each a
// witness the check accepts): squat on the start's contacts; then for each
// start contact on a limb the crawl also uses (a sole, whose leg kneels),
// that contact released and the limb's crawl contact (the knee) put down;
// before the last of them, the crawl's contacts on limbs the start does not
// use (the palms). An added contact is tried from the posture before it
// (a knee put down with the leg folded as the squat has it: swung straight
// to the crawl's leg, the planner's plans on the guide could not be
// interpolated), then from the limb as `crawl` holds it, then with the
// trunk too (the chest bent toward the palms): Ipopt is local. `keys` gets the start and each witness; false
// with `why` when a step finds no valid posture.
bool gettingDown(const Scenario& sc, PostureTools& t, const Configuration& crawl,
                 const std::vector<ContactSpec>& crawl_contacts, std::vector<Configuration>& keys, std::string& why) {
  const RobotModel& m = *sc.robot;
  std::vector<ContactSpec> stance = sc.start_stance;
  Configuration q = sc.start;
  keys = {sc.start};
  auto limbOf = [&](int spot) { return m.spotLimbRootJoint(spot); };
  auto settle = [&](const std::string& what) {  // the stance with every contact supporting
    for (auto& c : stance) c.supporting = true;
    const auto w = checkedWitnessNear(t, stance, q, q);
    if (!w) {
      why = "getting down: no valid posture once " + what;
      return false;
    }
    q = *w;
    return true;
  };
  {  // the squat
    Configuration lowered = sc.start;
    lowered.base_position.z() -= 0.25;
    const auto squat = checkedWitnessNear(t, stance, q, lowered);
    if (!squat) {
      why = "getting down: the start stance has no valid squat";
      return false;
    }
    q = *squat;
    keys.push_back(q);
  }
  auto add = [&](const ContactSpec& target) {
    const std::string name = m.spots()[target.spot].name;
    const Surface& surf = sc.scene->surfaces()[target.surface];
    Configuration limb = q;
    for (int j : m.jointsMovedBy(limbOf(target.spot))) limb.joints[j] = crawl.joints[j];
    Configuration trunk = limb;  // and the joints above the limb (the chest)
    for (int j : m.ancestorJoints(m.spots()[target.spot].link)) trunk.joints[j] = crawl.joints[j];
    PostureRequest r;
    r.contacts = stance;
    r.floating = overSurface(sc, target.spot, target.surface);
    const Configuration here = q;
    for (const Configuration* guess : std::initializer_list<const Configuration*>{&here, &limb, &trunk}) {
      r.initial_guess = *guess;
      r.cost = std::make_shared<ReferencePostureCost>(*guess, 0.01, 10.0, 1.0);
      const PostureResult res = t.pg.solve(r);
      if (!res.success()) continue;
      ContactSpec c = target;
      t.kin.setConfiguration(res.configuration);
      c.placement = projectOnSurface(surf, t.kin.spotPose(target.spot));
      c.supporting = false;
      std::vector<ContactSpec> touching = stance;
      touching.push_back(c);
      if (!t.checker.checkPosture(res.configuration, touching).valid()) continue;
      q = res.configuration;
      stance = touching;
      return settle(name + " is put down");
    }
    why = "getting down: " + name + " cannot be put down";
    return false;
  };
  auto release = [&](std::size_t i) {
    const std::string name = m.spots()[stance[i].spot].name;
    std::vector<ContactSpec> r = stance;
    r[i].supporting = false;
    const auto w = checkedWitnessNear(t, r, q, q);
    if (!w) {
      why = "getting down: " + name + " cannot be released";
      return false;
    }
    q = *w;
    stance.erase(stance.begin() + static_cast<long>(i));
    return true;
  };
  // Start contacts whose limb the crawl uses, each with its crawl contact.
  std::vector<std::pair<int, ContactSpec>> swaps;  // start spot, crawl contact
  std::vector<ContactSpec> others;                 // crawl contacts on limbs the start does not use
  for (const auto& k : crawl_contacts) {
    bool paired = false;
    for (const auto& c : sc.start_stance)
      if (c.spot != k.spot && limbOf(c.spot) >= 0 && limbOf(c.spot) == limbOf(k.spot)) {
        swaps.push_back({c.spot, k});
        paired = true;
      }
    bool held = false;
    for (const auto& c : sc.start_stance) held = held || c.spot == k.spot;
    if (!paired && !held) others.push_back(k);
  }
  if (swaps.empty()) {
    why = "getting down: no start contact is on a limb the crawling posture rests on";
    return false;
  }
  for (std::size_t s = 0; s < swaps.size(); ++s) {
    if (s + 1 == swaps.size())
      for (const auto& k : others) {
        if (!add(k)) return false;
        keys.push_back(q);
      }
    std::size_t i = 0;
    while (i < stance.size() && stance[i].spot != swaps[s].first) ++i;
    if (i == stance.size()) continue;
    if (!release(i) || !add(swaps[s].second)) return false;
    keys.push_back(q);
  }
  return true;
}

// One leg of the rough trajectory: OMPL's RRTConnect in the reduced space
// blending `from` into `to` within `budget` seconds, shortcut, its vertices
// lifted to whole-body postures (the first `from`, the last `to` exactly).
// With `crouch` (joint offsets, and the base's drop with them), the space
// has the crouch coordinate and the base may go that much lower. With
// `max_checks` > 0 the search also stops after that many state checks: a try
// whose failure leads to another (approach, then standing, then crouched)
// ends on a count, not on the machine's speed, so that the same scenario and
// seed give the same guide. With GuideOptions::stable the path is sampled
// along its edges and the samples projected into the statically stable
// subspace (projectStable, with `tools`); a sample that does not project
// gets a ball of the reduced space around it left out, and the leg is
// planned again (at most stable_replans times, within the same budget).
// False with out.status and out.reason set when there is no path.
struct LegEnds {
  const Configuration& from;
  const Configuration& to;
  std::string from_what, to_what;  // "start posture", "approach posture", "goal posture"
};
bool planLeg(const Scenario& sc, const GuideOptions& o, PostureTools& tools, const LegEnds& ends, double budget,
             long max_checks, const Eigen::VectorXd& crouch, double crouch_drop, const std::atomic<bool>* cancel,
             GuideResult& out, std::vector<Configuration>& postures) {
  const Configuration& from = ends.from;
  const Configuration& to = ends.to;
  const std::string& what = ends.to_what;
  Lift lift{from, to, yawOf(from.base_orientation), yawOf(to.base_orientation), crouch};
  const unsigned dims = crouch.size() ? 6 : 5;
  auto space = std::make_shared<ob::RealVectorStateSpace>(dims);
  ob::RealVectorBounds b(dims);
  for (int k = 0; k < 3; ++k) {
    const double lo = std::min(from.base_position[k], to.base_position[k]);
    const double hi = std::max(from.base_position[k], to.base_position[k]);
    const double margin = k == 2 ? 0.15 : 0.6;  // sideways room for detours; a little height
    b.setLow(k, lo - margin - (k == 2 ? crouch_drop : 0.0));
    b.setHigh(k, hi + margin);
  }
  b.setLow(3, std::min(lift.yaw_start, lift.yaw_goal) - M_PI / 2);
  b.setHigh(3, std::max(lift.yaw_start, lift.yaw_goal) + M_PI / 2);
  for (unsigned k = 4; k < dims; ++k) {
    b.setLow(k, 0.0);
    b.setHigh(k, 1.0);
  }
  space->setBounds(b);
  // The seed of the try being made (GuideOptions::path_tries): read when a
  // try's planner allocates its sampler.
  auto seed = std::make_shared<unsigned>(o.seed);
  space->setStateSamplerAllocator([seed](const ob::StateSpace* s) { return std::make_shared<SeededSampler>(s, *seed); });
  og::SimpleSetup ss(space);
  auto si = ss.getSpaceInformation();
  auto validity = std::make_shared<RelaxedValidity>(si, sc, lift, o.penetration);
  ss.setStateValidityChecker(validity);
  si->setStateValidityCheckingResolution(0.01);  // 1% of the space's extent per check along a motion

  ob::ScopedState<ob::RealVectorStateSpace> start(space), target(space);
  const double sv[6] = {from.base_position.x(), from.base_position.y(), from.base_position.z(), lift.yaw_start, 0.0, 0.0};
  const double gv[6] = {to.base_position.x(), to.base_position.y(), to.base_position.z(), lift.yaw_goal, 1.0, 0.0};
  for (unsigned k = 0; k < dims; ++k) start[k] = sv[k], target[k] = gv[k];
  if (!validity->isValid(start.get())) {
    out.status = GuideResult::Status::InvalidStart;
    out.reason = "the " + ends.from_what + fmt(" penetrates the scene by more than %.3f m", o.penetration);
    return false;
  }
  if (!validity->isValid(target.get())) {
    out.status = GuideResult::Status::NoGoalPosture;
    out.reason = "the " + what + " penetrates the scene";
    return false;
  }
  // The ceiling: the standing posture's base height over its soles, plus
  // GuideOptions::ceiling_slack, when both ends are under it.
  if (sc.robot->postures().count(o.standing_posture)) {
    Kinematics kin(sc.robot);
    const Configuration standing = sc.robot->posture(o.standing_posture);
    kin.setConfiguration(standing);
    double soles = std::numeric_limits<double>::infinity();
    for (const char* name : {"r_sole", "l_sole"})
      if (sc.robot->spotIndex(name) >= 0) soles = std::min(soles, kin.spotPose(sc.robot->spotIndex(name)).translation().z());
    if (std::isfinite(soles)) {
      const double ceiling = standing.base_position.z() - soles + o.ceiling_slack;
      auto under = [&](const double* v) {
        const auto h = validity->heightAboveGround(v);
        return !h || *h <= ceiling;
      };
      if (under(sv) && under(gv)) validity->setCeiling(ceiling);
    }
  }
  ss.setStartAndGoalStates(start, target);
  const double t1 = now();
  long try_checks = max_checks;  // the try's own bound on state checks (0: none), from its first check
  long checks0 = 0;
  const auto stop = [&] {
    return now() - t1 > budget || (try_checks > 0 && validity->checks() - checks0 >= try_checks) ||
           (cancel && cancel->load());
  };
  const auto cancelled = [&] {
    if (!cancel || !cancel->load()) return false;
    out.status = GuideResult::Status::Cancelled;
    out.reason = "cancelled";
    return true;
  };
  std::string unprojected;  // why the last path left the statically stable subspace (GuideOptions::stable)
  // One try: RRTConnect seeded with `try_seed`, its path shortcut; none
  // without an exact solution.
  // The first try's planner is kept across the replans (cleared, not seeded
  // again) and counts its checks from the leg's first, as a single try did.
  std::shared_ptr<SeededRRTConnect> first;
  const auto tryPath = [&](int t) -> std::optional<og::PathGeometric> {
    const unsigned try_seed = o.seed + 7919u * static_cast<unsigned>(t);
    *seed = try_seed;
    std::shared_ptr<SeededRRTConnect> planner = t == 0 ? first : nullptr;
    if (planner) {
      planner->clear();
    } else {
      planner = std::make_shared<SeededRRTConnect>(si, try_seed);
      planner->setRange(o.range);
      if (t == 0) first = planner;
    }
    ss.setPlanner(planner);
    ss.getProblemDefinition()->clearSolutionPaths();
    ss.setup();
    checks0 = t == 0 ? 0 : validity->checks();
    const double t2 = now();
    const ob::PlannerStatus st = ss.solve(ob::PlannerTerminationCondition(stop));
    out.path_seconds += now() - t2;
    if (st != ob::PlannerStatus::EXACT_SOLUTION) return std::nullopt;
    og::PathGeometric path = ss.getSolutionPath();
    out.path_vertices += static_cast<int>(path.getStateCount());
    SeededSimplifier simplifier(si, try_seed);
    simplifier.reduceVertices(path, static_cast<unsigned>(o.shortcut_steps));
    simplifier.shortcutPath(path, static_cast<unsigned>(o.shortcut_steps));
    simplifier.reduceVertices(path, static_cast<unsigned>(o.shortcut_steps));
    return path;
  };
  for (int attempt = 0;; ++attempt) {
    // GuideOptions::path_tries: the shortest of that many tries, each seeded
    // anew (the first with the guide's seed), the first on a tie; the tries
    // after the first bounded by state checks (fallback_checks where the leg
    // has no such bound), so that the choice is the same under any load.
    std::optional<og::PathGeometric> best;
    bool checks_out = false;  // the first try stopped on its check bound (the leg's, counted from its first check)
    // GuideOptions::path_retries: more tries, the same way, while none found a path.
    const int tries = std::max(1, o.path_tries);
    int made = 0;
    for (int t = 0; (t < tries || (!best && t < tries + std::max(0, o.path_retries))) && !(cancel && cancel->load());
         ++t) {
      ++made;
      try_checks = t == 0 || max_checks > 0 ? max_checks : o.fallback_checks;
      std::optional<og::PathGeometric> p = tryPath(t);
      if (t == 0) checks_out = max_checks > 0 && validity->checks() >= max_checks;
      if (p && (!best || p->length() < best->length() - 1e-12)) best = std::move(p);
      if (now() - t1 > budget) break;
    }
    if (cancelled()) return false;
    if (!best) {
      out.status = GuideResult::Status::NoPath;
      out.reason = "OMPL (RRTConnect) found no path to the " + what +
                   (checks_out ? fmt(" within %.0f state checks", max_checks) : fmt(" within %.1f s", budget));
      if (made > 1) out.reason += fmt(" in %.0f tries", made);
      if (attempt > 0)
        out.reason += fmt(" through the statically stable subspace (%.0f replans around samples that did not project; "
                          "the last: ", attempt) + unprojected + ")";
      return false;
    }
    og::PathGeometric& path = *best;
    // The vertices, or with GuideOptions::stable (or sample_edges) samples along the edges:
    // at most stable_step of base travel, 0.2 rad of heading, 0.1 of blend
    // or crouch apart.
    std::vector<Eigen::VectorXd> states;
    for (std::size_t i = 0; i < path.getStateCount(); ++i) {
      const Eigen::VectorXd b =
          Eigen::Map<const Eigen::VectorXd>(path.getState(i)->as<ob::RealVectorStateSpace::StateType>()->values, dims);
      if ((o.stable || o.sample_edges) && !states.empty()) {
        const Eigen::VectorXd a = states.back();
        const Eigen::VectorXd d = b - a;
        double parts = std::max(d.head<3>().norm() / o.stable_step, std::abs(d[3]) / 0.2);
        if (dims > 4) parts = std::max(parts, d.tail(dims - 4).cwiseAbs().maxCoeff() / 0.1);
        const int n = std::max(1, static_cast<int>(std::ceil(parts - 1e-9)));
        for (int j = 1; j < n; ++j) states.push_back(a + d * static_cast<double>(j) / n);
      }
      states.push_back(b);
    }
    postures.clear();
    for (std::size_t i = 0; i < states.size(); ++i)
      postures.push_back(i == 0 ? from : (i + 1 == states.size() ? to : lift(states[i].data())));
    if (!o.stable) return true;
    const double t3 = now();
    StableOptions so;
    so.reach = o.stable_reach;
    so.tolerance = o.stable_tolerance;
    const StableProjection p = projectStable(sc, tools, postures, so, cancel);
    out.stable_seconds += now() - t3;
    out.stable_projections += p.projections;
    if (p.success()) {
      postures = p.postures;
      return true;
    }
    if (cancelled()) return false;
    unprojected = p.reason;
    if (attempt >= o.stable_replans || stop()) {
      out.status = GuideResult::Status::NoPath;
      out.reason = "no path to the " + what + " through the statically stable subspace: " + p.reason +
                   fmt(" (after %.0f replans)", attempt);
      return false;
    }
    // Planned again with a ball around that sample left out (smaller than
    // its distance to either end, which stay valid).
    const Eigen::VectorXd& c = states[static_cast<std::size_t>(p.failed_sample)];
    const double to_ends = std::min((c - states.front()).norm(), (c - states.back()).norm());
    validity->forbid(c, std::min(o.stable_forbid, 0.9 * to_ends));
    ++out.stable_replans;
    ss.clear();
  }
}

// Appends a leg's postures to the guide, leaving out a posture whose base is
// within 1 cm and 0.02 rad of the one before (the guide's base projection
// must be one-to-one).
void appendKeys(Guide& g, const std::vector<Configuration>& postures) {
  for (const Configuration& q : postures) {
    if (!g.key_postures.empty() && (q.base_position - g.key_postures.back().base_position).norm() < 0.01 &&
        q.base_orientation.angularDistance(g.key_postures.back().base_orientation) < 0.02)
      continue;
    g.key_postures.push_back(q);
  }
}

// The guide of a crawl: getting down where the robot starts (gettingDown),
// then OMPL's leg from the crawling posture there to the crawling goal
// posture (the blend between two crawling postures: the base's path).
GuideResult crawlGuide(const Scenario& sc, const GuideOptions& o, PostureTools& t, int floor, const Configuration& goal,
                       const std::vector<ContactSpec>& crawl_contacts, double t0, const std::atomic<bool>* cancel,
                       GuideResult& out) {
  std::vector<Configuration> down;
  if (!gettingDown(sc, t, goal, crawl_contacts, down, out.reason)) {
    out.status = GuideResult::Status::NoPath;
    return out;
  }
  out.crawl = true;
  // Then the crawling posture itself a step ahead (the limbs as a crawl
  // holds them, not as getting down left them): the valley the planner's
  // first crawl steps follow.
  const double yaw = yawOf(sc.start.base_orientation);
  std::vector<ContactSpec> contacts;
  const Eigen::Vector2d ahead =
      down.back().base_position.head<2>() + o.crawl_step * Eigen::Vector2d(std::cos(yaw), std::sin(yaw));
  if (const auto crawling = crawlingAt(sc, o, t, floor, ahead, contacts)) down.push_back(*crawling);
  const LegEnds ends{down.back(), goal, "crawling posture where the robot got down", "crawling goal posture"};
  std::vector<Configuration> leg;
  if (!planLeg(sc, o, t, ends, o.max_seconds, 0, {}, 0, cancel, out, leg)) return out;
  Guide& g = out.guide;
  g.source = "ompl";
  g.scenario = sc.path;
  appendKeys(g, down);
  out.crawl_index = static_cast<int>(g.key_postures.size()) - 1;
  appendKeys(g, leg);
  g.seconds = now() - t0;
  out.goal_seconds = g.seconds - out.path_seconds - out.stable_seconds;
  out.status = GuideResult::Status::Success;
  out.reason.clear();
  return out;
}

}  // namespace

GuideResult authorGuide(const Scenario& sc, const GuideOptions& o, const std::atomic<bool>* cancel) {
  GuideResult out;
  const double t0 = now();
  ompl::msg::setLogLevel(ompl::msg::LOG_WARN);
  Configuration goal;
  PostureTools tools(sc);
  if (!goalPosture(sc, o, tools, goal, out.reason)) {
    // Where nothing stands in the goal region (under a low table): crawling.
    int floor = -1;
    for (const auto& c : sc.start_stance)
      if (floor < 0 && sc.scene->surfaces()[c.surface].frame.linear().col(2).z() >= kLevelSurface) floor = c.surface;
    std::vector<ContactSpec> crawl_contacts;
    if (!o.crawl || floor < 0 || !goalPostureCrawling(sc, o, tools, floor, goal, crawl_contacts)) {
      if (o.crawl && sc.robot->postures().count(o.crawling_posture) && sc.goal.axis != 2)
        out.reason += ", nor a crawling posture ('" + o.crawling_posture + "')";
      out.status = GuideResult::Status::NoGoalPosture;
      return out;
    }
    out.goal_seconds = now() - t0;
    return crawlGuide(sc, o, tools, floor, goal, crawl_contacts, t0, cancel, out);
  }
  out.goal_seconds = now() - t0;  // the goal posture (and at the end, every posture made)
  // One budget for every search (GuideOptions::max_seconds); the tries
  // whose failure leads to another stop on a count of state checks first.
  const double deadline = now() + o.max_seconds;
  auto remaining = [&] { return std::max(0.0, deadline - now()); };
  const LegEnds straight{sc.start, goal, "start posture", "goal posture"};
  std::vector<std::vector<Configuration>> legs;
  std::vector<Configuration> leg;
  int approach_index = -1;
  // Through the approach posture where the goal needs one. Where no path
  // reaches it (a chair 6 cm from its table: the posture stands there, but
  // no blend of two standing postures gets between them), or none goes on
  // from it, straight to the goal posture.
  Configuration approach;
  if (approachPosture(sc, o, tools, goal, approach)) {
    const LegEnds first{sc.start, approach, "start posture", "approach posture"};
    const LegEnds second{approach, goal, "approach posture", "goal posture from the approach posture"};
    std::vector<Configuration> to_approach;
    if (planLeg(sc, o, tools, first, remaining(), o.fallback_checks, {}, 0, cancel, out, to_approach) &&
        planLeg(sc, o, tools, second, remaining(), o.fallback_checks, {}, 0, cancel, out, leg)) {
      approach_index = static_cast<int>(to_approach.size()) - 1;
      legs = {to_approach, leg};
      out.approach = true;
    }
    if (out.status == GuideResult::Status::Cancelled) return out;
  }
  // Straight to the goal posture; where no path comes, with a crouch (under
  // a low beam: a blend of two standing postures cannot lower the head).
  if (legs.empty()) {
    if (planLeg(sc, o, tools, straight, remaining(), o.crouch ? o.fallback_checks : 0, {}, 0, cancel, out, leg))
      legs.push_back(leg);
    else if (out.status != GuideResult::Status::NoPath) return out;
  }
  if (legs.empty() && !o.crouch) {
    out.reason += " (a crouch was not tried: switched off)";
    return out;
  }
  if (legs.empty()) {
    Eigen::VectorXd crouch;
    double drop = 0;
    const std::string standing_failure = out.reason;
    if (!crouchOffsets(sc, tools, crouch, drop)) {
      out.reason = standing_failure + "; the start stance has no valid crouch to try";
      return out;
    }
    if (!planLeg(sc, o, tools, straight, remaining(), 0, crouch, drop, cancel, out, leg)) {
      if (out.status == GuideResult::Status::NoPath)
        out.reason = standing_failure + fmt(", nor with a crouch of %.2f m", drop);
      return out;
    }
    legs.push_back(leg);
    out.crouch = true;
  }

  Guide& g = out.guide;
  g.source = "ompl";
  g.scenario = sc.path;
  for (const auto& postures : legs) {
    appendKeys(g, postures);  // a leg's first posture is the last one's end
    if (&postures == &legs.front() && approach_index >= 0) out.approach_index = static_cast<int>(g.key_postures.size()) - 1;
  }
  if (g.key_postures.size() < 2) {
    out.status = GuideResult::Status::NoPath;
    out.reason = "the goal posture's base is the start's: nothing to guide";
    return out;
  }
  g.seconds = now() - t0;
  out.goal_seconds = g.seconds - out.path_seconds - out.stable_seconds;  // the goal, approach and crouch postures
  out.status = GuideResult::Status::Success;
  out.reason.clear();  // an approach or standing leg that failed on the way said why; the guide was made
  return out;
}

}  // namespace acyclic
