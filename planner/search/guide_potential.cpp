#include "planner/search/guide_potential.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "planner/common/geometry.h"

namespace acyclic {

namespace {

constexpr int kDegree = 7;

double binomial(int n, int k) {
  double r = 1;
  for (int i = 1; i <= k; ++i) r = r * (n - k + i) / i;
  return r;
}

// Control points of the first `n` derivatives of a Bezier curve (hodographs), index 0 the curve itself.
std::vector<std::vector<Eigen::VectorXd>> hodographs(const std::vector<Eigen::VectorXd>& P, int n) {
  std::vector<std::vector<Eigen::VectorXd>> out = {P};
  for (int d = 1; d <= n; ++d) {
    const auto& Q = out.back();
    const double degree = static_cast<double>(Q.size()) - 1;
    std::vector<Eigen::VectorXd> next;
    for (std::size_t i = 0; i + 1 < Q.size(); ++i) next.push_back(degree * (Q[i + 1] - Q[i]));
    out.push_back(next);
  }
  return out;
}

// A Bezier curve with control points Q at t (Bernstein form).
Eigen::VectorXd bernstein(const std::vector<Eigen::VectorXd>& Q, double t) {
  const int m = static_cast<int>(Q.size()) - 1;
  Eigen::VectorXd out = Eigen::VectorXd::Zero(Q[0].size());
  for (int i = 0; i <= m; ++i) out += binomial(m, i) * std::pow(t, i) * std::pow(1 - t, m - i) * Q[i];
  return out;
}

// 5-point Gauss-Legendre on [a, b].
template <class F>
double gauss(F f, double a, double b) {
  static const double x[5] = {0.0, -0.5384693101056831, 0.5384693101056831, -0.9061798459386640, 0.9061798459386640};
  static const double w[5] = {0.5688888888888889, 0.4786286704993665, 0.4786286704993665, 0.2369268850561891,
                              0.2369268850561891};
  const double h = 0.5 * (b - a), c = 0.5 * (a + b);
  double s = 0;
  for (int i = 0; i < 5; ++i) s += w[i] * f(c + h * x[i]);
  return h * s;
}

// Quintic Hermite basis with zero second derivatives at both ends:
// values at 0 and 1, slopes at 0 and 1 (in sigma), and their derivatives.
void quintic(double t, double h[4], double dh[4]) {
  const double t2 = t * t, t3 = t2 * t, t4 = t3 * t, t5 = t4 * t;
  h[0] = 1 - 10 * t3 + 15 * t4 - 6 * t5;
  h[1] = t - 6 * t3 + 8 * t4 - 3 * t5;
  h[2] = -4 * t3 + 7 * t4 - 3 * t5;
  h[3] = 10 * t3 - 15 * t4 + 6 * t5;
  dh[0] = -30 * t2 + 60 * t3 - 30 * t4;
  dh[1] = 1 - 18 * t2 + 32 * t3 - 15 * t4;
  dh[2] = -12 * t2 + 28 * t3 - 15 * t4;
  dh[3] = 30 * t2 - 60 * t3 + 30 * t4;
}

// Largest distance from a corner blend (control points as below, half-size 1)
// to the two half-lines meeting at the corner V along -u1 and u2.
double blendDeviation(const std::vector<Eigen::VectorXd>& ctrl, const Eigen::VectorXd& V, const Eigen::VectorXd& u1,
                      const Eigen::VectorXd& u2) {
  double worst = 0;
  for (int k = 0; k <= 100; ++k) {
    const Eigen::VectorXd c = bernstein(ctrl, k / 100.0) - V;
    const double d1 = (c - std::min(0.0, c.dot(u1)) * u1).norm();
    const double d2 = (c - std::max(0.0, c.dot(u2)) * u2).norm();
    worst = std::max(worst, std::min(d1, d2));
  }
  return worst;
}

Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d S;
  S << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return S;
}

}  // namespace

Eigen::VectorXd GuidePotential::coordinates(const Configuration& q) {
  Eigen::VectorXd P(6 + q.joints.size());
  P.head<3>() = q.base_position;
  P.segment<3>(3) = logSO3(q.base_orientation.normalized().toRotationMatrix());
  P.tail(q.joints.size()) = q.joints;
  return P;
}

