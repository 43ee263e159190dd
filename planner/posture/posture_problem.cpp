#include "planner/posture/posture_problem.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <stdexcept>

#include "planner/common/geometry.h"

namespace acyclic {

namespace {
constexpr double kInf = 1e19;  // Ipopt's infinity
// A floating contact's spot polygon is kept this far inside its surface, so
// that the same placement, later a fixed contact, passes the check below
// (the contract allows 1 mm; the solver meets its bounds only to tolerance).
constexpr double kFloatingPolygonMargin = 1e-4;
const Eigen::Vector3d kGravity(0, 0, -9.81);

Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d S;
  S << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return S;
}

// Outward unit normals n_e and offsets b_e of a CCW convex polygon: n_e . p <= b_e inside.
void halfPlanes(const ConvexPolygon& poly, std::vector<Eigen::Vector2d>& n, std::vector<double>& b) {
  const auto& v = poly.vertices();
  for (std::size_t i = 0; i < v.size(); ++i) {
    const Eigen::Vector2d e = v[(i + 1) % v.size()] - v[i];
    const Eigen::Vector2d out = Eigen::Vector2d(e.y(), -e.x()).normalized();
    n.push_back(out);
    b.push_back(out.dot(v[i]));
  }
}
}  // namespace

PostureProblem::PostureProblem(std::shared_ptr<const RobotModel> robot, std::shared_ptr<const Scene> scene,
                               std::shared_ptr<const CollisionModel> collision, const PostureRequest& request,
                               const PostureOptions& options)
    : robot_(std::move(robot)), scene_(std::move(scene)), collision_(std::move(collision)), req_(request),
      opt_(options), kin_(robot_) {
  // Its edges must be edges of the contract's pyramid, or it could reach outside it.
  if (opt_.pyramid_sides < 3 || kFrictionPyramidEdges % opt_.pyramid_sides != 0)
    throw std::invalid_argument("pyramid_sides = " + std::to_string(opt_.pyramid_sides) + ": expected a divisor of " +
                                std::to_string(kFrictionPyramidEdges) + " of at least 3");
  if (!(opt_.support_inset >= 0 && std::isfinite(opt_.support_inset)))
    throw std::invalid_argument("support_inset: expected a finite length >= 0 (m)");
  if (!(opt_.support_inset_y < 0 || std::isfinite(opt_.support_inset_y)))
    throw std::invalid_argument("support_inset_y: expected a finite length (m; < 0: support_inset)");
  if (!(opt_.friction_share > 0 && opt_.friction_share <= 1))
    throw std::invalid_argument("friction_share: expected a share in (0, 1]");
  if (req_.initial_guess.joints.size() != robot_->numJoints())
    throw std::invalid_argument("initial guess has " + std::to_string(req_.initial_guess.joints.size()) +
                                " joints, the robot " + std::to_string(robot_->numJoints()));
  if (!req_.initial_guess.joints.allFinite() || !req_.initial_guess.base_position.allFinite() ||
      !req_.initial_guess.base_orientation.coeffs().allFinite())
    throw std::invalid_argument("initial guess has a non-finite value");
  req_.initial_guess.base_orientation.normalize();
  if (!req_.cost) req_.cost = std::make_shared<ReferencePostureCost>(req_.initial_guess);

  std::set<int> spots;
  auto checkContact = [&](int spot, int surface) {
    if (spot < 0 || spot >= static_cast<int>(robot_->spots().size())) throw std::invalid_argument("unknown spot");
    if (surface < 0 || surface >= static_cast<int>(scene_->surfaces().size()))
      throw std::invalid_argument("unknown surface");
    if (!spots.insert(spot).second)
      throw std::invalid_argument("spot " + robot_->spots()[spot].name + " is in two contacts");
    allowed_touch_.push_back({robot_->spots()[spot].link, scene_->surfaces()[surface].obstacle});
  };
  for (const auto& c : req_.contacts) {
    checkContact(c.spot, c.surface);
    // A fixed contact's spot polygon must lie on its surface (docs/design.md section 9).
    const Surface& s = scene_->surfaces()[c.surface];
    for (const auto& v : robot_->spots()[c.spot].polygon.vertices()) {
      const Eigen::Vector2d p = Eigen::Vector2d(c.placement.x, c.placement.y) +
                                Eigen::Rotation2Dd(c.placement.theta) * v;
      if (!s.polygon.contains(p, kContactPolygonTolerance))
        throw std::invalid_argument("contact " + robot_->spots()[c.spot].name + "@" + s.name +
                                    ": the spot polygon leaves the surface polygon");
    }
  }
  if (req_.floating) {
    checkContact(req_.floating->spot, req_.floating->surface);
    if (!(req_.floating->volume.theta_min <= req_.floating->volume.theta_max))
      throw std::invalid_argument("search volume: theta_min > theta_max");
  }
  if (req_.pose_target) {
    const PoseTarget& t = *req_.pose_target;
    if (t.spot < 0 || t.spot >= static_cast<int>(robot_->spots().size())) throw std::invalid_argument("unknown spot");
    if (!spots.insert(t.spot).second)
      throw std::invalid_argument("spot " + robot_->spots()[t.spot].name + " is in a contact and a pose target");
    if (!t.pose.matrix().allFinite()) throw std::invalid_argument("pose target has a non-finite value");
    if (!(t.orientation_tolerance >= 0 && t.orientation_tolerance < 1))
      throw std::invalid_argument("pose target: orientation tolerance outside [0, 1)");
    if (!(t.position_tolerance.minCoeff() >= 0) || !(t.touch_margin >= 0 && t.touch_margin <= opt_.collision_margin))
      throw std::invalid_argument("pose target: negative position tolerance, or touch margin outside [0, collision margin]");
    for (int o : t.touch_obstacles) {
      if (o < 0 || o >= static_cast<int>(scene_->obstacles().size())) throw std::invalid_argument("unknown obstacle");
      near_touch_.push_back({robot_->spots()[t.spot].link, o});
    }
  }

  nq_ = robot_->tangentSize();
  int nx = nq_;
  if (req_.floating) x_float_ = nx, nx += 3;
  x_lambda_ = nx;
  for (int ci = 0; ci < static_cast<int>(req_.contacts.size()); ++ci) {
    const ContactSpec& c = req_.contacts[ci];
    if (!c.supporting) continue;
    const Surface& s = scene_->surfaces()[c.surface];
    Support sup;
    sup.contact = ci;
    sup.link = robot_->spots()[c.spot].link;
    const Eigen::Isometry3d T = contactFrame(s, c.placement);
    const ConvexPolygon polygon = robot_->spots()[c.spot].polygon.inset(
        opt_.support_inset, opt_.support_inset_y >= 0 ? opt_.support_inset_y : opt_.support_inset);
    for (const auto& v : polygon.vertices()) sup.corners.push_back(T * Eigen::Vector3d(v.x(), v.y(), 0));
    const Eigen::Matrix3d R = s.frame.linear();
    const double mu = opt_.friction_share * s.friction;
    for (int m = 0; m < opt_.pyramid_sides; ++m) {
      const double phi = 2 * M_PI * m / opt_.pyramid_sides;
      sup.generators.push_back((R.col(2) + mu * (std::cos(phi) * R.col(0) + std::sin(phi) * R.col(1))).normalized());
    }
    sup.lambda0 = nx;
    nx += static_cast<int>(sup.corners.size() * sup.generators.size());
    supports_.push_back(sup);
  }
  if (supports_.empty()) throw std::invalid_argument("no supporting contact: the robot cannot stand still");
  n_lambda_ = nx - x_lambda_;
  nx_ = nx;

  // Collision pairs near the initial guess, except a contacting body on its surface's obstacle.
  kin_.setConfiguration(req_.initial_guess);
  if (req_.floating)
    for (const auto& v : robot_->spots()[req_.floating->spot].polygon.vertices())
      floating_footprint_.push_back(req_.floating->footprint_turned ? Eigen::Vector2d(-v) : v);
  std::vector<int> near = collision_->pairsWithin(kin_, opt_.collision_cutoff);
  addCollisionPairs(near);
}

