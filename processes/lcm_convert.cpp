#include "processes/lcm_convert.h"

#include <cmath>

#include "planner/common/format_error.h"

namespace acyclic::convert {

namespace {

std::string field(const std::string& base, std::size_t i) { return base + "[" + std::to_string(i) + "]"; }

void checkJointNames(const std::vector<std::string>& names, const Scenario& sc, const std::string& origin) {
  const auto expected = sc.robot->jointNames();
  if (names != expected)
    throw FormatError(origin, "joint_names", "the robot's " + std::to_string(expected.size()) +
                                                 " joint names in controller order");
}

}  // namespace

ContactSpec fromMessage(const contact_t& c, const Scenario& sc, const std::string& origin, const std::string& at) {
  ContactSpec s;
  s.spot = sc.robot->spotIndex(c.spot);
  if (s.spot < 0) throw FormatError(origin, at + ".spot", "a contact spot of the robot (got '" + c.spot + "')");
  s.surface = sc.scene->surfaceIndex(c.surface);
  if (s.surface < 0)
    throw FormatError(origin, at + ".surface", "a surface of the scene (got '" + c.surface + "')");
  s.supporting = c.supporting;
  s.placement = {c.x, c.y, c.theta};
  return s;
}

contact_t toMessage(const ContactSpec& s, const Scenario& sc) {
  contact_t c{};
  c.spot = sc.robot->spots()[s.spot].name;
  c.surface = sc.scene->surfaces()[s.surface].name;
  c.supporting = s.supporting;
  c.x = s.placement.x;
  c.y = s.placement.y;
  c.theta = s.placement.theta;
  const Eigen::Isometry3d f = contactFrame(sc.scene->surfaces()[s.surface], s.placement);
  const Eigen::Quaterniond o(f.linear());
  for (int k = 0; k < 3; ++k) c.position[k] = f.translation()[k];
  c.orientation[0] = o.w(), c.orientation[1] = o.x(), c.orientation[2] = o.y(), c.orientation[3] = o.z();
  c.num_points = 0;
  return c;
}

configuration_t toMessageAsIs(const Configuration& q) {
  configuration_t m{};
  const Eigen::Quaterniond& o = q.base_orientation;
  for (int k = 0; k < 3; ++k) m.base_position[k] = q.base_position[k];
  m.base_orientation[0] = o.w(), m.base_orientation[1] = o.x(), m.base_orientation[2] = o.y(),
  m.base_orientation[3] = o.z();
  m.num_joints = static_cast<int32_t>(q.joints.size());
  m.joints.assign(q.joints.data(), q.joints.data() + q.joints.size());
  return m;
}

configuration_t toMessage(const Configuration& q) {
  configuration_t m = toMessageAsIs(q);
  const Eigen::Quaterniond o = q.base_orientation.normalized();
  m.base_orientation[0] = o.w(), m.base_orientation[1] = o.x(), m.base_orientation[2] = o.y(),
  m.base_orientation[3] = o.z();
  return m;
}

Configuration fromMessage(const configuration_t& m, const Scenario& sc, const std::string& origin) {
  Configuration q;
  q.base_position = {m.base_position[0], m.base_position[1], m.base_position[2]};
  q.base_orientation = Eigen::Quaterniond(m.base_orientation[0], m.base_orientation[1], m.base_orientation[2],
                                          m.base_orientation[3]);
  if (!(std::abs(q.base_orientation.norm() - 1) <= 1e-6))
    throw FormatError(origin, "base_orientation", "a unit quaternion [w, x, y, z]");
  if (m.num_joints != sc.robot->numJoints())
    throw FormatError(origin, "num_joints", std::to_string(sc.robot->numJoints()) + " joints");
  q.joints = Eigen::Map<const Eigen::VectorXd>(m.joints.data(), m.num_joints);
  if (!q.joints.allFinite() || !q.base_position.allFinite()) throw FormatError(origin, "joints", "finite numbers");
  return q;
}

plan_t toMessage(const Plan& plan, const Scenario& sc) {
  plan_t m{};
  m.joint_names = sc.robot->jointNames();
  m.num_joints = static_cast<int32_t>(m.joint_names.size());
  for (const auto& s : plan.stances) {
    stance_t st{};
    for (const auto& c : s.contacts) {
      contact_t mc = toMessage(c.spec, sc);
      mc.num_points = static_cast<int32_t>(c.points.size());
      for (std::size_t k = 0; k < c.points.size(); ++k) {
        mc.points.push_back({c.points[k].x(), c.points[k].y(), c.points[k].z()});
        mc.forces.push_back({c.forces[k].x(), c.forces[k].y(), c.forces[k].z()});
      }
      st.contacts.push_back(mc);
    }
    st.num_contacts = static_cast<int32_t>(st.contacts.size());
    st.configuration = toMessage(s.configuration);
    st.potential = s.potential;
    m.stances.push_back(st);
  }
  m.num_stances = static_cast<int32_t>(m.stances.size());
  m.nodes_generated = plan.stats.nodes_generated;
  m.nodes_expanded = plan.stats.nodes_expanded;
  m.posture_calls = plan.stats.posture_calls;
  m.posture_failures = plan.stats.posture_failures;
  m.seconds = plan.stats.seconds;
  return m;
}

Plan fromMessage(const plan_t& m, const Scenario& sc) {
  const std::string origin = "ACYCLIC_PLAN message (request " + std::to_string(m.request_id) + ")";
  checkJointNames(m.joint_names, sc, origin);
  Plan plan;
  plan.scenario = m.scenario_name;
  for (std::size_t i = 0; i < m.stances.size(); ++i) {
    const stance_t& st = m.stances[i];
    PlanStance s;
    for (std::size_t k = 0; k < st.contacts.size(); ++k) {
      const contact_t& mc = st.contacts[k];
      PlanContact c;
      c.spec = fromMessage(mc, sc, origin, field(field("stances", i) + ".contacts", k));
      c.frame = contactFrame(sc.scene->surfaces()[c.spec.surface], c.spec.placement);
      for (int p = 0; p < mc.num_points; ++p) {
        c.points.emplace_back(mc.points[p][0], mc.points[p][1], mc.points[p][2]);
        c.forces.emplace_back(mc.forces[p][0], mc.forces[p][1], mc.forces[p][2]);
      }
      s.contacts.push_back(c);
    }
    s.configuration = fromMessage(st.configuration, sc, origin + " " + field("stances", i) + ".configuration");
    s.potential = st.potential;
    plan.stances.push_back(s);
  }
  plan.stats = {m.nodes_generated, m.nodes_expanded, m.posture_calls, m.posture_failures, m.seconds};
  return plan;
}

trajectory_t toMessage(const Trajectory& tr, const Scenario& sc) {
  trajectory_t m{};
  m.dt = tr.dt;
  m.joint_names = sc.robot->jointNames();
  m.num_joints = static_cast<int32_t>(m.joint_names.size());
  const std::size_t n = tr.samples.size();
  m.num_samples = static_cast<int32_t>(n);
  m.t.resize(n);
  m.phase.resize(n);
  m.base_position.resize(n);
  m.base_orientation.resize(n);
  m.joints.resize(n);
  m.joint_velocities.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const TrajectorySample& s = tr.samples[i];
    m.t[i] = s.t;
    m.phase[i] = s.phase;
    const configuration_t c = toMessage(s.q);
    m.base_position[i] = {c.base_position[0], c.base_position[1], c.base_position[2]};
    m.base_orientation[i] = {c.base_orientation[0], c.base_orientation[1], c.base_orientation[2],
                             c.base_orientation[3]};
    m.joints[i] = c.joints;
    m.joint_velocities[i].assign(s.dq.data(), s.dq.data() + s.dq.size());
  }
  for (const auto& p : tr.phases) {
    trajectory_phase_t mp{};
    mp.t_start = p.t_start;
    mp.t_end = p.t_end;
    mp.stabilizer = false;
    for (const auto& c : p.contacts) {
      mp.spots.push_back(sc.robot->spots()[c.spot].name);
      mp.surfaces.push_back(sc.scene->surfaces()[c.surface].name);
      mp.supporting.push_back(c.supporting);
      // Placements travel with the phase (x, y, theta per contact) so that the
      // trajectory is complete without its plan.
      mp.x.push_back(c.placement.x);
      mp.y.push_back(c.placement.y);
      mp.theta.push_back(c.placement.theta);
    }
    mp.num_contacts = static_cast<int32_t>(mp.spots.size());
    mp.stance = p.stance;
    m.phases.push_back(mp);
  }
  m.num_phases = static_cast<int32_t>(m.phases.size());
  return m;
}

