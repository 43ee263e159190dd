#include "planner/model/robot_model.h"

#include <cmath>
#include <filesystem>
#include <set>
#include <stdexcept>

#include <urdf_parser/urdf_parser.h>

#include "planner/common/format_error.h"
#include "planner/common/yaml_field.h"
#include "planner/model/simbody_impl.h"

namespace acyclic {
namespace fs = std::filesystem;

namespace {

Eigen::Isometry3d toEigen(const urdf::Pose& p) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(p.position.x, p.position.y, p.position.z);
  T.linear() = Eigen::Quaterniond(p.rotation.w, p.rotation.x, p.rotation.y, p.rotation.z)
                   .normalized()
                   .toRotationMatrix();
  return T;
}

SimTK::Transform toSimTK(const Eigen::Isometry3d& T) {
  const Eigen::Matrix3d& R = T.linear();
  SimTK::Mat33 m;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) m(i, j) = R(i, j);
  SimTK::Rotation rot(m);  // orthonormal input; Simbody re-orthogonalizes
  return SimTK::Transform(rot, SimTK::Vec3(T.translation().x(), T.translation().y(), T.translation().z()));
}

CollisionShape readShape(const urdf::Collision& c, const std::string& file, const std::string& link) {
  CollisionShape s;
  s.name = c.name;
  s.pose = toEigen(c.origin);
  const std::string where = "link " + link + " collision '" + c.name + "'";
  if (!c.geometry) throw FormatError(file, where, "a geometry");
  switch (c.geometry->type) {
    case urdf::Geometry::BOX: {
      auto& b = static_cast<const urdf::Box&>(*c.geometry);
      s.kind = CollisionShape::Kind::Box;
      s.size = Eigen::Vector3d(b.dim.x, b.dim.y, b.dim.z);
      break;
    }
    case urdf::Geometry::SPHERE:
      s.kind = CollisionShape::Kind::Sphere;
      s.radius = static_cast<const urdf::Sphere&>(*c.geometry).radius;
      break;
    case urdf::Geometry::CYLINDER: {
      auto& cy = static_cast<const urdf::Cylinder&>(*c.geometry);
      // URDF has no capsule: a cylinder named capsule* stands for one (see the URDF's header).
      s.kind = c.name.rfind("capsule", 0) == 0 ? CollisionShape::Kind::Capsule
                                                : CollisionShape::Kind::Cylinder;
      s.radius = cy.radius;
      s.length = cy.length;
      break;
    }
    default:
      throw FormatError(file, where, "a box, sphere or cylinder (meshes are not supported)");
  }
  return s;
}

}  // namespace

RobotModel::RobotModel() : impl_(std::make_unique<Impl>()) {}
RobotModel::~RobotModel() = default;