GuidePotential::GuidePotential(const std::vector<Configuration>& key_postures, double k, double tolerance,
                               double joint_weight)
    : k_(k), tol_(tolerance), joint_weight_(joint_weight) {
  if (!(joint_weight > 0)) throw std::invalid_argument("the guide's joint weight must be positive");
  if (key_postures.size() < 2) throw std::invalid_argument("the rough trajectory needs at least two key postures");
  if (!(tolerance > 0)) throw std::invalid_argument("the smoothing tolerance must be positive");
  for (const auto& q : key_postures) keys_.push_back(coordinates(q));
  n_ = static_cast<int>(keys_[0].size());
  const int m = static_cast<int>(keys_.size());
  std::vector<double> L(m - 1);
  std::vector<Eigen::VectorXd> U(m - 1);
  for (int i = 0; i + 1 < m; ++i) {
    const Eigen::VectorXd d = keys_[i + 1].head(6) - keys_[i].head(6);
    L[i] = d.norm();
    if (L[i] < 1e-9)
      throw std::invalid_argument("key postures " + std::to_string(i) + " and " + std::to_string(i + 1) +
                                  " have the same base pose: the guide's base projection must be one-to-one");
    U[i] = d / L[i];
  }
  // Half-size t of the blend at each interior corner (0: none).
  std::vector<double> t(m, 0.0);
  for (int i = 1; i + 1 < m; ++i) {
    const double c = U[i - 1].dot(U[i]);
    if (1 - c < 1e-12) continue;
    if (c < std::cos(179.0 * M_PI / 180))
      throw std::invalid_argument("the rough trajectory turns back on itself at key posture " + std::to_string(i));
    // The blend's distance to the corner grows linearly with t.
    std::vector<Eigen::VectorXd> unit;
    const Eigen::VectorXd V = keys_[i].head(6);
    for (int j = 0; j < 4; ++j) unit.push_back(V - (1 - j / 3.0) * U[i - 1]);
    for (int j = 0; j < 4; ++j) unit.push_back(V + (j / 3.0) * U[i]);
    const double g = blendDeviation(unit, V, U[i - 1], U[i]);
    t[i] = std::min({tol_ / g, 0.5 * L[i - 1], 0.5 * L[i]});
  }
  auto restAt = [&](int seg, double along) {  // joints on original segment seg at distance `along`
    return Eigen::VectorXd(keys_[seg].tail(n_ - 6) + (along / L[seg]) * (keys_[seg + 1].tail(n_ - 6) - keys_[seg].tail(n_ - 6)));
  };
  auto slope = [&](int seg) {
    return Eigen::VectorXd((keys_[seg + 1].tail(n_ - 6) - keys_[seg].tail(n_ - 6)) / L[seg]);
  };
  double s = 0;
  for (int i = 0; i + 1 < m; ++i) {
    if (t[i] > 0) {  // the blend at the corner i
      Piece b;
      b.blend = true;
      b.V = keys_[i].head(6);
      for (int j = 0; j < 4; ++j) b.ctrl.push_back(b.V - t[i] * (1 - j / 3.0) * U[i - 1]);
      for (int j = 0; j < 4; ++j) b.ctrl.push_back(b.V + t[i] * (j / 3.0) * U[i]);
      b.hodographs = hodographs(b.ctrl, 3);
      b.centre = Eigen::VectorXd::Zero(6);
      for (const auto& c : b.ctrl) b.centre += c / static_cast<double>(b.ctrl.size());
      for (const auto& c : b.ctrl) b.radius = std::max(b.radius, (c - b.centre).norm());
      const int N = 64;
      b.tau_table.push_back(0);
      b.s_table.push_back(0);
      for (int k = 1; k <= N; ++k) {
        const double a = (k - 1.0) / N, c = static_cast<double>(k) / N;
        b.tau_table.push_back(c);
        b.s_table.push_back(b.s_table.back() + gauss([&](double x) { return blendPoint(b, x, 1).norm(); }, a, c));
      }
      b.len = b.s_table.back();
      b.s0 = s;
      b.r0 = restAt(i - 1, L[i - 1] - t[i]);
      b.r1 = restAt(i, t[i]);
      b.m0 = slope(i - 1);
      b.m1 = slope(i);
      s += b.len;
      pieces_.push_back(b);
    }
    Piece seg;  // the segment from corner i to corner i + 1, trimmed by their blends
    seg.len = L[i] - t[i] - t[i + 1];
    if (seg.len > 1e-12) {  // zero only between two blends that each take half of it
      seg.u = U[i];
      seg.a = keys_[i].head(6) + t[i] * U[i];
      seg.r0 = restAt(i, t[i]);
      seg.m0 = slope(i);
      seg.s0 = s;
      s += seg.len;
      pieces_.push_back(seg);
    }
  }
  length_ = s;
}

Eigen::VectorXd GuidePotential::blendPoint(const Piece& p, double tau, int d) {
  return bernstein(p.hodographs[d], tau);
}

Eigen::VectorXd GuidePotential::basePoint(const Piece& p, double tau, int d) const {
  if (p.blend) return blendPoint(p, tau, d);
  if (d == 0) return p.a + tau * p.len * p.u;
  if (d == 1) return p.len * p.u;
  return Eigen::VectorXd::Zero(6);
}