Trajectory fromMessage(const trajectory_t& m, const Scenario& sc) {
  const std::string origin = "ACYCLIC_TRAJECTORY message (request " + std::to_string(m.request_id) + ")";
  checkJointNames(m.joint_names, sc, origin);
  if (!(m.dt > 0)) throw FormatError(origin, "dt", "a positive sample period");
  Trajectory tr;
  tr.dt = m.dt;
  for (std::size_t i = 0; i < m.phases.size(); ++i) {
    const trajectory_phase_t& mp = m.phases[i];
    TrajectoryPhase p;
    p.t_start = mp.t_start;
    p.t_end = mp.t_end;
    p.stance = mp.stance;
    for (int k = 0; k < mp.num_contacts; ++k) {
      contact_t c{};
      c.spot = mp.spots[k];
      c.surface = mp.surfaces[k];
      c.supporting = mp.supporting[k];
      c.x = mp.x[k], c.y = mp.y[k], c.theta = mp.theta[k];
      p.contacts.push_back(fromMessage(c, sc, origin, field(field("phases", i) + ".contacts", k)));
    }
    tr.phases.push_back(p);
  }
  const int phase_at_end = static_cast<int>(tr.phases.size());
  for (int i = 0; i < m.num_samples; ++i) {
    TrajectorySample s;
    s.t = m.t[i];
    if (!std::isfinite(s.t) || (i > 0 && s.t <= m.t[i - 1]))
      throw FormatError(origin, field("t", i), "finite, increasing times");
    s.q.base_position = {m.base_position[i][0], m.base_position[i][1], m.base_position[i][2]};
    s.q.base_orientation = Eigen::Quaterniond(m.base_orientation[i][0], m.base_orientation[i][1],
                                              m.base_orientation[i][2], m.base_orientation[i][3]);
    if (!(std::abs(s.q.base_orientation.norm() - 1) <= 1e-6))
      throw FormatError(origin, field("base_orientation", i), "a unit quaternion [w, x, y, z]");
    s.q.joints = Eigen::Map<const Eigen::VectorXd>(m.joints[i].data(), m.num_joints);
    s.dq = Eigen::Map<const Eigen::VectorXd>(m.joint_velocities[i].data(), m.num_joints);
    if (!s.q.joints.allFinite() || !s.dq.allFinite() || !s.q.base_position.allFinite())
      throw FormatError(origin, field("joints", i), "finite numbers");
    s.phase = m.phase[i];
    if (s.phase < 0 || s.phase >= phase_at_end)
      throw FormatError(origin, field("phase", i), "a phase index below " + std::to_string(phase_at_end));
    tr.samples.push_back(s);
  }
  if (m.num_samples > 0 && tr.phases.empty()) throw FormatError(origin, "phases", "at least one phase");
  return tr;
}

