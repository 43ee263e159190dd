#include "planner/plan/trajectory.h"

#include <cmath>

#include "planner/plan/json_field.h"

namespace acyclic {

using nlohmann::json;
using json_field::J;

std::string trajectoryToJson(const Trajectory& tr, const Scenario& sc) {
  json j;
  j["format"] = "acyclic.trajectory/1";
  j["scenario"] = tr.scenario;
  j["plan"] = tr.plan;
  j["joint_names"] = sc.robot->jointNames();
  j["dt"] = tr.dt;
  j["phases"] = json::array();
  for (const auto& p : tr.phases) {
    json jp = {{"t_start", p.t_start}, {"t_end", p.t_end}, {"stance", p.stance}, {"contacts", json::array()}};
    for (const auto& c : p.contacts) jp["contacts"].push_back(json_field::specToJson(c, sc));
    j["phases"].push_back(jp);
  }
  // Column-wise: one list per quantity, one entry per sample.
  json t = json::array(), phase = json::array(), pos = json::array(), ori = json::array(), joints = json::array(),
       vel = json::array();
  for (const auto& s : tr.samples) {
    t.push_back(s.t);
    phase.push_back(s.phase);
    pos.push_back(json_field::vec(s.q.base_position));
    const Eigen::Quaterniond o = s.q.base_orientation.normalized();
    ori.push_back(json::array({o.w(), o.x(), o.y(), o.z()}));
    joints.push_back(std::vector<double>(s.q.joints.data(), s.q.joints.data() + s.q.joints.size()));
    vel.push_back(std::vector<double>(s.dq.data(), s.dq.data() + s.dq.size()));
  }
  j["samples"] = {{"t", t}, {"phase", phase}, {"base_position", pos}, {"base_orientation", ori},
                  {"joints", joints}, {"joint_velocities", vel}};
  j["stats"] = {{"stances_in", tr.stats.stances_in},   {"stances_kept", tr.stats.stances_kept},
                {"transitions", tr.stats.transitions}, {"repairs", tr.stats.repairs},
                {"posture_calls", tr.stats.posture_calls}, {"seconds", tr.stats.seconds}};
  return j.dump();
}

void writeTrajectory(const Trajectory& tr, const Scenario& sc, const std::string& path) {
  json_field::writeFileAtomically(path, trajectoryToJson(tr, sc) + "\n");
}

Trajectory readTrajectory(const std::string& path, const Scenario& sc) {
  return trajectoryFromJson(json_field::readWholeFile(path), path, sc);
}

namespace {

double finite(const J& j) {
  const double v = j.number();
  if (!std::isfinite(v)) j.fail("a finite number");
  return v;
}

}  // namespace

Trajectory trajectoryFromJson(const std::string& text, const std::string& origin, const Scenario& sc) {
  const json doc = json_field::parseFormat(text, origin, "acyclic.trajectory/1");
  const J root{doc, origin, ""};
  Trajectory tr;
  tr.scenario = root.has("scenario") ? root.at("scenario").string() : "";
  tr.plan = root.has("plan") ? root.at("plan").string() : "";
  json_field::checkJointNames(root.at("joint_names"), sc);
  tr.dt = finite(root.at("dt"));
  if (tr.dt <= 0) root.at("dt").fail("a positive sample period (s)");

  const J phases = root.at("phases");
  for (std::size_t i = 0; i < phases.size(); ++i) {
    const J jp = phases.item(i);
    TrajectoryPhase p;
    p.t_start = finite(jp.at("t_start"));
    p.t_end = finite(jp.at("t_end"));
    if (p.t_end < p.t_start) jp.at("t_end").fail("t_end >= t_start");
    p.stance = jp.has("stance") ? static_cast<int>(jp.at("stance").number()) : -1;
    const J cs = jp.at("contacts");
    for (std::size_t k = 0; k < cs.size(); ++k) p.contacts.push_back(json_field::specFromJson(cs.item(k), sc));
    tr.phases.push_back(p);
  }

  const J s = root.at("samples");
  const J t = s.at("t"), phase = s.at("phase"), pos = s.at("base_position"), ori = s.at("base_orientation"),
          joints = s.at("joints"), vel = s.at("joint_velocities");
  const std::size_t n = t.size();
  for (const J* col : {&phase, &pos, &ori, &joints, &vel})
    if (col->size() != n) col->fail("one entry per sample (" + std::to_string(n) + ", as samples.t)");
  const int nj = sc.robot->numJoints();
  tr.samples.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    TrajectorySample& smp = tr.samples[i];
    smp.t = finite(t.item(i));
    if (i > 0 && smp.t <= tr.samples[i - 1].t) t.item(i).fail("increasing times");
    const J ph = phase.item(i);
    smp.phase = static_cast<int>(ph.number());
    if (smp.phase < 0 || smp.phase >= static_cast<int>(tr.phases.size()))
      ph.fail("a phase index below " + std::to_string(tr.phases.size()));
    smp.q.base_position = pos.item(i).vec3();
    const auto o = ori.item(i).numbers(4);
    smp.q.base_orientation = Eigen::Quaterniond(o[0], o[1], o[2], o[3]);
    if (!(std::abs(smp.q.base_orientation.norm() - 1) <= 1e-6)) ori.item(i).fail("a unit quaternion [w, x, y, z]");
    const auto jv = joints.item(i).numbers(nj);
    const auto dv = vel.item(i).numbers(nj);
    smp.q.joints = Eigen::Map<const Eigen::VectorXd>(jv.data(), nj);
    smp.dq = Eigen::Map<const Eigen::VectorXd>(dv.data(), nj);
    if (!smp.q.joints.allFinite() || !smp.q.base_position.allFinite()) joints.item(i).fail("finite numbers");
    if (!smp.dq.allFinite()) vel.item(i).fail("finite numbers");
  }
  if (root.has("stats")) {
    const J st = root.at("stats");
    auto num = [&](const char* k) { return st.has(k) ? st.at(k).number() : 0.0; };
    tr.stats.stances_in = static_cast<int>(num("stances_in"));
    tr.stats.stances_kept = static_cast<int>(num("stances_kept"));
    tr.stats.transitions = static_cast<int>(num("transitions"));
    tr.stats.repairs = static_cast<int>(num("repairs"));
    tr.stats.posture_calls = static_cast<long>(num("posture_calls"));
    tr.stats.seconds = num("seconds");
  }
  return tr;
}

}  // namespace acyclic