std::shared_ptr<const RobotModel> RobotModel::load(const std::string& yaml_path) {
  YamlField root = YamlField::loadFile(yaml_path);
  root.requireFormat("acyclic.robot/1");
  root.allowOnly({"format", "name", "urdf", "base_link", "controller_order", "contact_spots",
                  "self_collision_pairs", "postures", "acceleration_limits"});
  std::shared_ptr<RobotModel> m(new RobotModel());
  m->yaml_path_ = yaml_path;
  m->urdf_path_ = (fs::path(yaml_path).parent_path() / root["urdf"].string()).string();

  urdf::ModelInterfaceSharedPtr urdf = urdf::parseURDFFile(m->urdf_path_);
  if (!urdf) throw FormatError(yaml_path, "urdf", "a readable, valid URDF file (" + m->urdf_path_ + ")");
  const std::string& ufile = m->urdf_path_;
  m->name_ = root.has("name") ? root["name"].string() : urdf->getName();

  // Links: the base first, then each joint's child in controller order, so a
  // parent always precedes its children.
  const std::string base = root["base_link"].string();
  auto addLink = [&](const std::string& name, int parent_joint) {
    auto ul = urdf->getLink(name);
    LinkInfo li;
    li.name = name;
    li.index = static_cast<int>(m->links_.size());
    li.parent_joint = parent_joint;
    if (ul->inertial) {
      li.mass = ul->inertial->mass;
      Eigen::Isometry3d Ti = toEigen(ul->inertial->origin);
      li.com = Ti.translation();
      Eigen::Matrix3d I;
      I << ul->inertial->ixx, ul->inertial->ixy, ul->inertial->ixz, ul->inertial->ixy,
          ul->inertial->iyy, ul->inertial->iyz, ul->inertial->ixz, ul->inertial->iyz, ul->inertial->izz;
      li.inertia = Ti.linear() * I * Ti.linear().transpose();
    }
    if (li.mass <= 0) throw FormatError(ufile, "link " + name + " inertial.mass", "a positive mass");
    for (const auto& c : ul->collision_array) li.shapes.push_back(readShape(*c, ufile, name));
    m->links_.push_back(li);
  };
  if (!urdf->getLink(base)) root["base_link"].fail("a link of " + ufile);
  addLink(base, -1);

  YamlField order = root["controller_order"];
  std::set<std::string> seen;
  for (std::size_t i = 0; i < order.size(); ++i) {
    const std::string jn = order.at(i).string();
    auto uj = urdf->getJoint(jn);
    if (!uj) order.at(i).fail("a joint of " + ufile);
    if (!seen.insert(jn).second) order.at(i).fail("a joint not listed before");
    if (uj->type != urdf::Joint::REVOLUTE)
      throw FormatError(ufile, "joint " + jn + " type", "revolute (the only joint type supported)");
    JointInfo j;
    j.name = jn;
    j.index = static_cast<int>(i);
    j.parent_link = m->linkIndex(uj->parent_link_name);
    if (j.parent_link < 0)
      order.at(i).fail("a joint listed after the joint that moves its parent link " + uj->parent_link_name);
    if (!uj->limits) throw FormatError(ufile, "joint " + jn + " limit", "lower, upper, effort, velocity");
    j.lower = uj->limits->lower;
    j.upper = uj->limits->upper;
    j.effort = uj->limits->effort;
    j.velocity = uj->limits->velocity;
    if (!(j.lower < j.upper)) throw FormatError(ufile, "joint " + jn + " limit", "lower < upper");
    if (j.effort <= 0 || j.velocity <= 0)
      throw FormatError(ufile, "joint " + jn + " limit", "positive effort and velocity");
    j.axis = Eigen::Vector3d(uj->axis.x, uj->axis.y, uj->axis.z).normalized();
    j.origin = toEigen(uj->parent_to_joint_origin_transform);
    addLink(uj->child_link_name, j.index);
    j.child_link = static_cast<int>(m->links_.size()) - 1;
    m->joints_.push_back(j);
  }
  for (const auto& [name, uj] : urdf->joints_)
    if (!seen.count(name))
      throw FormatError(yaml_path, "controller_order", "every joint of the URDF; missing " + name);

  // Acceleration limits: `default` and any joint by name, rad/s^2.
  for (auto& j : m->joints_) j.acceleration = kDefaultJointAcceleration;
  if (root.has("acceleration_limits")) {
    const YamlField acc = root["acceleration_limits"];
    if (!acc.isMap()) acc.fail("a map of joint names (or default) to rad/s^2");
    auto value = [](const YamlField& f) {
      const double a = f.number();
      if (!(a > 0 && a <= 1e4)) f.fail("an acceleration in (0, 10000] rad/s^2");
      return a;
    };
    if (acc.has("default"))
      for (auto& j : m->joints_) j.acceleration = value(acc["default"]);
    for (const std::string& k : acc.keys()) {
      if (k == "default") continue;
      const int ji = m->jointIndex(k);
      if (ji < 0) acc[k].fail("a joint of the robot (or default)");
      m->joints_[ji].acceleration = value(acc[k]);
    }
  }

  // Tree structure: which joints move which links.
  m->ancestors_.assign(m->links_.size(), {});
  for (const auto& l : m->links_) {
    for (int j = l.parent_joint; j >= 0; j = m->links_[m->joints_[j].parent_link].parent_joint)
      m->ancestors_[l.index].insert(m->ancestors_[l.index].begin(), j);
  }
  m->moves_.assign(m->joints_.size(), std::vector<bool>(m->links_.size(), false));
  m->subtree_mass_.assign(m->joints_.size(), 0.0);
  for (const auto& l : m->links_)
    for (int j : m->ancestors_[l.index]) {
      m->moves_[j][l.index] = true;
      m->subtree_mass_[j] += l.mass;
    }
  // A limb hangs from the last joint, on the way from the base, whose parent link branches.
  std::vector<int> children(m->links_.size(), 0);
  for (const auto& j : m->joints_) ++children[j.parent_link];
  m->limb_root_.assign(m->links_.size(), -1);
  for (const auto& l : m->links_)
    for (int j : m->ancestors_[l.index])
      if (children[m->joints_[j].parent_link] > 1) m->limb_root_[l.index] = j;

  // Simbody: a free-flying base and one pin per joint.
  Impl& S = *m->impl_;
  auto massProps = [](const LinkInfo& l) {
    const Eigen::Vector3d& c = l.com;
    Eigen::Matrix3d Io = l.inertia + l.mass * (c.squaredNorm() * Eigen::Matrix3d::Identity() - c * c.transpose());
    SimTK::Mat33 I;
    for (int i = 0; i < 3; ++i)
      for (int k = 0; k < 3; ++k) I(i, k) = Io(i, k);
    return SimTK::MassProperties(l.mass, SimTK::Vec3(c.x(), c.y(), c.z()), SimTK::Inertia(I));
  };
  S.link_mobod.resize(m->links_.size());
  SimTK::MobilizedBody::Free baseBody(S.matter.updGround(), SimTK::Transform(),
                                      SimTK::Body::Rigid(massProps(m->links_[0])), SimTK::Transform());
  S.base_mobod = baseBody.getMobilizedBodyIndex();
  S.link_mobod[0] = S.base_mobod;
  for (const auto& j : m->joints_) {
    const Eigen::Isometry3d& X_PJ = j.origin;
    // A Pin turns about z of its frames: align z with the joint axis.
    Eigen::Isometry3d A = Eigen::Isometry3d::Identity();
    A.linear() = Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), j.axis).toRotationMatrix();
    SimTK::MobilizedBody::Pin pin(S.matter.updMobilizedBody(S.link_mobod[j.parent_link]), toSimTK(X_PJ * A),
                                  SimTK::Body::Rigid(massProps(m->links_[j.child_link])), toSimTK(A));
    S.link_mobod[j.child_link] = pin.getMobilizedBodyIndex();
  }
  S.system.realizeTopology();
  S.default_state = S.system.getDefaultState();
  S.system.realizeModel(S.default_state);

  // Simbody's generalized speeds: the free base's (angular, linear), then one per pin.
  const int nu = S.default_state.getNU();
  if (nu != m->tangentSize()) throw std::logic_error("Simbody system has an unexpected number of speeds");
  S.tangent_of_u.assign(nu, -1);
  const auto& free = S.matter.getMobilizedBody(S.base_mobod);
  const int u0 = free.getFirstUIndex(S.default_state);
  for (int k = 0; k < 3; ++k) {
    S.tangent_of_u[u0 + k] = 3 + k;      // angular -> rotation
    S.tangent_of_u[u0 + 3 + k] = k;      // linear -> translation
  }
  S.q_of_joint.resize(m->joints_.size());
  for (const auto& j : m->joints_) {
    const auto& mb = S.matter.getMobilizedBody(S.link_mobod[j.child_link]);
    S.tangent_of_u[mb.getFirstUIndex(S.default_state)] = 6 + j.index;
    S.q_of_joint[j.index] = mb.getFirstQIndex(S.default_state);
  }

  // Contact spots.
  if (root.has("contact_spots")) {
    YamlField spots = root["contact_spots"];
    for (const auto& name : spots.keys()) {
      YamlField s = spots[name];
      s.allowOnly({"body", "position", "rpy", "rpy_deg", "quaternion", "polygon"});
      ContactSpot cs;
      cs.name = name;
      cs.link = m->linkIndex(s["body"].string());
      if (cs.link < 0) s["body"].fail("a link of the URDF");
      cs.frame = readPose(s);
      cs.polygon = s["polygon"].polygon();
      m->spots_.push_back(cs);
    }
  }

  // Self-collision pairs: products of two link groups.
  if (root.has("self_collision_pairs")) {
    YamlField pairs = root["self_collision_pairs"];
    std::set<std::pair<int, int>> unique;
    for (std::size_t i = 0; i < pairs.size(); ++i) {
      YamlField p = pairs.at(i);
      p.allowOnly({"a", "b"});
      auto group = [&](const YamlField& g) {
        std::vector<int> out;
        for (std::size_t k = 0; k < g.size(); ++k) {
          int l = m->linkIndex(g.at(k).string());
          if (l < 0) g.at(k).fail("a link of the URDF");
          if (m->links_[l].shapes.empty()) g.at(k).fail("a link with collision shapes");
          out.push_back(l);
        }
        return out;
      };
      for (int a : group(p["a"]))
        for (int b : group(p["b"])) {
          if (a == b) p.fail("two different links in each pair");
          unique.insert({std::min(a, b), std::max(a, b)});
        }
    }
    m->self_pairs_.assign(unique.begin(), unique.end());
  }

  if (root.has("postures")) {
    YamlField ps = root["postures"];
    for (const auto& name : ps.keys()) m->postures_[name] = m->readConfiguration(ps[name]);
  }
  return m;
}