int8_t toMessage(hrp2::BridgeState s) {
  switch (s) {
    case hrp2::BridgeState::Idle: return hrp2_bridge_status_t::IDLE;
    case hrp2::BridgeState::Checking: return hrp2_bridge_status_t::CHECKING;
    case hrp2::BridgeState::Streaming: return hrp2_bridge_status_t::STREAMING;
    case hrp2::BridgeState::Holding: return hrp2_bridge_status_t::HOLDING;
    case hrp2::BridgeState::Stopped: return hrp2_bridge_status_t::STOPPED;
    case hrp2::BridgeState::Fault: return hrp2_bridge_status_t::FAULT;
  }
  // Only a value outside the enum gets here: the worst state, not a guess.
  return hrp2_bridge_status_t::FAULT;
}

hrp2::BridgeState bridgeStateFromMessage(int8_t state) {
  switch (state) {
    case hrp2_bridge_status_t::IDLE: return hrp2::BridgeState::Idle;
    case hrp2_bridge_status_t::CHECKING: return hrp2::BridgeState::Checking;
    case hrp2_bridge_status_t::STREAMING: return hrp2::BridgeState::Streaming;
    case hrp2_bridge_status_t::HOLDING: return hrp2::BridgeState::Holding;
    case hrp2_bridge_status_t::STOPPED: return hrp2::BridgeState::Stopped;
    case hrp2_bridge_status_t::FAULT: return hrp2::BridgeState::Fault;
  }
  throw FormatError("hrp2_bridge_status_t", "state", "IDLE, CHECKING, STREAMING, HOLDING, STOPPED or FAULT (got " +
                                                         std::to_string(state) + ")");
}

int8_t toMessage(hrp2::CommandMode mode) {
  switch (mode) {
    case hrp2::CommandMode::Stream: return hrp2_command_t::STREAM;
    case hrp2::CommandMode::Hold: return hrp2_command_t::HOLD;
    case hrp2::CommandMode::Freeze: return hrp2_command_t::FREEZE;
  }
  // Only a value outside the enum gets here: the safest command, not a guess.
  return hrp2_command_t::FREEZE;
}

