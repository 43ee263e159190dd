#include "hrp2_bridge/sim/feet_stabilizer.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include <Eigen/Dense>

#include "hrp2_bridge/stabilizer_schedule.h"

namespace acyclic::hrp2 {

void FeetStabilizerOptions::validate() const {
  auto positive = [](double v, const char* name) {
    if (!(v > 0) || !std::isfinite(v))
      throw std::invalid_argument(std::string("stabilizer ") + name + " must be positive (got " + std::to_string(v) + ")");
  };
  auto nonNegative = [](double v, const char* name) {
    if (!(v >= 0) || !std::isfinite(v))
      throw std::invalid_argument(std::string("stabilizer ") + name + " must be >= 0 (got " + std::to_string(v) + ")");
  };
  nonNegative(zmp_com_gain, "zmp_com_gain");
  nonNegative(zmp_velocity_gain, "zmp_velocity_gain");
  nonNegative(cop_gain, "cop_gain");
  positive(cop_leak, "cop_leak");
  nonNegative(max_tilt, "max_tilt");
  positive(force_damping, "force_damping");
  positive(force_leak, "force_leak");
  nonNegative(max_lift, "max_lift");
  nonNegative(cop_edge, "cop_edge");
  positive(off_time, "off_time");
  positive(place_time, "place_time");
  nonNegative(max_place, "max_place");
  nonNegative(max_place_turn, "max_place_turn");
  positive(place_leak, "place_leak");
}

FeetStabilizer::FeetStabilizer(std::shared_ptr<const RobotModel> robot, std::shared_ptr<const Scene> scene,
                               const FeetStabilizerOptions& options)
    : robot_(std::move(robot)), scene_(std::move(scene)), opt_(options), kin_(robot_) {
  opt_.validate();
  const RobotModel& m = *robot_;
  lift_.assign(m.spots().size(), 0.0);
  tilt_.assign(m.spots().size(), Eigen::Vector2d::Zero());
  place_.assign(m.spots().size(), Eigen::Matrix<double, 6, 1>::Zero());
  want_load_.assign(m.spots().size(), 0.0);
  want_cop_.assign(m.spots().size(), Eigen::Vector2d::Zero());
  for (int s = 0; s < static_cast<int>(m.spots().size()); ++s) {
    if (!isFootSpot(m, s)) continue;
    std::vector<int> chain;
    for (int link = m.spots()[s].link; m.links()[link].parent_joint >= 0;) {
      const JointInfo& j = m.joints()[m.links()[link].parent_joint];
      chain.push_back(j.index);
      link = j.parent_link;
    }
    std::reverse(chain.begin(), chain.end());
    feet_.push_back(s);
    leg_.push_back(chain);
  }
}

namespace {

// x + dt * rate, clamped to [-bound, bound].
double step(double x, double rate, double dt, double bound) { return std::clamp(x + dt * rate, -bound, bound); }

// The point of a convex polygon nearest to p (p itself when inside).
Eigen::Vector2d nearestIn(const ConvexPolygon& poly, const Eigen::Vector2d& p) {
  return poly.contains(p) ? p : poly.nearestBoundaryPoint(p);
}

// The convex hull of points, counter-clockwise (Andrew's monotone chain).
std::vector<Eigen::Vector2d> hull(std::vector<Eigen::Vector2d> p) {
  std::sort(p.begin(), p.end(), [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
  });
  auto cross = [](const Eigen::Vector2d& o, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return (a - o).x() * (b - o).y() - (a - o).y() * (b - o).x();
  };
  std::vector<Eigen::Vector2d> h(2 * p.size());
  std::size_t k = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    while (k >= 2 && cross(h[k - 2], h[k - 1], p[i]) <= 0) --k;
    h[k++] = p[i];
  }
  for (std::size_t i = p.size() - 1, t = k + 1; i > 0; --i) {
    while (k >= t && cross(h[k - 2], h[k - 1], p[i - 1]) <= 0) --k;
    h[k++] = p[i - 1];
  }
  h.resize(k > 1 ? k - 1 : k);
  return h;
}

// Weights w >= 0 on the points p, summing to 1, with sum w_i p_i = z, of
// least norm (the load spread as evenly as the points allow): z is first
// moved into the points' hull, then an active-set iteration drops the most
// negative weight and solves again. Empty if it does not settle.
std::vector<double> spreadWeights(const std::vector<Eigen::Vector2d>& p, Eigen::Vector2d z) {
  const std::vector<Eigen::Vector2d> h = hull(p);
  if (h.size() < 3) return {};
  z = nearestIn(ConvexPolygon(h), z);
  const int n = static_cast<int>(p.size());
  std::vector<bool> active(n, true);
  for (int round = 0; round < n; ++round) {
    std::vector<int> idx;
    for (int i = 0; i < n; ++i)
      if (active[i]) idx.push_back(i);
    if (idx.size() < 3) return {};
    Eigen::MatrixXd A(3, idx.size());
    for (std::size_t j = 0; j < idx.size(); ++j) A.col(j) << 1.0, p[idx[j]].x(), p[idx[j]].y();
    const Eigen::Matrix3d AAt = A * A.transpose();
    Eigen::LDLT<Eigen::Matrix3d> ldlt(AAt);
    if (ldlt.info() != Eigen::Success || std::abs(AAt.determinant()) < 1e-15) return {};
    const Eigen::VectorXd w = A.transpose() * ldlt.solve(Eigen::Vector3d(1.0, z.x(), z.y()));
    int worst = -1;
    for (std::size_t j = 0; j < idx.size(); ++j)
      if (w[j] < -1e-12 && (worst < 0 || w[j] < w[worst])) worst = static_cast<int>(j);
    if (worst < 0) {
      std::vector<double> out(n, 0.0);
      for (std::size_t j = 0; j < idx.size(); ++j) out[idx[j]] = std::max(0.0, w[j]);
      return out;
    }
    active[idx[worst]] = false;
  }
  return {};
}

}  // namespace