int RobotModel::jointIndex(const std::string& name) const {
  for (const auto& j : joints_)
    if (j.name == name) return j.index;
  return -1;
}
int RobotModel::linkIndex(const std::string& name) const {
  for (const auto& l : links_)
    if (l.name == name) return l.index;
  return -1;
}
int RobotModel::spotIndex(const std::string& name) const {
  for (std::size_t i = 0; i < spots_.size(); ++i)
    if (spots_[i].name == name) return static_cast<int>(i);
  return -1;
}
std::vector<std::string> RobotModel::jointNames() const {
  std::vector<std::string> out;
  for (const auto& j : joints_) out.push_back(j.name);
  return out;
}
double RobotModel::totalMass() const {
  double m = 0;
  for (const auto& l : links_) m += l.mass;
  return m;
}

#define ACYCLIC_LIMIT_VECTOR(fn, field)                               \
  Eigen::VectorXd RobotModel::fn() const {                            \
    Eigen::VectorXd v(numJoints());                                   \
    for (const auto& j : joints_) v[j.index] = j.field;               \
    return v;                                                         \
  }
ACYCLIC_LIMIT_VECTOR(lowerLimits, lower)
ACYCLIC_LIMIT_VECTOR(upperLimits, upper)
ACYCLIC_LIMIT_VECTOR(velocityLimits, velocity)
ACYCLIC_LIMIT_VECTOR(accelerationLimits, acceleration)
ACYCLIC_LIMIT_VECTOR(effortLimits, effort)
#undef ACYCLIC_LIMIT_VECTOR