void PostureProblem::addCollisionPairs(const std::vector<int>& pairs) {
  std::set<int> have(pairs_.begin(), pairs_.end());
  for (int p : pairs) {
    const CollisionPair& cp = collision_->pairs()[p];
    bool allowed = false;
    for (const auto& [link, obstacle] : allowed_touch_)
      allowed = allowed || (cp.kind == CollisionPair::Kind::RobotEnvironment && cp.link_a == link && cp.obstacle == obstacle);
    if (!allowed && have.insert(p).second) pairs_.push_back(p);
  }
  layout();
}

void PostureProblem::layout() {
  const int n_contacts = numContacts();
  row_floating_ = 6 * n_contacts;
  n_float_rows_ = 0;
  if (req_.floating) {
    const auto& f = *req_.floating;
    n_float_rows_ = static_cast<int>(f.volume.polygon.size() +
                                     robot_->spots()[f.spot].polygon.size() * scene_->surfaces()[f.surface].polygon.size());
  }
  row_statics_ = row_floating_ + n_float_rows_;
  row_collision_ = row_statics_ + nq_;
  ng_ = row_collision_ + static_cast<int>(pairs_.size());

  // Sparsity by structure: which variables each row can depend on.
  structure_.clear();
  auto linkCols = [&](int link, std::vector<bool>& mask) {
    for (int k = 0; k < 6; ++k) mask[k] = true;
    for (int j : robot_->ancestorJoints(link)) mask[6 + j] = true;
  };
  auto emit = [&](int row, const std::vector<bool>& mask) {
    for (int c = 0; c < nx_; ++c)
      if (mask[c]) structure_.push_back({row, c});
  };
  for (int ci = 0; ci < n_contacts; ++ci) {
    const bool floating = req_.floating && ci == static_cast<int>(req_.contacts.size());
    std::vector<bool> mask(nx_, false);
    linkCols(robot_->spots()[spotOf(ci)].link, mask);
    if (floating)
      for (int k = 0; k < 3; ++k) mask[x_float_ + k] = true;
    for (int r = 0; r < 6; ++r) emit(6 * ci + r, mask);
  }
  for (int r = 0; r < n_float_rows_; ++r) {
    std::vector<bool> mask(nx_, false);
    for (int k = 0; k < 3; ++k) mask[x_float_ + k] = true;
    emit(row_floating_ + r, mask);
  }
  {
    std::vector<bool> lam(nx_, false), all(nx_, false);
    for (int c = x_lambda_; c < nx_; ++c) lam[c] = all[c] = true;
    for (int c = 0; c < nq_; ++c) all[c] = true;
    for (int r = 0; r < 3; ++r) emit(row_statics_ + r, lam);
    for (int r = 3; r < 6; ++r) emit(row_statics_ + r, all);
    for (const auto& j : robot_->joints()) {
      std::vector<bool> mask(nx_, false);
      for (int k = 0; k < 6; ++k) mask[k] = true;
      for (const auto& i : robot_->joints())
        if (robot_->jointMovesLink(i.index, j.child_link) || robot_->jointMovesLink(j.index, i.child_link))
          mask[6 + i.index] = true;
      for (const auto& s : supports_)
        if (robot_->jointMovesLink(j.index, s.link))
          for (int c = 0; c < static_cast<int>(s.corners.size() * s.generators.size()); ++c) mask[s.lambda0 + c] = true;
      emit(row_statics_ + 6 + j.index, mask);
    }
  }
  for (std::size_t k = 0; k < pairs_.size(); ++k) {
    const CollisionPair& p = collision_->pairs()[pairs_[k]];
    std::vector<bool> mask(nx_, false);
    linkCols(p.link_a, mask);
    if (p.kind == CollisionPair::Kind::Self) linkCols(p.link_b, mask);
    emit(row_collision_ + static_cast<int>(k), mask);
  }
  hstructure_.clear();
  for (int r = 0; r < x_lambda_; ++r)  // configuration and floating variables
    for (int c = 0; c <= r; ++c) hstructure_.push_back({r, c});
  for (int r = x_lambda_; r < nx_; ++r) {
    for (int c = 0; c < nq_; ++c) hstructure_.push_back({r, c});
    hstructure_.push_back({r, r});
  }
  valid_ = false;
}

