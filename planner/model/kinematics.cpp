#include "planner/model/kinematics.h"

#include <stdexcept>

#include "planner/model/simbody_impl.h"

namespace acyclic {

struct Kinematics::State {
  SimTK::State s;
  SimTK::Matrix scratch;
};

namespace {
SimTK::Vec3 toVec3(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }
Eigen::Vector3d toEigen(const SimTK::Vec3& v) { return {v[0], v[1], v[2]}; }
}  // namespace

Kinematics::Kinematics(std::shared_ptr<const RobotModel> model)
    : model_(std::move(model)), state_(std::make_unique<State>()) {
  state_->s = model_->impl().default_state;
  setConfiguration(model_->zeroConfiguration());
}

Kinematics::~Kinematics() = default;

void Kinematics::requireSize(const Configuration& q) const {
  if (q.joints.size() != model_->numJoints())
    throw std::invalid_argument("Kinematics: configuration has " + std::to_string(q.joints.size()) +
                                " joints, the model " + std::to_string(model_->numJoints()));
}

void Kinematics::setConfiguration(const Configuration& q) {
  const auto& S = model_->impl();
  requireSize(q);
  q_ = q;
  const Eigen::Quaterniond o = q.base_orientation.normalized();
  SimTK::Transform X(SimTK::Rotation(SimTK::Quaternion(o.w(), o.x(), o.y(), o.z())), toVec3(q.base_position));
  S.matter.getMobilizedBody(S.base_mobod).setQToFitTransform(state_->s, X);
  SimTK::Vector& Q = state_->s.updQ();
  for (int j = 0; j < model_->numJoints(); ++j) Q[S.q_of_joint[j]] = q.joints[j];
  S.system.realize(state_->s, SimTK::Stage::Position);
  const int nl = model_->numLinks();
  link_pose_.resize(nl);
  for (int l = 0; l < nl; ++l) {
    const SimTK::Transform& X = S.matter.getMobilizedBody(S.link_mobod[l]).getBodyTransform(state_->s);
    Eigen::Isometry3d& T = link_pose_[l];
    T.setIdentity();
    const SimTK::Mat33& R = X.R().asMat33();
    for (int i = 0; i < 3; ++i)
      for (int k = 0; k < 3; ++k) T.linear()(i, k) = R(i, k);
    T.translation() = toEigen(X.p());
  }
  simbody_current_ = true;
  setJointFrames();
}

void Kinematics::setPoses(const Configuration& q) {
  requireSize(q);
  q_ = q;
  simbody_current_ = false;
  link_pose_.resize(model_->numLinks());
  link_pose_[0] = q.basePose();
  // Joints come parent first (RobotModel refuses another order).
  for (const auto& j : model_->joints())
    link_pose_[j.child_link] = link_pose_[j.parent_link] * j.origin * Eigen::AngleAxisd(q.joints[j.index], j.axis);
  setJointFrames();
}

void Kinematics::setJointFrames() {
  // A joint's frame is its child link's frame: its axis there is unchanged by its own rotation.
  joint_axis_.resize(model_->numJoints());
  joint_origin_.resize(model_->numJoints());
  for (const auto& j : model_->joints()) {
    joint_axis_[j.index] = link_pose_[j.child_link].linear() * j.axis;
    joint_origin_[j.index] = link_pose_[j.child_link].translation();
  }
}

Eigen::MatrixXd Kinematics::chainPointJacobian(int link, const Eigen::Vector3d& p) const {
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(3, model_->tangentSize());
  const Eigen::Vector3d r = p - link_pose_[0].translation();
  J.block<3, 3>(0, 0).setIdentity();
  J.block<3, 3>(0, 3) << 0, r.z(), -r.y(), -r.z(), 0, r.x(), r.y(), -r.x(), 0;  // -[r]x
  for (int j : model_->ancestorJoints(link)) J.col(6 + j) = joint_axis_[j].cross(p - joint_origin_[j]);
  return J;
}

void Kinematics::addPointGradient(int link, const Eigen::Vector3d& p, const Eigen::Vector3d& v,
                                  Eigen::Ref<Eigen::VectorXd> grad) const {
  grad.segment<3>(0) += v;
  grad.segment<3>(3) += (p - link_pose_[0].translation()).cross(v);
  for (int j : model_->ancestorJoints(link)) grad[6 + j] += v.dot(joint_axis_[j].cross(p - joint_origin_[j]));
}

void Kinematics::addAxisGradient(int link, const Eigen::Vector3d& u, const Eigen::Vector3d& w,
                                 Eigen::Ref<Eigen::VectorXd> grad) const {
  // A rotation by omega moves u by omega x u: d(u . w) = omega . (u x w).
  const Eigen::Vector3d uxw = u.cross(w);
  grad.segment<3>(3) += uxw;
  for (int j : model_->ancestorJoints(link)) grad[6 + j] += joint_axis_[j].dot(uxw);
}

void Kinematics::requireSimbody(const char* query) const {
  if (!simbody_current_)
    throw std::logic_error(std::string("Kinematics::") + query + " after setPoses: call setConfiguration first");
}

Eigen::Isometry3d Kinematics::spotPose(int spot) const {
  const ContactSpot& s = model_->spots().at(spot);
  return linkPose(s.link) * s.frame;
}

Eigen::MatrixXd Kinematics::pointJacobian(int link, const Eigen::Vector3d& p) const {
  requireSimbody("pointJacobian");
  const auto& S = model_->impl();
  S.matter.calcStationJacobian(state_->s, S.link_mobod.at(link), toVec3(p), state_->scratch);
  const SimTK::Matrix& J = state_->scratch;
  Eigen::MatrixXd out(3, model_->tangentSize());
  for (int u = 0; u < J.ncol(); ++u) {
    const int t = S.tangent_of_u[u];
    for (int r = 0; r < 3; ++r) out(r, t) = J(r, u);
  }
  return out;
}

Eigen::MatrixXd Kinematics::frameJacobian(int link, const Eigen::Vector3d& origin) const {
  requireSimbody("frameJacobian");
  const auto& S = model_->impl();
  S.matter.calcFrameJacobian(state_->s, S.link_mobod.at(link), toVec3(origin), state_->scratch);
  const SimTK::Matrix& J = state_->scratch;  // rows: angular(3), linear(3)
  Eigen::MatrixXd out(6, model_->tangentSize());
  for (int u = 0; u < J.ncol(); ++u) {
    const int t = S.tangent_of_u[u];
    for (int r = 0; r < 3; ++r) {
      out(r, t) = J(3 + r, u);
      out(3 + r, t) = J(r, u);
    }
  }
  return out;
}

Eigen::Vector3d Kinematics::centerOfMass() const {
  requireSimbody("centerOfMass");
  const auto& S = model_->impl();
  return toEigen(S.matter.calcSystemMassCenterLocationInGround(state_->s));
}

Eigen::MatrixXd Kinematics::centerOfMassJacobian() const {
  requireSimbody("centerOfMassJacobian");
  // Simbody has no system mass-centre Jacobian: row k is J^T applied to the
  // forces (m_i / M) e_k at each link's centre of mass, one O(n) pass per row.
  const auto& S = model_->impl();
  const double M = model_->totalMass();
  Eigen::MatrixXd out(3, model_->tangentSize());
  SimTK::Vector_<SimTK::SpatialVec> F(S.matter.getNumBodies());
  SimTK::Vector f;
  for (int k = 0; k < 3; ++k) {
    F = SimTK::SpatialVec(SimTK::Vec3(0), SimTK::Vec3(0));
    SimTK::Vec3 e(0);
    e[k] = 1.0;
    for (const auto& l : model_->links()) {
      const auto& mb = S.matter.getMobilizedBody(S.link_mobod[l.index]);
      const SimTK::Vec3 r = mb.getBodyRotation(state_->s) * toVec3(l.com);
      const SimTK::Vec3 force = (l.mass / M) * e;
      F[mb.getMobilizedBodyIndex()] = SimTK::SpatialVec(r % force, force);
    }
    S.matter.multiplyBySystemJacobianTranspose(state_->s, F, f);
    for (int u = 0; u < f.size(); ++u) out(k, S.tangent_of_u[u]) = f[u];
  }
  return out;
}

Eigen::VectorXd Kinematics::gravityTorques() const {
  requireSimbody("gravityTorques");
  const auto& S = model_->impl();
  const int nb = S.matter.getNumBodies();
  SimTK::Vector_<SimTK::SpatialVec> F(nb, SimTK::SpatialVec(SimTK::Vec3(0), SimTK::Vec3(0)));
  const SimTK::Vec3 g = toVec3(S.gravity);
  for (const auto& l : model_->links()) {
    const auto& mb = S.matter.getMobilizedBody(S.link_mobod[l.index]);
    const SimTK::Vec3 r = mb.getBodyRotation(state_->s) * toVec3(l.com);  // origin -> com, ground axes
    const SimTK::Vec3 f = l.mass * g;
    F[mb.getMobilizedBodyIndex()] = SimTK::SpatialVec(r % f, f);
  }
  SimTK::Vector f;
  S.matter.multiplyBySystemJacobianTranspose(state_->s, F, f);
  Eigen::VectorXd out(model_->tangentSize());
  for (int u = 0; u < f.size(); ++u) out[S.tangent_of_u[u]] = -f[u];
  return out;
}

}  // namespace acyclic
