#include "planner/check/quasi_static.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "planner/scene/friction.h"

#include <coin/ClpSimplex.hpp>
#include <coin/CoinPackedMatrix.hpp>

namespace acyclic {

namespace {

// A sparse LP assembled row by row, solved by Clp.
struct Lp {
  int ncols = 0;
  std::vector<int> ri, ci;
  std::vector<double> v, rlo, rhi, clo, chi, obj;
  int addCol(double lo, double hi, double c) {
    clo.push_back(lo), chi.push_back(hi), obj.push_back(c);
    return ncols++;
  }
  void addRow(const std::vector<std::pair<int, double>>& terms, double lo, double hi) {
    const int r = static_cast<int>(rlo.size());
    for (const auto& [c, a] : terms)
      if (std::abs(a) > 1e-12) ri.push_back(r), ci.push_back(c), v.push_back(a);
    rlo.push_back(lo), rhi.push_back(hi);
  }
  // Minimizes obj; returns false when infeasible (or failed). With `warm`:
  // starts from its basis when the LP has the same size, and keeps the
  // optimal basis found.
  bool solve(std::vector<double>& x, QuasiStaticChecker::WarmStart* warm) const {
    const int nrows = static_cast<int>(rlo.size());
    CoinPackedMatrix M(false, ri.data(), ci.data(), v.data(), static_cast<CoinBigIndex>(v.size()));
    M.setDimensions(nrows, ncols);
    auto load = [&](ClpSimplex& model) {
      model.setLogLevel(0);
      model.loadProblem(M, clo.data(), chi.data(), obj.data(), rlo.data(), rhi.data());
    };
    if (warm && warm->rows == nrows && warm->cols == ncols) {
      ClpSimplex model;
      load(model);
      model.copyinStatus(warm->status.data());
      model.dual();  // from the given basis (a presolve would drop it)
      if (model.isProvenOptimal()) return finish(model, x, warm);
      // a stale basis must never change the verdict: solved again from scratch
    }
    ClpSimplex model;
    load(model);
    model.initialSolve();  // presolve, then Clp's choice of method
    if (model.isProvenOptimal()) return finish(model, x, warm);
    // Clp's presolve has called feasible LPs of this kind infeasible (the
    // friction facets make them degenerate): an infeasible verdict needs the
    // simplex without presolve to agree, dual and then primal.
    ClpSimplex dual;
    load(dual);
    dual.dual();
    if (dual.isProvenOptimal()) return finish(dual, x, warm);
    ClpSimplex primal;
    load(primal);
    primal.primal();
    return finish(primal, x, warm);
  }
  bool finish(ClpSimplex& model, std::vector<double>& x, QuasiStaticChecker::WarmStart* warm) const {
    if (!model.isProvenOptimal()) return false;
    x.assign(model.getColSolution(), model.getColSolution() + ncols);
    if (warm) {
      warm->rows = static_cast<int>(rlo.size());
      warm->cols = ncols;
      warm->status.assign(model.statusArray(), model.statusArray() + warm->rows + ncols);
    }
    return true;
  }
};

// The contract's friction facets in the surface frame: outward direction
// (cos, sin) and the cone's share where the facet lies (cos(pi/E)).
struct Facet {
  double cos, sin, inset;
};
const std::array<Facet, kFrictionPyramidEdges> kFacets = [] {
  std::array<Facet, kFrictionPyramidEdges> f{};
  for (int m = 0; m < kFrictionPyramidEdges; ++m) {
    const double a = 2 * M_PI * (m + 0.5) / kFrictionPyramidEdges;
    f[m] = {std::cos(a), std::sin(a), std::cos(M_PI / kFrictionPyramidEdges)};
  }
  return f;
}();

// A supporting contact's polygon corner: world point, its surface's normal
// and tangent axes and friction, and the corner's J^T columns (Simbody).
struct Corner {
  int contact;
  Eigen::Vector3d p, n, t1, t2;
  double mu;
  Eigen::MatrixXd JT;  // nt x 3
};

// The corners of a stance's supporting contacts at the kinematics'
// configuration; `supporting` counts those contacts.
std::vector<Corner> supportingCorners(const RobotModel& m, const Scene& scene, const Kinematics& kin,
                                      const std::vector<ContactSpec>& stance, int& supporting) {
  std::vector<Corner> corners;
  supporting = 0;
  for (std::size_t ci = 0; ci < stance.size(); ++ci) {
    const ContactSpec& c = stance[ci];
    if (!c.supporting) continue;
    ++supporting;
    const ContactSpot& spot = m.spots()[c.spot];
    const Surface& s = scene.surfaces()[c.surface];
    const Eigen::Isometry3d Tspot = kin.spotPose(c.spot);
    // One frame Jacobian at the spot's origin (Simbody) gives every corner's:
    // v_p = v_o + w x (p - o), so each column of J_p is J_v's plus J_w's
    // x (p - o). Half the passes of a station Jacobian per corner, in the
    // check that every sample of a trajectory pays.
    const Eigen::MatrixXd Jo = kin.frameJacobian(spot.link, spot.frame.translation());  // rows: linear, angular
    const Eigen::Matrix<double, 3, Eigen::Dynamic> Jw = Jo.bottomRows<3>();
    for (const auto& v : spot.polygon.vertices()) {
      Corner k;
      k.contact = static_cast<int>(ci);
      const Eigen::Vector3d in_spot(v.x(), v.y(), 0);
      k.p = Tspot * in_spot;
      k.n = s.frame.linear().col(2);
      k.t1 = s.frame.linear().col(0);
      k.t2 = s.frame.linear().col(1);
      k.mu = s.friction;
      k.JT = (Jo.topRows<3>() + Jw.colwise().cross(k.p - Tspot.translation())).transpose();
      corners.push_back(k);
    }
  }
  return corners;
}

// Columns (f_n, f_t1, f_t2) for each corner, from column 0.
void addCornerColumns(Lp& lp, std::size_t corners) {
  for (std::size_t k = 0; k < corners; ++k) {
    lp.addCol(0, COIN_DBL_MAX, 0);
    lp.addCol(-COIN_DBL_MAX, COIN_DBL_MAX, 0);
    lp.addCol(-COIN_DBL_MAX, COIN_DBL_MAX, 0);
  }
}

// Row i of sum J^T f over the corners' columns.
std::vector<std::pair<int, double>> generalizedForceRow(const std::vector<Corner>& corners, int i) {
  std::vector<std::pair<int, double>> row;
  for (std::size_t k = 0; k < corners.size(); ++k) {
    const Corner& c = corners[k];
    row.push_back({3 * static_cast<int>(k), c.JT.row(i).dot(c.n)});
    row.push_back({3 * static_cast<int>(k) + 1, c.JT.row(i).dot(c.t1)});
    row.push_back({3 * static_cast<int>(k) + 2, c.JT.row(i).dot(c.t2)});
  }
  return row;
}

// The contract's friction pyramid at each corner by its facets:
// mu cos(pi/E) f_n - (cos a f_t1 + sin a f_t2) >= s, s the column `margin`
// (LP 1) or 0 (margin < 0), a = 2 pi (m + 1/2) / E the facet's outward direction.
void addFacetRows(Lp& lp, const std::vector<Corner>& corners, int margin) {
  for (std::size_t k = 0; k < corners.size(); ++k)
    for (const Facet& f : kFacets) {
      const int c = 3 * static_cast<int>(k);
      std::vector<std::pair<int, double>> row = {{c, corners[k].mu * f.inset}, {c + 1, -f.cos}, {c + 2, -f.sin}};
      if (margin >= 0) row.push_back({margin, -1.0});
      lp.addRow(row, 0, COIN_DBL_MAX);
    }
}

}  // namespace

QuasiStaticChecker::QuasiStaticChecker(std::shared_ptr<const RobotModel> robot, std::shared_ptr<const Scene> scene)
    : robot_(std::move(robot)), scene_(std::move(scene)) {}

QuasiStaticReport QuasiStaticChecker::check(const Kinematics& kin, const std::vector<ContactSpec>& stance) const {
  QuasiStaticReport rep;
  if (!margin_computed_) rep.margin = std::numeric_limits<double>::quiet_NaN();
  const RobotModel& m = *robot_;
  const int nt = m.tangentSize();
  const double W = m.totalMass() * 9.81;
  const Eigen::VectorXd g = kin.gravityTorques();  // Simbody

  const std::vector<Corner> corners = supportingCorners(m, *scene_, kin, stance, rep.supporting_contacts);
  if (corners.empty()) {
    rep.reason = "no supporting contact";
    return rep;
  }

  // Columns: per corner (f_n, f_t1, f_t2), then the LP's own variable (s or t).
  auto build = [&](Lp& lp, bool margin_lp) {
    addCornerColumns(lp, corners.size());
    const int extra = margin_lp ? lp.addCol(-W, W, -1.0)   // maximize s
                                : lp.addCol(0, COIN_DBL_MAX, 1.0);  // minimize t
    // Generalized force rows: (J^T f)_i for each tangent index i.
    for (int i = 0; i < nt; ++i) {
      const std::vector<std::pair<int, double>> row = generalizedForceRow(corners, i);
      if (i < 6) {
        lp.addRow(row, g[i], g[i]);  // the base: forces and moments balance gravity
      } else {
        const double lim = m.joints()[i - 6].effort;
        if (margin_lp) {
          lp.addRow(row, g[i] - lim, g[i] + lim);  // |g - J^T f| <= limit
        } else {
          // |g_i - (J^T f)_i| <= t lim:  (J^T f)_i + t lim >= g_i  and  (J^T f)_i - t lim <= g_i
          auto r1 = row, r2 = row;
          r1.push_back({extra, lim});
          r2.push_back({extra, -lim});
          lp.addRow(r1, g[i], COIN_DBL_MAX);
          lp.addRow(r2, -COIN_DBL_MAX, g[i]);
        }
      }
    }
    // Friction: the contract's pyramid inscribed in the cone (friction.h),
    // by its facets, inside by s (LP 1) or 0 (LP 2).
    addFacetRows(lp, corners, margin_lp ? extra : -1);
    return extra;
  };

  std::unique_lock<std::mutex> warm_lock(warm_mutex_, std::defer_lock);
  if (warm_start_) warm_lock.try_lock();
  WarmStart* warm2 = warm_lock.owns_lock() ? &warm_[1] : nullptr;
  WarmStart* warm1 = warm_lock.owns_lock() ? &warm_[0] : nullptr;
  const int nf = 3 * static_cast<int>(corners.size());
  std::vector<double> x2;  // forces per corner (f_n, f_t1, f_t2), then LP 2's t when it is solved

  // Forces reused (setForcesReused): a point that proves LP 2 feasible. The
  // seed moved by the least-norm change that balances the base here, then
  // accepted when inside every facet with its normal force >= 0, every torque
  // within (1 - 1e-6) of its limit and the balance exact to 1e-9 of the
  // weight: LP 2's optimum is then at most that point's ratio, below 1.
  auto certify = [&](const Eigen::VectorXd& seed, std::vector<double>& x) {
    Eigen::MatrixXd M(nt, nf);  // generalized forces of each corner's (f_n, f_t1, f_t2)
    for (std::size_t k = 0; k < corners.size(); ++k) {
      const Corner& c = corners[k];
      M.col(3 * k) = c.JT * c.n;
      M.col(3 * k + 1) = c.JT * c.t1;
      M.col(3 * k + 2) = c.JT * c.t2;
    }
    const auto A = M.topRows<6>();
    const Eigen::Matrix<double, 6, 6> AAt = A * A.transpose();
    const Eigen::VectorXd f = seed + A.transpose() * AAt.ldlt().solve(g.head<6>() - A * seed);
    const Eigen::VectorXd tau = g - M * f;
    if (!(tau.head<6>().norm() <= 1e-3 * residualTolerance() * W)) return false;
    for (std::size_t k = 0; k < corners.size(); ++k) {
      if (!(f[3 * k] >= 0)) return false;
      for (const Facet& fa : kFacets)
        if (!(corners[k].mu * fa.inset * f[3 * k] - fa.cos * f[3 * k + 1] - fa.sin * f[3 * k + 2] >= 0)) return false;
    }
    for (const auto& j : m.joints())
      if (!(std::abs(tau[6 + j.index]) <= (1 - 1e-6) * j.effort)) return false;
    x.assign(f.data(), f.data() + nf);
    return true;
  };
  // The seed: the previous check's point, when it had the same supporting
  // contacts. LP 2's own solution would not do: at its vertex unloaded
  // corners and some facets sit exactly on their bounds (and LP 1's on a
  // torque limit), and the next sample's change leaves them. The midpoint of
  // the two is inside both by half their margins.
  const bool may_reuse = reuse_forces_ && !margin_computed_ && warm_lock.owns_lock();
  std::vector<std::pair<int, int>> supporting;  // (spot, surface), in stance order
  if (may_reuse)
    for (const auto& c : stance)
      if (c.supporting) supporting.push_back({c.spot, c.surface});
  const bool certified =
      may_reuse && last_.contacts == supporting && last_.f.size() == nf && certify(last_.f, x2);
  if (certified) {
    ++reused_;
    last_.f = Eigen::Map<const Eigen::VectorXd>(x2.data(), nf);
  } else {
    // LP 2: forces in their pyramids that balance gravity, with the smallest
    // worst torque ratio; infeasible only when no forces balance at all.
    Lp lp2;
    const int t_col = build(lp2, false);
    if (!lp2.solve(x2, warm2)) {
      rep.reason = "no contact forces inside the friction pyramids balance gravity (the centre of mass is outside the support)";
      return rep;
    }
    rep.worst_torque_ratio = x2[t_col];
    if (may_reuse) last_.contacts.clear();
    if (may_reuse && x2[t_col] < 1) {
      Lp lp1;
      const int s_col = build(lp1, true);
      std::vector<double> x1;
      if (lp1.solve(x1, warm1) && x1[s_col] > 0)
        last_ = {supporting, 0.5 * (Eigen::Map<const Eigen::VectorXd>(x1.data(), nf) +
                                    Eigen::Map<const Eigen::VectorXd>(x2.data(), nf))};
    }
  }
  // LP 1: how far inside the pyramids the forces can stay, torques within limits.
  if (margin_computed_) {
    Lp lp1;
    const int s_col = build(lp1, true);
    std::vector<double> x1;
    rep.margin = lp1.solve(x1, warm1) ? x1[s_col] : -std::numeric_limits<double>::infinity();
  }

  // Forces, torques and the balance residual at LP 2's solution (or the certified point).
  Eigen::VectorXd JTf = Eigen::VectorXd::Zero(nt);
  rep.points.assign(stance.size(), {});
  rep.forces.assign(stance.size(), {});
  for (std::size_t k = 0; k < corners.size(); ++k) {
    const Corner& c = corners[k];
    const Eigen::Vector3d f = x2[3 * k] * c.n + x2[3 * k + 1] * c.t1 + x2[3 * k + 2] * c.t2;
    JTf += c.JT * f;
    rep.points[c.contact].push_back(c.p);
    rep.forces[c.contact].push_back(f);
    rep.worst_cone_ratio = std::max(rep.worst_cone_ratio, coneRatio(f, c.n, c.mu, 1e-6 * W));
  }
  const Eigen::VectorXd tau = g - JTf;
  rep.residual = tau.head<6>().norm() / W;
  double worst = 0;
  for (const auto& j : m.joints()) {
    const double r = std::abs(tau[6 + j.index]) / j.effort;
    if (r > worst) worst = r, rep.worst_joint = j.name;
  }
  if (certified) rep.worst_torque_ratio = worst;  // that point's: LP 2's optimum is at most this
  const bool margin_ok = !margin_computed_ || rep.margin >= -1e-9;  // implied by worst <= 1 (setMarginComputed)
  rep.feasible = worst <= 1 + 1e-9 && margin_ok && rep.residual <= residualTolerance();
  if (!rep.feasible) {
    std::ostringstream os;
    if (worst > 1 + 1e-9) os << "the least torque needs " << worst << " times the limit at " << rep.worst_joint;
    else if (!margin_ok) os << "no forces within both the friction pyramids and the torque limits";
    else os << "balance residual " << rep.residual << " of the weight";
    rep.reason = os.str();
  }
  return rep;
}

PushMargin QuasiStaticChecker::pushMargin(const Kinematics& kin, const std::vector<ContactSpec>& stance,
                                          int directions) const {
  if (directions < 1) throw std::invalid_argument("pushMargin: at least one direction");
  PushMargin out;
  const RobotModel& m = *robot_;
  const int nt = m.tangentSize();
  const double W = m.totalMass() * 9.81;
  int supporting = 0;
  const std::vector<Corner> corners = supportingCorners(m, *scene_, kin, stance, supporting);
  if (corners.empty()) return out;
  const Eigen::VectorXd g = kin.gravityTorques();
  // A force F at the centre of mass has the generalized force J_com^T F
  // (gravity's is J_com^T (0, 0, -W), so g = J_com^T (0, 0, W)); held, it
  // adds -J_com^T F to what the joints and the contacts must supply.
  const Eigen::MatrixXd Jc = kin.centerOfMassJacobian();
  // Rows of sum J^T f, the same in every direction's LP.
  std::vector<std::vector<std::pair<int, double>>> force_rows(nt);
  for (int i = 0; i < nt; ++i) force_rows[i] = generalizedForceRow(corners, i);
  // The push s d held: (J^T f)_i + s push_i = g_i at the base, within the
  // limit of g_i at a joint; s in [0, s_max], maximized. x[s_col] on success.
  auto solve = [&](const Eigen::Vector3d& d, double s_max, std::vector<double>& x) {
    const Eigen::VectorXd push = Jc.transpose() * d;
    Lp lp;
    addCornerColumns(lp, corners.size());
    const int s_col = lp.addCol(0, s_max, -1.0);
    for (int i = 0; i < nt; ++i) {
      std::vector<std::pair<int, double>> row = force_rows[i];
      row.push_back({s_col, push[i]});
      const double lim = i < 6 ? 0.0 : m.joints()[i - 6].effort;
      lp.addRow(row, g[i] - lim, g[i] + lim);
    }
    addFacetRows(lp, corners, -1);
    return lp.solve(x, nullptr) ? std::max(0.0, x[s_col]) : -1.0;
  };
  // Without a push first: a stance out of equilibrium can be held with
  // one (the push moves the resultant's line into the support), which is
  // no margin. With it, each direction's feasible pushes are [0, s_max]
  // (the LP is convex), and a direction whose LP fails (numerically) counts 0.
  std::vector<double> x;
  if (solve(Eigen::Vector3d::UnitX(), 0.0, x) < 0) return out;
  out.per_direction.assign(directions, 0.0);
  for (int k = 0; k < directions; ++k) {
    const double a = 2 * M_PI * k / directions;
    out.per_direction[k] = std::max(0.0, solve(Eigen::Vector3d(std::cos(a), std::sin(a), 0), W, x));
  }
  out.computed = true;
  const auto weakest = std::min_element(out.per_direction.begin(), out.per_direction.end());
  out.weakest = *weakest;
  out.weakest_direction_deg = 360.0 * (weakest - out.per_direction.begin()) / directions;
  return out;
}

}  // namespace acyclic