void PostureProblem::bounds(Eigen::VectorXd& xl, Eigen::VectorXd& xu, Eigen::VectorXd& gl, Eigen::VectorXd& gu) const {
  xl = Eigen::VectorXd::Constant(nx_, -kInf);
  xu = Eigen::VectorXd::Constant(nx_, kInf);
  const Configuration& q0 = req_.initial_guess;
  for (const auto& j : robot_->joints()) {
    xl[6 + j.index] = j.lower - q0.joints[j.index];
    xu[6 + j.index] = j.upper - q0.joints[j.index];
  }
  if (req_.floating) {
    xl[x_float_ + 2] = req_.floating->volume.theta_min;
    xu[x_float_ + 2] = req_.floating->volume.theta_max;
  }
  for (int c = x_lambda_; c < nx_; ++c) xl[c] = minCoefficient();

  gl = Eigen::VectorXd::Zero(ng_);
  gu = Eigen::VectorXd::Zero(ng_);
  if (req_.floating) {
    const auto& f = *req_.floating;
    std::vector<Eigen::Vector2d> n;
    std::vector<double> b;
    halfPlanes(f.volume.polygon, n, b);
    int r = row_floating_;
    for (double bi : b) gl[r] = -kInf, gu[r++] = bi;
    n.clear(), b.clear();
    halfPlanes(scene_->surfaces()[f.surface].polygon, n, b);
    for (std::size_t k = 0; k < robot_->spots()[f.spot].polygon.size(); ++k)
      for (double bi : b) gl[r] = -kInf, gu[r++] = bi - kFloatingPolygonMargin;
  }
  if (req_.pose_target) {
    const PoseTarget& t = *req_.pose_target;
    const int r = 6 * (numContacts() - 1);  // the pose target's rows come last among the contacts'
    for (int k = 0; k < 3; ++k) gl[r + k] = -t.position_tolerance[k], gu[r + k] = t.position_tolerance[k];
    for (int k = 3; k < 6; ++k) gl[r + k] = -t.orientation_tolerance, gu[r + k] = t.orientation_tolerance;
  }
  for (const auto& j : robot_->joints()) {
    const double W = robot_->totalMass() * 9.81;  // statics rows are in units of the weight
    gl[row_statics_ + 6 + j.index] = -opt_.torque_share * j.effort / W;
    gu[row_statics_ + 6 + j.index] = opt_.torque_share * j.effort / W;
  }
  for (std::size_t k = 0; k < pairs_.size(); ++k) {
    const CollisionPair& cp = collision_->pairs()[pairs_[k]];
    bool near = false;
    for (const auto& [link, obstacle] : near_touch_)
      near = near || (cp.kind == CollisionPair::Kind::RobotEnvironment && cp.link_a == link && cp.obstacle == obstacle);
    gl[row_collision_ + k] = near ? req_.pose_target->touch_margin : opt_.collision_margin;
    gu[row_collision_ + k] = kInf;
  }
}