double GuidePotential::arcLength(const Piece& p, double tau) const {
  if (!p.blend) return tau * p.len;
  const int N = static_cast<int>(p.tau_table.size()) - 1;
  const int k = std::min(N - 1, static_cast<int>(tau * N));
  return p.s_table[k] + gauss([&](double x) { return blendPoint(p, x, 1).norm(); }, p.tau_table[k], tau);
}

double GuidePotential::tauAt(const Piece& p, double sl) const {
  if (!p.blend) return p.len > 0 ? sl / p.len : 0.0;
  const int N = static_cast<int>(p.tau_table.size()) - 1;
  int k = 0;
  while (k + 1 < N && p.s_table[k + 1] < sl) ++k;
  double tau = p.tau_table[k] + (sl - p.s_table[k]) / (p.s_table[k + 1] - p.s_table[k]) / N;
  for (int it = 0; it < 20; ++it) {
    const double f = arcLength(p, tau) - sl;
    if (std::abs(f) < 1e-14) break;
    tau = std::clamp(tau - f / blendPoint(p, tau, 1).norm(), 0.0, 1.0);
  }
  return tau;
}

void GuidePotential::rest(const Piece& p, double sl, Eigen::VectorXd& r, Eigen::VectorXd& dr) const {
  if (!p.blend) {
    r = p.r0 + sl * p.m0;
    dr = p.m0;
    return;
  }
  double h[4], dh[4];
  const double S = p.len;
  quintic(sl / S, h, dh);
  r = h[0] * p.r0 + h[1] * S * p.m0 + h[2] * S * p.m1 + h[3] * p.r1;
  dr = (dh[0] * p.r0 + dh[1] * S * p.m0 + dh[2] * S * p.m1 + dh[3] * p.r1) / S;
}

GuidePotential::Projection GuidePotential::project(const Eigen::VectorXd& P) const {
  if (P.size() != n_) throw std::invalid_argument("GuidePotential: coordinate size mismatch");
  const Eigen::VectorXd Pb = P.head(6);
  // A blend costs a grid and a Newton search of Bernstein evaluations; a
  // segment a dot product. The segments' nearest distance bounds the
  // answer, so a blend whose ball is farther than it cannot be the closest
  // piece and is not searched. The margin (1e-9, against ties decided at
  // 1e-15 below) keeps the choice exactly the one of searching every piece.
  // A segment's nearest point: its parameter and squared distance (an
  // expression, no vector made: this runs in every cost evaluation).
  auto nearestOnSegment = [&](const Piece& p, double& tau) {
    tau = p.len > 0 ? std::clamp((Pb - p.a).dot(p.u) / p.len, 0.0, 1.0) : 0.0;
    return (p.a + tau * p.len * p.u - Pb).squaredNorm();
  };
  // Each segment's (tau, d) is kept from this first pass for the second,
  // which decides ties in piece order. The buffer is per thread and reused,
  // so no allocation happens per call once it has grown.
  thread_local std::vector<std::pair<double, double>> segment_nearest;
  segment_nearest.resize(pieces_.size());
  double nearest_segment = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < pieces_.size(); ++i)
    if (!pieces_[i].blend) {
      double tau;
      const double d = nearestOnSegment(pieces_[i], tau);
      segment_nearest[i] = {tau, d};
      nearest_segment = std::min(nearest_segment, d);
    }
  const double bound = nearest_segment * (1 + 1e-9) + 1e-9;
  double best = std::numeric_limits<double>::infinity();
  int best_piece = 0;
  double best_tau = 0;
  int blends_searched = 0;
  for (int i = 0; i < static_cast<int>(pieces_.size()); ++i) {
    const Piece& p = pieces_[i];
    double tau, d;
    if (!p.blend) {
      std::tie(tau, d) = segment_nearest[i];
    } else {
      const double gap = (Pb - p.centre).norm() - p.radius * (1 + 1e-12) - 1e-12;
      if (gap > 0 && gap * gap > bound) continue;
      ++blends_searched;
      tau = 0;
      double bd = std::numeric_limits<double>::infinity();
      for (int k = 0; k <= 16; ++k) {
        const double dk = (blendPoint(p, k / 16.0, 0) - Pb).squaredNorm();
        if (dk < bd) bd = dk, tau = k / 16.0;
      }
      for (int it = 0; it < 30; ++it) {  // Newton on (c - P) . c' = 0
        const Eigen::VectorXd c = blendPoint(p, tau, 0), c1 = blendPoint(p, tau, 1), c2 = blendPoint(p, tau, 2);
        const double g = (c - Pb).dot(c1), dg = c1.squaredNorm() + (c - Pb).dot(c2);
        const double next = std::clamp(tau - g / (dg > 0 ? dg : c1.squaredNorm()), 0.0, 1.0);
        if (std::abs(next - tau) < 1e-15) break;
        tau = next;
      }
      d = (blendPoint(p, tau, 0) - Pb).squaredNorm();
    }
    if (d < best - 1e-15) best = d, best_piece = i, best_tau = tau;
  }
  const Piece& p = pieces_[best_piece];
  Projection pr;
  pr.piece = best_piece;
  pr.blends_searched = blends_searched;
  const double sl = arcLength(p, best_tau);
  pr.s = p.s0 + sl;
  const Eigen::VectorXd c = basePoint(p, best_tau, 0), c1 = basePoint(p, best_tau, 1), c2 = basePoint(p, best_tau, 2);
  Eigen::VectorXd r, dr;
  rest(p, sl, r, dr);
  pr.Q.resize(n_);
  pr.Q << c, r;
  pr.Q_s.resize(n_);
  pr.Q_s << c1.normalized(), dr;
  pr.grad_s = Eigen::VectorXd::Zero(n_);
  const bool before_start = best_piece == 0 && best_tau <= 0 && (Pb - c).dot(c1) < 0;
  const bool after_end = best_piece + 1 == static_cast<int>(pieces_.size()) && best_tau >= 1 && (Pb - c).dot(c1) > 0;
  if (!before_start && !after_end) {
    // From (c(tau) - P) . c'(tau) = 0: dtau/dP = c' / (|c'|^2 + (c - P) . c''), ds = |c'| dtau.
    const double den = c1.squaredNorm() + (c - Pb).dot(c2);
    pr.grad_s.head(6) = c1.norm() * c1 / den;
  }
  return pr;
}