Configuration RobotModel::zeroConfiguration() const {
  Configuration q;
  q.joints = Eigen::VectorXd::Zero(numJoints());
  return q;
}

const Configuration& RobotModel::posture(const std::string& name) const {
  auto it = postures_.find(name);
  if (it == postures_.end()) throw std::out_of_range("no posture named '" + name + "'");
  return it->second;
}

Configuration RobotModel::readConfiguration(const YamlField& f) const {
  f.allowOnly({"posture", "base_position", "base_orientation", "base_rpy_deg", "joints", "joints_rad",
               "joints_deg"});
  Configuration q = zeroConfiguration();
  if (f.has("posture")) {
    std::string p = f["posture"].string();
    auto it = postures_.find(p);
    if (it == postures_.end()) {
      std::string names;
      for (const auto& [n, _] : postures_) names += (names.empty() ? "" : ", ") + n;
      f["posture"].fail("a named posture of the robot (" + names + ")");
    }
    q = it->second;
  }
  if (f.has("base_position")) q.base_position = f["base_position"].vec3();
  if (f.has("base_orientation") && f.has("base_rpy_deg"))
    f.fail("at most one of base_orientation and base_rpy_deg");
  if (f.has("base_orientation")) {
    auto v = f["base_orientation"].numbers(4);
    Eigen::Quaterniond o(v[0], v[1], v[2], v[3]);
    if (std::abs(o.norm() - 1) > 1e-6) f["base_orientation"].fail("a unit quaternion [w, x, y, z]");
    q.base_orientation = o.normalized();
  }
  if (f.has("base_rpy_deg")) q.base_orientation = rpyToQuaternion(f["base_rpy_deg"].angles3(true) * M_PI / 180);
  if (f.has("joints")) {
    const YamlField list = f["joints"];
    list.numbers(numJoints());  // the count, with its message
    for (int j = 0; j < numJoints(); ++j) q.joints[j] = list.at(j).angle();
  }
  for (const char* key : {"joints_rad", "joints_deg"}) {
    if (!f.has(key)) continue;
    const double scale = std::string(key) == "joints_deg" ? M_PI / 180 : 1.0;
    YamlField map = f[key];
    for (const auto& name : map.keys()) {
      int j = jointIndex(name);
      if (j < 0) throw FormatError(map.file(), map.path() + "." + name, "a joint name of the robot");
      q.joints[j] = (scale == 1.0 ? map[name].angle() : map[name].degrees()) * scale;
    }
  }
  return q;
}

std::vector<int> RobotModel::jointsMovedBy(int joint) const {
  std::vector<int> out;
  for (const auto& j : joints_)
    if (jointMovesLink(joint, j.child_link)) out.push_back(j.index);
  return out;
}

}  // namespace acyclic