Eigen::VectorXd PostureProblem::initialPoint() const {
  Eigen::VectorXd x = Eigen::VectorXd::Zero(nx_);
  Eigen::VectorXd xl, xu, gl, gu;
  bounds(xl, xu, gl, gu);
  x = x.cwiseMax(xl).cwiseMin(xu);  // a guess outside the joint limits starts on them
  if (req_.floating) {
    const auto& v = req_.floating->volume;
    const Eigen::Vector2d c = v.polygon.centroid();
    x[x_float_] = c.x();
    x[x_float_ + 1] = c.y();
    // Start at angle 0 (modulo 2 pi) when the interval holds it, else at its middle.
    const double zero = v.theta_min + std::fmod(std::fmod(-v.theta_min, 2 * M_PI) + 2 * M_PI, 2 * M_PI);
    x[x_float_ + 2] = zero <= v.theta_max ? zero : 0.5 * (v.theta_min + v.theta_max);
  }
  // Forces: the least-squares balance of the weight at the initial guess
  // (force and moment rows), kept non-negative.
  if (n_lambda_ > 0) {
    Kinematics k(robot_);
    k.setConfiguration(req_.initial_guess);
    const double M = robot_->totalMass();
    Eigen::MatrixXd A = Eigen::MatrixXd::Zero(6, n_lambda_);
    for (const auto& s : supports_)
      for (std::size_t c = 0; c < s.corners.size(); ++c)
        for (std::size_t m = 0; m < s.generators.size(); ++m) {
          const int col = s.lambda0 + static_cast<int>(c * s.generators.size() + m) - x_lambda_;
          A.block<3, 1>(0, col) = s.generators[m];
          A.block<3, 1>(3, col) = s.corners[c].cross(s.generators[m]);
        }
    Eigen::VectorXd b(6);
    b.head<3>() = Eigen::Vector3d(0, 0, 1);  // in units of the weight
    b.tail<3>() = k.centerOfMass().cross(Eigen::Vector3d(0, 0, 1));
    (void)M;
    const Eigen::MatrixXd AtA = A.transpose() * A + 1e-3 * Eigen::MatrixXd::Identity(n_lambda_, n_lambda_);
    Eigen::VectorXd lam = AtA.ldlt().solve(A.transpose() * b);
    // a few projected gradient steps toward the non-negative least-squares solution
    const double step = 1.0 / AtA.norm();
    for (int it = 0; it < 200; ++it) lam = (lam - step * (AtA * lam - A.transpose() * b)).cwiseMax(0.0);
    x.segment(x_lambda_, n_lambda_) = lam.cwiseMax(minCoefficient());
  }
  return x;
}

Eigen::VectorXd PostureProblem::hessianDiagonal() const {
  Eigen::VectorXd d = Eigen::VectorXd::Constant(nx_, 1e-6);
  d.head(nq_) = req_.cost->diagonalHessian(nq_);
  if (x_float_ >= 0) d.segment<3>(x_float_).setConstant(1e-3);
  d.segment(x_lambda_, n_lambda_).setConstant(2 * opt_.force_regularization);
  return d;
}

namespace {

// A rotational degree of freedom moving a link: the base rotation about the
// base origin (three, "base" true) or a joint, in chain order.
struct Dof {
  int col;
  Eigen::Vector3d axis, origin;
  bool base;
};

// d^n p / dq_1 .. dq_n for a point p moving with the link, the dofs given in
// chain order: a_1 x (a_2 x ( ... (a_n x (p - o_n)))). Base rotations do not
// form a chain: their orderings are averaged.
Eigen::Vector3d nested(std::vector<const Dof*> d, const Eigen::Vector3d& p) {
  auto chain = [&](const std::vector<const Dof*>& s) {
    Eigen::Vector3d v = s.back()->axis.cross(p - s.back()->origin);
    for (int i = static_cast<int>(s.size()) - 2; i >= 0; --i) v = s[i]->axis.cross(v);
    return v;
  };
  int nb = 0;
  while (nb < static_cast<int>(d.size()) && d[nb]->base) ++nb;
  if (nb < 2) return chain(d);
  std::sort(d.begin(), d.begin() + nb);
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int count = 0;
  do {
    sum += chain(d);
    ++count;
  } while (std::next_permutation(d.begin(), d.begin() + nb));
  return sum / count;
}

}  // namespace