double GuidePotential::valueAndGradient(const Eigen::VectorXd& P, Eigen::VectorXd* grad) const {
  const Projection pr = project(P);
  const Eigen::VectorXd D = P - pr.Q;
  Eigen::VectorXd WD = D;  // the weighted difference: base weight 1, joints joint_weight_
  WD.tail(n_ - 6) *= joint_weight_;
  if (grad) *grad = 2 * WD - (2 * WD.dot(pr.Q_s) + k_) * pr.grad_s;
  return D.dot(WD) - k_ * pr.s;
}

double GuidePotential::value(const Eigen::VectorXd& P) const { return valueAndGradient(P, nullptr); }

Eigen::VectorXd GuidePotential::gradient(const Eigen::VectorXd& P) const {
  Eigen::VectorXd g;
  valueAndGradient(P, &g);
  return g;
}

Eigen::VectorXd GuidePotential::pointAt(double s) const {
  s = std::clamp(s, 0.0, length_);
  int i = 0;
  while (i + 1 < static_cast<int>(pieces_.size()) && pieces_[i + 1].s0 <= s) ++i;
  const Piece& p = pieces_[i];
  const double sl = std::min(s - p.s0, p.len);
  Eigen::VectorXd r, dr;
  rest(p, sl, r, dr);
  Eigen::VectorXd out(n_);
  out << basePoint(p, tauAt(p, sl), 0), r;
  return out;
}

std::vector<double> GuidePotential::junctions() const {
  std::vector<double> out;
  for (const auto& p : pieces_)
    if (p.blend) out.push_back(p.s0), out.push_back(p.s0 + p.len);
  return out;
}

double GuidePotential::maxDeviation() const {
  double worst = 0;
  for (const auto& p : pieces_)
    if (p.blend)
      worst = std::max(worst, blendDeviation(p.ctrl, p.V, (p.ctrl[3] - p.ctrl[0]).normalized(),
                                             (p.ctrl[7] - p.ctrl[4]).normalized()));
  return worst;
}

double GuidePotential::evaluate(const Kinematics& kin, Eigen::Ref<Eigen::VectorXd> grad) const {
  const Eigen::VectorXd P = coordinates(kin.configuration());
  Eigen::VectorXd g;
  const double f = valueAndGradient(P, &g);
  // Tangent space: a world rotation dtheta changes w = log R by J_l(w)^-1 dtheta.
  const Eigen::Vector3d w = P.segment<3>(3);
  const double th = w.norm();
  const Eigen::Matrix3d W = skew(w);
  Eigen::Matrix3d Jinv = Eigen::Matrix3d::Identity() - 0.5 * W;
  if (th > 1e-6) Jinv += (1 / (th * th) - (1 + std::cos(th)) / (2 * th * std::sin(th))) * W * W;
  else Jinv += W * W / 12.0;
  grad.head<3>() += g.head<3>();
  grad.segment<3>(3) += Jinv.transpose() * g.segment<3>(3);
  grad.tail(n_ - 6) += g.tail(n_ - 6);
  return f;
}

Eigen::VectorXd GuidePotential::diagonalHessian(int tangent_size) const {
  Eigen::VectorXd h = Eigen::VectorXd::Constant(tangent_size, 2.0);
  h.tail(tangent_size - 6) *= joint_weight_;
  return h;
}

}  // namespace acyclic