hrp2::CommandMode commandModeFromMessage(int8_t mode) {
  switch (mode) {
    case hrp2_command_t::STREAM: return hrp2::CommandMode::Stream;
    case hrp2_command_t::HOLD: return hrp2::CommandMode::Hold;
    case hrp2_command_t::FREEZE: return hrp2::CommandMode::Freeze;
  }
  throw FormatError("hrp2_command_t", "mode", "STREAM, HOLD or FREEZE (got " + std::to_string(mode) + ")");
}

hrp2_command_t toMessage(const hrp2::Command& c, int64_t utime) {
  hrp2_command_t m{};
  m.utime = utime;
  m.request_id = c.request_id;
  m.sequence = c.sequence;
  m.mode = toMessage(c.mode);
  m.num_joints = static_cast<int32_t>(c.q.size());
  m.q.assign(c.q.data(), c.q.data() + c.q.size());
  m.dq.assign(c.dq.data(), c.dq.data() + c.dq.size());
  for (int i = 0; i < 3; ++i) {
    m.waist_position[i] = c.waist_position[i];
    m.waist_rpy[i] = c.waist_rpy[i];
    m.zmp_waist[i] = c.zmp_waist[i];
  }
  m.stabilizer = c.stabilizer;
  return m;
}

hrp2_bridge_status_t toMessage(const hrp2::BridgeStatus& s, int64_t utime) {
  hrp2_bridge_status_t m{};
  m.utime = utime;
  m.request_id = s.request_id;
  m.state = toMessage(s.state);
  m.reason = s.reason;
  m.progress = s.progress;
  m.commands_sent = s.commands_sent;
  m.tracking_error_max = s.tracking_error_max;
  m.safety_events = s.safety_events;
  m.finished_request_id = s.finished_request_id;
  return m;
}

hrp2_state_t toMessage(const hrp2::SimState& s, int64_t utime) {
  hrp2_state_t m{};
  m.utime = utime;
  m.request_id = s.request_id;
  m.command_sequence = s.command_sequence;
  m.num_joints = static_cast<int32_t>(s.q.size());
  m.q.assign(s.q.data(), s.q.data() + s.q.size());
  m.dq.assign(s.dq.data(), s.dq.data() + s.dq.size());
  for (int i = 0; i < 3; ++i) m.base_position[i] = s.configuration.base_position[i];
  const Eigen::Quaterniond& o = s.configuration.base_orientation;
  m.base_orientation[0] = o.w(), m.base_orientation[1] = o.x(), m.base_orientation[2] = o.y(),
  m.base_orientation[3] = o.z();
  m.num_wrenches = static_cast<int32_t>(s.wrenches.size());
  for (const auto& w : s.wrenches) {
    m.wrench_names.push_back(w.name);
    m.wrenches.emplace_back(w.wrench.data(), w.wrench.data() + 6);
  }
  m.servo_on = s.servo_on;
  m.stabilizer = s.stabilizer;
  return m;
}

hrp2::MeasuredState fromMessage(const hrp2_state_t& m) {
  hrp2::MeasuredState s;
  s.q = Eigen::Map<const Eigen::VectorXd>(m.q.data(), static_cast<Eigen::Index>(m.q.size()));
  s.dq = Eigen::Map<const Eigen::VectorXd>(m.dq.data(), static_cast<Eigen::Index>(m.dq.size()));
  s.request_id = m.request_id;
  s.command_sequence = m.command_sequence;
  s.servo_on = m.servo_on;
  return s;
}

hrp2::SimCommand fromMessage(const hrp2_command_t& m) {
  hrp2::SimCommand c;
  commandModeFromMessage(m.mode);  // refuses an unknown mode; the controller keeps the message's value
  c.request_id = m.request_id, c.sequence = m.sequence, c.mode = m.mode;
  c.q = Eigen::Map<const Eigen::VectorXd>(m.q.data(), static_cast<Eigen::Index>(m.q.size()));
  c.dq = Eigen::Map<const Eigen::VectorXd>(m.dq.data(), static_cast<Eigen::Index>(m.dq.size()));
  c.waist_position = Eigen::Vector3d(m.waist_position);
  c.waist_rpy = Eigen::Vector3d(m.waist_rpy);
  c.stabilizer = m.stabilizer;
  return c;
}

}  // namespace acyclic::convert