Eigen::MatrixXd PostureProblem::lagrangianHessian(const Eigen::VectorXd& x, double sigma, const Eigen::VectorXd& y) {
  evaluate(x);  // kinematics at x
  const RobotModel& m = *robot_;
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(nx_, nx_);
  H.diagonal() = sigma * hessianDiagonal();
  const Eigen::Vector3d pb = kin_.linkPose(0).translation();
  auto dofsOf = [&](int link) {
    std::vector<Dof> d;
    for (int k = 0; k < 3; ++k) d.push_back({3 + k, Eigen::Vector3d::Unit(k), pb, true});
    for (int j : m.ancestorJoints(link)) d.push_back({6 + j, kin_.jointAxis(j), kin_.jointOrigin(j), false});
    return d;
  };
  // v . d2p/dqi dqj for a point p on a link (or, with is_axis, a direction u on it).
  auto addSecond = [&](int link, const Eigen::Vector3d& p, bool is_axis, const Eigen::Vector3d& v) {
    std::vector<Dof> d = dofsOf(link);
    if (is_axis)
      for (auto& e : d) e.origin.setZero();  // a direction turns about any point alike
    for (std::size_t j = 0; j < d.size(); ++j)
      for (std::size_t i = 0; i <= j; ++i) {
        const double h = v.dot(nested({&d[i], &d[j]}, p));
        H(d[j].col, d[i].col) += h;
        if (i != j) H(d[i].col, d[j].col) += h;
      }
  };

  // Contact rows.
  for (int ci = 0; ci < numContacts(); ++ci) {
    const ContactGeometry cg = contactGeometry(ci, x);
    const bool floating = cg.floating;
    const int link = cg.link;
    const Eigen::Isometry3d& Ts = cg.spot;
    const Eigen::Isometry3d& T = cg.target;
    const int r = 6 * ci;
    const Eigen::Vector3d zs = Ts.linear().col(2), xs = Ts.linear().col(0);
    const Eigen::Vector3d xt = T.linear().col(0), yt = T.linear().col(1);
    const bool target = req_.pose_target && ci == numContacts() - 1;  // its offset rows are in its own frame
    addSecond(link, Ts.translation(), false,
              target ? Eigen::Vector3d(T.linear() * y.segment<3>(r)) : Eigen::Vector3d(y.segment<3>(r)));
    addSecond(link, zs, true, y[r + 3] * xt + y[r + 4] * yt);
    addSecond(link, xs, true, y[r + 5] * yt);
    if (floating) {
      const int th = x_float_ + 2;
      H(th, th) += -y[r + 3] * zs.dot(xt) - y[r + 4] * zs.dot(yt) - y[r + 5] * xs.dot(yt);
      Eigen::VectorXd g = Eigen::VectorXd::Zero(nq_);
      kin_.addAxisGradient(link, zs, y[r + 3] * yt - y[r + 4] * xt, g);
      kin_.addAxisGradient(link, xs, -y[r + 5] * xt, g);
      H.block(th, 0, 1, nq_) += g.transpose();
      H.block(0, th, nq_, 1) += g;
    }
  }
  if (req_.floating) {
    const auto& f = *req_.floating;
    std::vector<Eigen::Vector2d> n;
    std::vector<double> b;
    halfPlanes(scene_->surfaces()[f.surface].polygon, n, b);
    const Eigen::Matrix2d R = Eigen::Rotation2Dd(x[x_float_ + 2]).toRotationMatrix();
    int r = row_floating_ + static_cast<int>(f.volume.polygon.size());
    for (const auto& c : floating_footprint_)
      for (const auto& ne : n) H(x_float_ + 2, x_float_ + 2) += -y[r++] * ne.dot(R * c);
  }

  // Statics rows (in weights; forces W lambda g).
  const double M = m.totalMass(), W = M * 9.81;
  const Eigen::Vector3d gvec(0, 0, -9.81), G = M * gvec;
  const Eigen::Vector3d ym = y.segment<3>(row_statics_ + 3);
  for (const auto& l : m.links()) {
    const Eigen::Vector3d cl = kin_.linkPose(l.index) * l.com;
    // moment rows: -(c x G) / W, c = sum m_l c_l / M
    addSecond(l.index, cl, false, -(l.mass / (M * W)) * G.cross(ym));
    // torque rows, gravity: -(m_l g / W) . d3 c_l / dqa dqb dqj
    const std::vector<Dof> d = dofsOf(l.index);
    const Eigen::Vector3d w = -(l.mass / W) * gvec;
    for (std::size_t jj = 3; jj < d.size(); ++jj) {
      const double yj = y[row_statics_ + d[jj].col];
      if (yj == 0) continue;
      for (std::size_t b = 0; b < d.size(); ++b)
        for (std::size_t a = 0; a <= b; ++a) {
          std::vector<const Dof*> s = {&d[a], &d[b], &d[jj]};
          std::sort(s.begin(), s.end(), [&](const Dof* p, const Dof* q) { return p - d.data() < q - d.data(); });
          const double h = yj * w.dot(nested(s, cl));
          H(d[b].col, d[a].col) += h;
          if (a != b) H(d[a].col, d[b].col) += h;
        }
    }
  }
  // torque rows, contact forces at fixed world points: -(f / W) . d2[a_j x (p - o_j)]
  for (const auto& s : supports_) {
    const int ng = static_cast<int>(s.generators.size());
    const std::vector<Dof> d = dofsOf(s.link);
    for (std::size_t k = 0; k < s.corners.size(); ++k) {
      Eigen::Vector3d f = Eigen::Vector3d::Zero();
      for (int mm = 0; mm < ng; ++mm) f += x[s.lambda0 + k * ng + mm] * s.generators[mm];  // / W already
      const Eigen::Vector3d& p = s.corners[k];
      for (std::size_t jj = 3; jj < d.size(); ++jj) {
        const double yj = y[row_statics_ + d[jj].col];
        if (yj == 0) continue;
        const Eigen::Vector3d& a = d[jj].axis;
        const Eigen::Vector3d& o = d[jj].origin;
        // derivatives of a_j and o_j under the dofs above j, and translation
        auto da = [&](std::size_t i) { return Eigen::Vector3d(d[i].axis.cross(a)); };
        auto dO = [&](std::size_t i) { return Eigen::Vector3d(d[i].axis.cross(o - d[i].origin)); };
        for (std::size_t h = 0; h < jj; ++h) {
          for (std::size_t i = 0; i <= h; ++i) {
            const Eigen::Vector3d d2a = nested({&d[i], &d[h]}, a + d[h].origin) ;  // a_i x (a_h x a)
            const Eigen::Vector3d d2o = nested({&d[i], &d[h]}, o);
            const Eigen::Vector3d v = d2a.cross(p - o) - da(i).cross(dO(h)) - da(h).cross(dO(i)) - a.cross(d2o);
            const double val = -yj * f.dot(v);
            H(d[h].col, d[i].col) += val;
            if (i != h) H(d[i].col, d[h].col) += val;
          }
          // translation t: d o_j = e_t; d2/dt dq_h = -(d a_j / dq_h) x e_t
          for (int t3 = 0; t3 < 3; ++t3) {
            const double val = -yj * f.dot(-da(h).cross(Eigen::Vector3d::Unit(t3)));
            H(d[h].col, t3) += val;
            H(t3, d[h].col) += val;
          }
        }
        // force coupling: d/dlambda of the torque row's configuration derivatives
        for (int mm = 0; mm < ng; ++mm) {
          const int col = s.lambda0 + static_cast<int>(k) * ng + mm;
          const Eigen::Vector3d& g = s.generators[mm];
          const Eigen::Vector3d arm = (p - o).cross(g);
          for (int c = 0; c < 3; ++c) H(col, c) += yj * g.cross(a)[c];
          for (std::size_t i = 0; i < jj; ++i)
            H(col, d[i].col) += -yj * (da(i).dot(arm) - a.dot(dO(i).cross(g)));
        }
      }
    }
  }
  for (int r = x_lambda_; r < nx_; ++r) H.block(0, r, nq_, 1) = H.block(r, 0, 1, nq_).transpose();

  // Base rotation vector: first-order chain rule (J_l), as for the Jacobian.
  const Eigen::Matrix3d Jl = leftJacobian(x.segment<3>(3));
  H.middleCols(3, 3) = H.middleCols(3, 3) * Jl;
  H.middleRows(3, 3) = Jl.transpose() * H.middleRows(3, 3);
  return H;
}

