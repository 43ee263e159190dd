#include "viewer/export/view_data.h"

#include <algorithm>
#include <cmath>

#include <nlohmann/json.hpp>

#include "planner/check/quasi_static.h"
#include "planner/check/validity.h"
#include "planner/model/kinematics.h"

namespace acyclic {
namespace {

using nlohmann::json;

// Display precision: 10 um and 1e-5 on quaternions keeps data.js small and
// is far below what a screen shows.
double r5(double v) { return std::round(v * 1e5) / 1e5; }
json vec(const Eigen::Vector3d& v) { return json::array({r5(v.x()), r5(v.y()), r5(v.z())}); }
// Poses as [x, y, z, qx, qy, qz, qw]: three.js's order for Quaternion.set.
void appendPose(json& out, const Eigen::Isometry3d& T) {
  const Eigen::Quaterniond q(T.linear());
  const Eigen::Vector3d p = T.translation();
  for (double v : {p.x(), p.y(), p.z(), q.x(), q.y(), q.z(), q.w()}) out.push_back(r5(v));
}

const char* kindName(CollisionShape::Kind k) {
  switch (k) {
    case CollisionShape::Kind::Box: return "box";
    case CollisionShape::Kind::Capsule: return "capsule";
    case CollisionShape::Kind::Sphere: return "sphere";
    case CollisionShape::Kind::Cylinder: return "cylinder";
  }
  return "box";
}

json shapeJson(const CollisionShape& s) {
  json j = {{"name", s.name}, {"kind", kindName(s.kind)}};
  if (s.kind == CollisionShape::Kind::Box) j["size"] = vec(s.size);
  else j["radius"] = r5(s.radius);
  if (s.kind == CollisionShape::Kind::Capsule || s.kind == CollisionShape::Kind::Cylinder) j["length"] = r5(s.length);
  return j;
}

// Shapes, CoM and the contacts' geometry at one configuration; the forces are
// filled by the caller (the plan's, or the quasi-static check's).
ViewPosture evaluate(const Scenario& sc, Kinematics& kin, const std::vector<ViewShape>& shapes,
                     const Configuration& q, const std::vector<ContactSpec>& stance) {
  ViewPosture v;
  v.q = q;
  kin.setConfiguration(q);
  const RobotModel& m = *sc.robot;
  for (const auto& s : shapes) v.shape_poses.push_back(kin.linkPose(s.link) * m.links()[s.link].shapes[s.index].pose);
  v.com = kin.centerOfMass();
  for (const auto& c : stance) {
    ViewContact vc;
    vc.spot = c.spot;
    vc.surface = c.surface;
    vc.supporting = c.supporting;
    vc.frame = contactFrame(sc.scene->surfaces()[c.surface], c.placement);
    // The outline is drawn where the body's spot really is (the contract
    // keeps it within 1 mm of the contact frame).
    const Eigen::Isometry3d spot = kin.spotPose(c.spot);
    for (const auto& p : m.spots()[c.spot].polygon.vertices()) vc.outline.push_back(spot * Eigen::Vector3d(p.x(), p.y(), 0));
    v.contacts.push_back(std::move(vc));
  }
  return v;
}

void applyStatics(const QuasiStaticReport& r, ViewPosture& v) {
  v.feasible = r.feasible;
  v.margin = r.margin;
  v.worst_torque_ratio = r.worst_torque_ratio;
  v.worst_cone_ratio = r.worst_cone_ratio;
}

// The check's corners and forces of stance contact c (the report holds one
// list per stance contact, empty for those that do not support).
void takeCheckForces(const QuasiStaticReport& r, std::size_t c, ViewContact& vc) {
  if (!r.feasible || !vc.supporting || c >= r.points.size()) return;
  vc.points = r.points[c];
  vc.forces = r.forces[c];
}

json postureJson(const Scenario& sc, const ViewPosture& v) {
  json poses = json::array();
  for (const auto& T : v.shape_poses) appendPose(poses, T);
  json contacts = json::array();
  for (const auto& c : v.contacts) {
    json outline = json::array(), points = json::array(), forces = json::array();
    for (const auto& p : c.outline) outline.push_back(vec(p));
    for (const auto& p : c.points) points.push_back(vec(p));
    for (const auto& f : c.forces) forces.push_back(vec(f));
    contacts.push_back({{"spot", sc.robot->spots()[c.spot].name},
                        {"surface", sc.scene->surfaces()[c.surface].name},
                        {"supporting", c.supporting},
                        {"outline", outline},
                        {"points", points},
                        {"forces", forces}});
  }
  return {{"t", r5(v.t)}, {"stance", v.stance}, {"phase", v.phase}, {"sample", v.sample},
          {"poses", poses}, {"com", vec(v.com)}, {"contacts", contacts},
          {"forces_from", v.forces_from_check ? "check" : "plan"}, {"feasible", v.feasible}, {"margin", r5(v.margin)}, {"worst_torque_ratio", r5(v.worst_torque_ratio)}};
}

}  // namespace

std::vector<ViewShape> viewShapes(const RobotModel& robot) {
  std::vector<ViewShape> out;
  for (const auto& l : robot.links())
    for (int i = 0; i < static_cast<int>(l.shapes.size()); ++i) out.push_back({l.index, i});
  return out;
}

std::vector<ViewPosture> stancePostures(const Scenario& sc, const Plan& plan) {
  Kinematics kin(sc.robot);
  QuasiStaticChecker statics(sc.robot, sc.scene);
  const auto shapes = viewShapes(*sc.robot);
  std::vector<ViewPosture> out;
  for (std::size_t i = 0; i < plan.stances.size(); ++i) {
    const PlanStance& s = plan.stances[i];
    ViewPosture v = evaluate(sc, kin, shapes, s.configuration, s.specs());
    v.stance = static_cast<int>(i);
    // The plan's own forces: what the planner claims holds the robot. A plan
    // written without them (e.g. by hand) gets the independent check's.
    const QuasiStaticReport r = statics.check(kin, s.specs());
    applyStatics(r, v);
    bool plan_forces = true;
    for (const auto& c : s.contacts) plan_forces &= !c.spec.supporting || !c.forces.empty();
    v.forces_from_check = !plan_forces;
    for (std::size_t c = 0; c < s.contacts.size(); ++c) {
      if (plan_forces) {
        v.contacts[c].points = s.contacts[c].points;
        v.contacts[c].forces = s.contacts[c].forces;
      } else {
        takeCheckForces(r, c, v.contacts[c]);
      }
    }
    out.push_back(std::move(v));
  }
  return out;
}

std::vector<ViewPosture> trajectoryFrames(const Scenario& sc, const Trajectory& tr, double fps) {
  if (!(fps > 0)) throw std::invalid_argument("trajectoryFrames: fps must be positive");
  std::vector<ViewPosture> out;
  if (tr.samples.empty()) return out;
  Kinematics kin(sc.robot);
  QuasiStaticChecker statics(sc.robot, sc.scene);
  const auto shapes = viewShapes(*sc.robot);
  const int last = static_cast<int>(tr.samples.size()) - 1;
  const double duration = tr.duration();
  std::vector<int> picks;
  for (int k = 0;; ++k) {
    const double t = k / fps;
    if (t > duration + 1e-9) break;
    picks.push_back(std::clamp(static_cast<int>(std::lround(t / tr.dt)), 0, last));
  }
  if (picks.empty() || picks.back() != last) picks.push_back(last);  // the end is always shown
  for (int idx : picks) {
    const TrajectorySample& s = tr.samples[idx];
    const TrajectoryPhase& ph = tr.phases[s.phase];
    ViewPosture v = evaluate(sc, kin, shapes, s.q, ph.contacts);
    v.t = s.t;
    v.sample = idx;
    v.phase = s.phase;
    v.stance = ph.stance;
    v.forces_from_check = true;
    // The trajectory carries no forces: the independent check's (LP 2) are shown.
    const QuasiStaticReport r = statics.check(kin, ph.contacts);
    applyStatics(r, v);
    for (std::size_t c = 0; c < v.contacts.size(); ++c) takeCheckForces(r, c, v.contacts[c]);
    out.push_back(std::move(v));
  }
  return out;
}

std::string viewDataJson(const Scenario& sc, const Plan& plan, const std::vector<ViewPosture>& stances,
                         const std::vector<ViewPosture>& frames, double fps, const ViewSources& src) {
  const RobotModel& m = *sc.robot;
  json shapes = json::array();
  for (const auto& s : viewShapes(m)) {
    json j = shapeJson(m.links()[s.link].shapes[s.index]);
    j["link"] = m.links()[s.link].name;
    shapes.push_back(j);
  }
  json obstacles = json::array();
  for (const auto& o : sc.scene->obstacles()) {
    json j = shapeJson(o.shape);
    j["name"] = o.name;
    json pose = json::array();
    appendPose(pose, o.shape.pose);
    j["pose"] = pose;
    obstacles.push_back(j);
  }
  json surfaces = json::array();
  for (const auto& s : sc.scene->surfaces()) {
    json outline = json::array();
    for (const auto& p : s.polygon.vertices()) outline.push_back(vec(s.frame * Eigen::Vector3d(p.x(), p.y(), 0)));
    surfaces.push_back({{"name", s.name}, {"outline", outline}});
  }
  // The validity contract, per stance (the same check as acyclic-check --plan).
  ValidityChecker checker(sc.robot, sc.scene);
  json st = json::array();
  for (std::size_t i = 0; i < stances.size(); ++i) {
    json j = postureJson(sc, stances[i]);
    const PlanStance& ps = plan.stances[i];
    j["potential"] = ps.potential;
    j["valid"] = checker.checkPosture(ps.configuration, ps.specs()).valid();
    json names = json::array();
    for (const auto& c : ps.specs()) names.push_back(sc.describe(c));
    j["description"] = names;
    st.push_back(j);
  }
  json fr = json::array();
  for (const auto& f : frames) fr.push_back(postureJson(sc, f));
  json out = {{"format", "acyclic.view/1"},
              {"scenario", {{"name", sc.name}, {"file", src.scenario}}},
              {"plan", src.plan},
              {"trajectory", src.trajectory},
              {"robot", {{"name", m.name()}, {"mass", m.totalMass()}, {"shapes", shapes}}},
              {"obstacles", obstacles},
              {"surfaces", surfaces},
              {"stances", st},
              {"fps", fps},
              {"frames", fr}};
  return out.dump();
}

}  // namespace acyclic