Eigen::VectorXd FeetStabilizer::update(double dt, bool on, const Configuration& plan,
                                       const std::vector<ContactSpec>& contacts, const Eigen::Vector3d& com,
                                       const std::vector<SpotWrench>& wrenches,
                                       const std::optional<Eigen::Isometry3d>& waist) {
  const RobotModel& m = *robot_;
  kin_.setConfiguration(plan);
  const Eigen::Vector3d plan_com = kin_.centerOfMass();
  // Velocities by differences, the measured one smoothed over 20 ms (the
  // simulated state is exact, but a real estimate is not, and the contact
  // springs ring).
  if (has_last_) {
    const double a = std::min(1.0, dt / 0.02);
    const Eigen::Vector3d v = (com - last_com_) / dt - (plan_com - last_plan_com_) / dt;
    com_velocity_ = (1 - a) * com_velocity_ + a * v;
  }
  has_last_ = true;
  last_com_ = com;
  last_plan_com_ = plan_com;

  struct Foot {
    int spot;
    Eigen::Isometry3d pose;   // the planned spot frame (z into the foot)
    bool supporting;
    double force = 0;         // measured, along the normal
    double want = 0;
    Eigen::Vector2d cop = Eigen::Vector2d::Zero(), want_cop = Eigen::Vector2d::Zero();  // spot frame
    // Where the wanted centre of pressure was pulled from to keep it cop_edge
    // inside the sole (zero when it was not pulled), spot frame.
    Eigen::Vector2d pulled = Eigen::Vector2d::Zero();
  };
  std::vector<Foot> down;
  for (const ContactSpec& c : contacts)
    if (isFootSpot(m, c.spot)) down.push_back({c.spot, kin_.spotPose(c.spot), c.supporting});

  // The supporting soles whose frames are measured: their mean offset from
  // their planned places, and the first of them, which a swinging sole is
  // placed against.
  Eigen::Vector2d drift = Eigen::Vector2d::Zero();
  int measured = 0;
  const Foot* anchor = nullptr;
  for (const Foot& f : down)
    if (f.supporting && wrenches[f.spot].frame) {
      drift += (wrenches[f.spot].frame->translation() - f.pose.translation()).head<2>();
      ++measured;
      if (!anchor) anchor = &f;
    }
  if (measured > 0) drift /= measured;

  std::vector<bool> regulated(m.spots().size(), false);
  std::fill(want_load_.begin(), want_load_.end(), 0.0);
  if (on && !down.empty()) {
    zmp_ = plan_com.head<2>() + opt_.zmp_com_gain * (com.head<2>() - drift - plan_com.head<2>()) +
           opt_.zmp_velocity_gain * com_velocity_.head<2>();
    double total = 0;
    for (Foot& f : down) {
      const SpotWrench& w = wrenches[f.spot];
      const Eigen::Matrix3d R = f.pose.linear();
      const Eigen::Vector3d F = R.transpose() * w.force, M = R.transpose() * w.moment;
      f.force = std::max(F.z(), 0.0);
      if (F.z() > 1.0) f.cop = Eigen::Vector2d(-M.y() / F.z(), M.x() / F.z());
      total += f.force;
    }
    std::vector<Foot*> sup;
    for (Foot& f : down)
      if (f.supporting) sup.push_back(&f);
    // Where the wanted ZMP puts each supporting foot's load and centre of
    // pressure (world x-y), then in the foot's frame.
    auto wantAt = [&](Foot& f, double share, const Eigen::Vector2d& p) {
      f.want = share * total;
      const Eigen::Vector3d local = f.pose.inverse() * Eigen::Vector3d(p.x(), p.y(), f.pose.translation().z());
      f.want_cop = nearestIn(m.spots()[f.spot].polygon.inset(opt_.cop_edge), local.head<2>());
      f.pulled = local.head<2>() - f.want_cop;
    };
    if (sup.size() == 1) {
      wantAt(*sup[0], 1.0, zmp_);
    } else if (sup.size() >= 2) {
      // The wanted ZMP spread over the corners of the supporting soles
      // (shrunk by cop_edge) with weights of least norm: each sole's share is
      // its corners' weights, its centre of pressure their weighted mean. So
      // staggered feet share as the plan's statics do, the front sole not
      // left to hold a ZMP behind its heel alone.
      std::vector<Eigen::Vector2d> corners;
      std::vector<int> owner;
      for (std::size_t k = 0; k < sup.size(); ++k) {
        const ConvexPolygon shrunk = m.spots()[sup[k]->spot].polygon.inset(opt_.cop_edge);
        for (const Eigen::Vector2d& v : shrunk.vertices()) {
          corners.push_back((sup[k]->pose * Eigen::Vector3d(v.x(), v.y(), 0)).head<2>());
          owner.push_back(static_cast<int>(k));
        }
      }
      const std::vector<double> w = spreadWeights(corners, zmp_);
      if (!w.empty()) {
        // How far the wanted ZMP was pulled into the shrunk soles' hull.
        const Eigen::Vector2d pulled = zmp_ - nearestIn(ConvexPolygon(hull(corners)), zmp_);
        for (std::size_t k = 0; k < sup.size(); ++k) {
          double share = 0;
          Eigen::Vector2d at = Eigen::Vector2d::Zero();
          for (std::size_t i = 0; i < corners.size(); ++i)
            if (owner[i] == static_cast<int>(k)) share += w[i], at += w[i] * corners[i];
          wantAt(*sup[k], share, share > 1e-9 ? Eigen::Vector2d(at / share) : sup[k]->pose.translation().head<2>());
          sup[k]->pulled += (sup[k]->pose.linear().transpose() * Eigen::Vector3d(pulled.x(), pulled.y(), 0)).head<2>();
        }
      } else {
        const Eigen::Vector2d a = sup[0]->pose.translation().head<2>(), b = sup[1]->pose.translation().head<2>();
        const Eigen::Vector2d ab = b - a;
        const double lambda = ab.squaredNorm() > 1e-12 ? std::clamp((zmp_ - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0) : 0.5;
        const Eigen::Vector2d off = zmp_ - (a + lambda * ab);
        wantAt(*sup[0], 1 - lambda, a + off);
        wantAt(*sup[1], lambda, b + off);
      }
    }
    for (const Foot& f : down) {
      want_load_[f.spot] = f.want;
      want_cop_[f.spot] = (f.pose * Eigen::Vector3d(f.want_cop.x(), f.want_cop.y(), 0)).head<2>();
    }
    for (Foot& f : down) {
      double& z = lift_[f.spot];
      Eigen::Vector2d& th = tilt_[f.spot];
      if (down.size() >= 2) z = step(z, (f.force - f.want) / opt_.force_damping - z / opt_.force_leak, dt, opt_.max_lift);
      else z *= std::exp(-dt / opt_.force_leak);
      if (f.supporting && f.force > 1.0) {
        // Turning about the foot's +y by a > 0 presses its toe (+x) down;
        // about its +x by b > 0 lifts its +y side.
        Eigen::Vector2d e = f.want_cop - f.cop;
        // A ZMP wanted beyond the sole's edge was pulled cop_edge inside it;
        // a centre of pressure already past that point, toward the wanted
        // ZMP, is where the stabilizer wants it: turning the foot to bring it
        // back inside would move the centre of mass away from the ZMP's side,
        // the opposite of what the wanted ZMP asks.
        if (f.pulled.norm() > 1e-9) {
          const Eigen::Vector2d u = f.pulled.normalized();
          if (e.dot(u) < 0) e -= e.dot(u) * u;
        }
        th.x() = step(th.x(), -opt_.cop_gain * e.y() - th.x() / opt_.cop_leak, dt, opt_.max_tilt);
        th.y() = step(th.y(), opt_.cop_gain * e.x() - th.y() / opt_.cop_leak, dt, opt_.max_tilt);
      } else {
        th *= std::exp(-dt / opt_.cop_leak);
      }
      place_[f.spot] *= std::exp(-dt / opt_.place_leak);
      regulated[f.spot] = true;
    }
  }
  const bool placing = on && anchor && waist;
  for (int s : feet_)
    if (!regulated[s]) {
      const Eigen::Isometry3d planned = kin_.spotPose(s);
      const double f = planned.linear().col(2).dot(wrenches[s].force);
      if (placing && f > 1.0) {
        // Touching the floor already: held where it is.
      } else if (placing) {
        // Where the plan has this sole relative to the anchor, put on the
        // anchor's measured frame, against where the reference puts it: the
        // plan's sole relative to the waist, on the measured waist. (Not
        // against the measured sole, whose lag behind a moving reference is
        // no placement error.)
        const Eigen::Isometry3d want = *wrenches[anchor->spot].frame * anchor->pose.inverse() * planned;
        const Eigen::Isometry3d ref = *waist * plan.basePose().inverse() * planned;
        // Along the floor only: across the floor the sole's height and
        // tilt stay the plan's (pushing a sole down against a waist that the
        // push itself tilts would feed on itself; a sole that lands early
        // yields instead, below).
        const Eigen::AngleAxisd turn(want.linear() * ref.linear().transpose());
        Eigen::Matrix<double, 6, 1> target = Eigen::Matrix<double, 6, 1>::Zero();
        target.head<2>() = (want.translation() - ref.translation()).head<2>();
        target[5] = (turn.angle() * turn.axis()).z();
        Eigen::Matrix<double, 6, 1>& x = place_[s];
        for (int i = 0; i < 6; ++i) {
          const double bound = i < 3 ? opt_.max_place : opt_.max_place_turn;
          x[i] = step(x[i], (std::clamp(target[i], -bound, bound) - x[i]) / opt_.place_time, dt, bound);
        }
      } else {
        place_[s] *= std::exp(-dt / opt_.off_time);
      }
      // A swinging foot that meets the floor early (the body sags a few
      // millimetres under its servos' compliance) yields to the load it
      // measures, as the landing foot's force control does, instead of
      // pushing the body over with the rest of its descent.
      if (on && f > 1.0) lift_[s] = step(lift_[s], f / opt_.force_damping, dt, opt_.max_lift);
      else lift_[s] *= std::exp(-dt / opt_.off_time);
      tilt_[s] *= std::exp(-dt / opt_.off_time);
    }

  // Joint offsets: each foot moved by its rise and turned by its tilt
  // relative to the waist, through the leg's Jacobian (damped least squares,
  // so that a stretched knee does not blow them up).
  Eigen::VectorXd dq = Eigen::VectorXd::Zero(m.numJoints());
  for (std::size_t k = 0; k < feet_.size(); ++k) {
    const int s = feet_[k];
    if (std::abs(lift_[s]) < 1e-9 && tilt_[s].norm() < 1e-9 && place_[s].norm() < 1e-9) continue;
    const ContactSpot& spot = m.spots()[s];
    const Eigen::Isometry3d pose = kin_.spotPose(s);
    Eigen::Matrix<double, 6, 1> d = place_[s];
    d.head<3>() += lift_[s] * pose.linear().col(2);
    d.tail<3>() += pose.linear() * Eigen::Vector3d(tilt_[s].x(), tilt_[s].y(), 0);
    const Eigen::MatrixXd J = kin_.frameJacobian(spot.link, spot.frame.translation());
    const std::vector<int>& leg = leg_[k];
    Eigen::MatrixXd Jl(6, leg.size());
    for (std::size_t i = 0; i < leg.size(); ++i) Jl.col(i) = J.col(6 + leg[i]);
    const Eigen::MatrixXd A = Jl * Jl.transpose() + 1e-6 * Eigen::MatrixXd::Identity(6, 6);
    const Eigen::VectorXd x = Jl.transpose() * A.ldlt().solve(d);
    for (std::size_t i = 0; i < leg.size(); ++i) dq[leg[i]] += x[i];
  }
  return dq;
}

}  // namespace acyclic::hrp2