void PostureProblem::hessianValues(const Eigen::VectorXd& x, double sigma, const Eigen::VectorXd& y, double* values) {
  const Eigen::MatrixXd H = lagrangianHessian(x, sigma, y);
  for (std::size_t k = 0; k < hstructure_.size(); ++k) values[k] = H(hstructure_[k].first, hstructure_[k].second);
}

Configuration PostureProblem::configurationAt(const Eigen::VectorXd& x) const {
  const Configuration& q0 = req_.initial_guess;
  Configuration q = q0;
  q.base_position = q0.base_position + x.segment<3>(0);
  q.base_orientation = Eigen::Quaterniond(expSO3(x.segment<3>(3)) * q0.base_orientation.toRotationMatrix());
  q.joints = q0.joints + x.segment(6, robot_->numJoints());
  return q;
}

SurfacePlacement PostureProblem::floatingAt(const Eigen::VectorXd& x) const {
  SurfacePlacement p;
  if (req_.floating) p.x = x[x_float_], p.y = x[x_float_ + 1], p.theta = x[x_float_ + 2];
  return p;
}

std::vector<PostureProblem::ContactForces> PostureProblem::forcesAt(const Eigen::VectorXd& x) const {
  std::vector<ContactForces> out;
  for (const auto& s : supports_) {
    ContactForces cf;
    cf.contact = s.contact;
    cf.points = s.corners;
    for (std::size_t k = 0; k < s.corners.size(); ++k) {
      Eigen::Vector3d f = Eigen::Vector3d::Zero();
      for (std::size_t m = 0; m < s.generators.size(); ++m)
        f += x[s.lambda0 + k * s.generators.size() + m] * s.generators[m];
      cf.forces.push_back(robot_->totalMass() * 9.81 * f);
    }
    out.push_back(cf);
  }
  return out;
}

int PostureProblem::spotOf(int ci) const {
  const int nc = static_cast<int>(req_.contacts.size());
  if (ci < nc) return req_.contacts[ci].spot;
  if (req_.floating && ci == nc) return req_.floating->spot;
  return req_.pose_target->spot;
}

PostureProblem::ContactGeometry PostureProblem::contactGeometry(int ci, const Eigen::VectorXd& x) const {
  const int nc = static_cast<int>(req_.contacts.size());
  const int spot = spotOf(ci);
  if (ci >= nc + (req_.floating ? 1 : 0))  // the pose target: a world frame, no surface
    return {false, robot_->spots()[spot].link, kin_.spotPose(spot), req_.pose_target->pose};
  const bool floating = ci == nc;
  const Surface& surf = scene_->surfaces()[floating ? req_.floating->surface : req_.contacts[ci].surface];
  const SurfacePlacement pl = floating ? floatingAt(x) : req_.contacts[ci].placement;
  return {floating, robot_->spots()[spot].link, kin_.spotPose(spot), contactFrame(surf, pl)};
}

Eigen::Matrix3d PostureProblem::leftJacobian(const Eigen::Vector3d& w) const {
  // d/de exp(w + e v) = [J_l(w) v]x exp(w): maps rotation-vector steps to world rotations.
  const double th = w.norm();
  const Eigen::Matrix3d W = skew(w);
  if (th < 1e-6) return Eigen::Matrix3d::Identity() + 0.5 * W + W * W / 6.0;
  return Eigen::Matrix3d::Identity() + (1 - std::cos(th)) / (th * th) * W + (th - std::sin(th)) / (th * th * th) * W * W;
}

void PostureProblem::evaluate(const Eigen::VectorXd& x) {
  if (valid_ && x.size() == x_cached_.size() && x == x_cached_) return;
  const Configuration q = configurationAt(x);
  kin_.setConfiguration(q);
  const RobotModel& m = *robot_;
  g_ = Eigen::VectorXd::Zero(ng_);
  jac_ = Eigen::MatrixXd::Zero(ng_, nx_);
  Eigen::VectorXd row(nq_);

  // Cost.
  grad_f_ = Eigen::VectorXd::Zero(nx_);
  Eigen::VectorXd gq = Eigen::VectorXd::Zero(nq_);
  f_ = req_.cost->evaluate(kin_, gq);
  grad_f_.head(nq_) = gq;
  const Eigen::VectorXd lam = x.segment(x_lambda_, n_lambda_);
  f_ += opt_.force_regularization * lam.squaredNorm();
  grad_f_.segment(x_lambda_, n_lambda_) = 2 * opt_.force_regularization * lam;

  // Contacts.
  for (int ci = 0; ci < numContacts(); ++ci) {
    const ContactGeometry cg = contactGeometry(ci, x);
    const bool floating = cg.floating;
    const int link = cg.link;
    const Eigen::Isometry3d& Ts = cg.spot;
    const Eigen::Isometry3d& T = cg.target;
    const int r = 6 * ci;
    if (req_.pose_target && ci == numContacts() - 1) {
      // The pose target's offset in its own frame, so that it can be bounded along and across a normal.
      g_.segment<3>(r) = T.linear().transpose() * (Ts.translation() - T.translation());
      jac_.block(r, 0, 3, nq_) = T.linear().transpose() * kin_.chainPointJacobian(link, Ts.translation());
    } else {
      g_.segment<3>(r) = Ts.translation() - T.translation();
      jac_.block(r, 0, 3, nq_) = kin_.chainPointJacobian(link, Ts.translation());
    }
    const Eigen::Vector3d zs = Ts.linear().col(2), xs = Ts.linear().col(0);
    const Eigen::Vector3d xt = T.linear().col(0), yt = T.linear().col(1);
    const std::pair<Eigen::Vector3d, Eigen::Vector3d> axes[3] = {{zs, xt}, {zs, yt}, {xs, yt}};
    for (int k = 0; k < 3; ++k) {
      g_[r + 3 + k] = axes[k].first.dot(axes[k].second);
      row.setZero();
      kin_.addAxisGradient(link, axes[k].first, axes[k].second, row);
      jac_.block(r + 3 + k, 0, 1, nq_) = row.transpose();
    }
    if (floating) {
      const Eigen::Matrix3d SR = scene_->surfaces()[req_.floating->surface].frame.linear();
      jac_.block(r, x_float_, 3, 1) = -SR.col(0);
      jac_.block(r, x_float_ + 1, 3, 1) = -SR.col(1);
      // d x_t / d theta = y_t, d y_t / d theta = -x_t
      jac_(r + 3, x_float_ + 2) = zs.dot(yt);
      jac_(r + 4, x_float_ + 2) = -zs.dot(xt);
      jac_(r + 5, x_float_ + 2) = -xs.dot(xt);
    }
  }

  // Floating contact inside its search volume, and its spot polygon on the surface.
  if (req_.floating) {
    const auto& f = *req_.floating;
    const Eigen::Vector2d p(x[x_float_], x[x_float_ + 1]);
    const double th = x[x_float_ + 2];
    std::vector<Eigen::Vector2d> n;
    std::vector<double> b;
    halfPlanes(f.volume.polygon, n, b);
    int r = row_floating_;
    for (const auto& ne : n) {
      g_[r] = ne.dot(p);
      jac_(r, x_float_) = ne.x();
      jac_(r, x_float_ + 1) = ne.y();
      ++r;
    }
    n.clear(), b.clear();
    halfPlanes(scene_->surfaces()[f.surface].polygon, n, b);
    const Eigen::Matrix2d R = Eigen::Rotation2Dd(th).toRotationMatrix();
    Eigen::Matrix2d dR;
    dR << -std::sin(th), -std::cos(th), std::cos(th), -std::sin(th);
    for (const auto& c : floating_footprint_)
      for (const auto& ne : n) {
        g_[r] = ne.dot(p + R * c);
        jac_(r, x_float_) = ne.x();
        jac_(r, x_float_ + 1) = ne.y();
        jac_(r, x_float_ + 2) = ne.dot(dR * c);
        ++r;
      }
  }

  // Statics: h = g(q) - sum J^T f, forces applied at the supporting contacts'
  // target corners (constant points: they coincide with the spot's corners
  // when the contact rows hold).
  {
    // Forces are W lambda g (lambda in units of the body weight W) and the rows
    // are divided by W: every statics row and variable is of order one.
    const int r0 = row_statics_;
    const double M = m.totalMass();
    const double W = M * 9.81;
    const Eigen::Vector3d G = M * kGravity;
    std::vector<Eigen::Vector3d> S(m.numJoints(), Eigen::Vector3d::Zero());  // subtree sum m_l c_l
    Eigen::Vector3d Sc = Eigen::Vector3d::Zero();
    for (const auto& l : m.links()) {
      const Eigen::Vector3d cl = kin_.linkPose(l.index) * l.com;
      Sc += l.mass * cl;
      for (int j : m.ancestorJoints(l.index)) S[j] += l.mass * cl;
    }
    const Eigen::Vector3d c = Sc / M;
    const Eigen::Vector3d pb = kin_.linkPose(0).translation();
    std::vector<Eigen::Vector3d> C(m.numJoints());
    for (const auto& j : m.joints()) C[j.index] = S[j.index] / m.subtreeMass(j.index);

    // Forces at corners; per joint: F_j (sum of forces below j), Q_j (their moment about o_j).
    std::vector<Eigen::Vector3d> F(m.numJoints(), Eigen::Vector3d::Zero()), Q(m.numJoints(), Eigen::Vector3d::Zero());
    Eigen::Vector3d Ftot = Eigen::Vector3d::Zero(), Mtot = Eigen::Vector3d::Zero();
    for (const auto& s : supports_) {
      const int ng = static_cast<int>(s.generators.size());
      for (std::size_t k = 0; k < s.corners.size(); ++k) {
        Eigen::Vector3d f = Eigen::Vector3d::Zero();
        for (int mm = 0; mm < ng; ++mm) f += W * x[s.lambda0 + k * ng + mm] * s.generators[mm];
        Ftot += f;
        Mtot += s.corners[k].cross(f);
        for (int j : m.ancestorJoints(s.link)) {
          F[j] += f;
          Q[j] += (s.corners[k] - kin_.jointOrigin(j)).cross(f);
        }
        for (int mm = 0; mm < ng; ++mm) {
          const int col = s.lambda0 + static_cast<int>(k) * ng + mm;
          const Eigen::Vector3d& gm = s.generators[mm];
          jac_.block(r0, col, 3, 1) = -gm;
          jac_.block(r0 + 3, col, 3, 1) = -s.corners[k].cross(gm);
          for (int j : m.ancestorJoints(s.link))
            jac_(r0 + 6 + j, col) = -kin_.jointAxis(j).dot((s.corners[k] - kin_.jointOrigin(j)).cross(gm));
        }
      }
    }
    g_.segment<3>(r0) = (-G - Ftot) / W;
    g_.segment<3>(r0 + 3) = (-c.cross(G) - Mtot) / W;
    // d(-(c x G)) = G x dc, with the centre of mass Jacobian from the chain.
    Eigen::MatrixXd Jc = Eigen::MatrixXd::Zero(3, nq_);
    Jc.block<3, 3>(0, 0).setIdentity();
    Jc.block<3, 3>(0, 3) = -skew(c - pb);
    for (const auto& j : m.joints())
      Jc.col(6 + j.index) = m.subtreeMass(j.index) / M *
                            kin_.jointAxis(j.index).cross(C[j.index] - kin_.jointOrigin(j.index));
    jac_.block(r0 + 3, 0, 3, nq_) = skew(G) * Jc / W;

    for (const auto& j : m.joints()) {
      const int jj = j.index;
      const Eigen::Vector3d& a = kin_.jointAxis(jj);
      const Eigen::Vector3d& o = kin_.jointOrigin(jj);
      const double Mj = m.subtreeMass(jj);
      const Eigen::Vector3d mj = (C[jj] - o).cross(Mj * kGravity) + Q[jj];
      const int r = r0 + 6 + jj;
      g_[r] = -a.dot(mj) / W;
      // Base translation: o_j and C_j move together, the corners stay.
      jac_.block(r, 0, 1, 3) = F[jj].cross(a).transpose() / W;
      // A rotation omega about a point o_i above joint j (base rotation or ancestor joint).
      auto above = [&](const Eigen::Vector3d& w, const Eigen::Vector3d& oi) {
        const Eigen::Vector3d da = w.cross(a);
        const Eigen::Vector3d dO = w.cross(o - oi);
        const Eigen::Vector3d dm = (w.cross(C[jj] - o)).cross(Mj * kGravity) - dO.cross(F[jj]);
        return -(da.dot(mj) + a.dot(dm));
      };
      for (int k = 0; k < 3; ++k) jac_(r, 3 + k) = above(Eigen::Vector3d::Unit(k), pb) / W;
      for (const auto& i : m.joints()) {
        const int ii = i.index;
        if (ii != jj && m.jointMovesLink(ii, j.child_link)) {
          jac_(r, 6 + ii) = above(kin_.jointAxis(ii), kin_.jointOrigin(ii)) / W;
        } else if (m.jointMovesLink(jj, i.child_link)) {
          // joint j itself or below it: only the subtree's centre of mass moves
          const Eigen::Vector3d dm =
              (m.subtreeMass(ii) * kin_.jointAxis(ii).cross(C[ii] - kin_.jointOrigin(ii))).cross(kGravity);
          jac_(r, 6 + ii) = -a.dot(dm) / W;
        }
      }
    }
  }

  // Collisions.
  for (std::size_t k = 0; k < pairs_.size(); ++k) {
    const PairDistance d = collision_->pairDistance(kin_, pairs_[k], true);
    g_[row_collision_ + k] = d.distance;
    jac_.block(row_collision_ + k, 0, 1, nq_) = d.gradient.transpose();
  }

  // Chain rule for the base rotation vector: tangent rotation = J_l(w) dw.
  const Eigen::Matrix3d Jl = leftJacobian(x.segment<3>(3));
  jac_.middleCols(3, 3) = jac_.middleCols(3, 3) * Jl;
  grad_f_.segment<3>(3) = Jl.transpose() * grad_f_.segment<3>(3);

  x_cached_ = x;
  valid_ = true;
}

double PostureProblem::cost(const Eigen::VectorXd& x) {
  evaluate(x);
  return f_;
}
Eigen::VectorXd PostureProblem::costGradient(const Eigen::VectorXd& x) {
  evaluate(x);
  return grad_f_;
}
Eigen::VectorXd PostureProblem::constraints(const Eigen::VectorXd& x) {
  evaluate(x);
  return g_;
}
const Eigen::MatrixXd& PostureProblem::constraintJacobian(const Eigen::VectorXd& x) {
  evaluate(x);
  return jac_;
}
void PostureProblem::jacobianValues(const Eigen::VectorXd& x, double* values) {
  evaluate(x);
  for (std::size_t k = 0; k < structure_.size(); ++k) values[k] = jac_(structure_[k].first, structure_[k].second);
}

}  // namespace acyclic
