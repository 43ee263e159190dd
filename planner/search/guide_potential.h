#pragma once
// The guide potential f_T of the paper (section 2.7): a descending valley
// around a rough trajectory T of key postures,
//     f_T(P) = |P - Q|^2 - k s',
// where P' is P's base part (6-D: position, rotation vector), Q' the closest
// point of T' (T's base part) to P', s' its arc length along T', and Q the
// point of T above Q'.
//
// Coordinates: P = [base position (3), base rotation vector log(R) (3),
// joints (n)]. T is piecewise linear between key postures; the corners of T'
// are smoothed so that f_T is twice continuously differentiable near T. The
// paper uses circular arcs there; an arc's curvature jumps at its ends, which
// makes the gradient of s' (and of f_T) jump off the curve, so each corner is
// replaced instead by a degree-7 Bezier blend in the corner's plane whose
// curvature and curvature derivative vanish at both junctions, as large as
// the tolerance allows (distance to the corner <= tolerance, at most half of
// each adjacent segment). Above a blend, the joint coordinates of T follow a
// quintic in arc length that matches the adjacent segments' values, slopes
// and (zero) second derivatives.
#include <vector>

#include <Eigen/Core>

#include "planner/posture/posture_cost.h"

namespace acyclic {

class GuidePotential : public PostureCost {
 public:
  // Throws std::invalid_argument when fewer than two key postures are given,
  // or two consecutive ones share their base pose (T' must be one-to-one).
  // joint_weight scales the joints' part of |P - Q|^2 (the base's weight is 1):
  // below 1, the valley is about the base's path and leaves the limbs freer to
  // reach contacts the key postures did not foresee.
  GuidePotential(const std::vector<Configuration>& key_postures, double k = 1.0, double tolerance = 0.05,
                 double joint_weight = 1.0);

  static Eigen::VectorXd coordinates(const Configuration& q);

  struct Projection {
    double s = 0;                 // arc length of Q' along T'
    Eigen::VectorXd Q;            // point of T above Q' (full coordinates)
    Eigen::VectorXd Q_s;          // dQ/ds
    Eigen::VectorXd grad_s;       // ds/dP (zero beyond the ends of T)
    int piece = 0;
    int blends_searched = 0;      // blends not left out by their bounding ball
  };
  Projection project(const Eigen::VectorXd& P) const;
  double value(const Eigen::VectorXd& P) const;
  Eigen::VectorXd gradient(const Eigen::VectorXd& P) const;  // in coordinates
  Eigen::VectorXd pointAt(double s) const;                   // T (full coordinates) at arc length s
  double length() const { return length_; }
  double k() const { return k_; }
  // Arc lengths at which T' passes from a segment to a blend or back.
  std::vector<double> junctions() const;
  // The largest distance between T' and the polyline of the key postures.
  double maxDeviation() const;

  // PostureCost: f_T at the kinematics' configuration; gradient in the tangent space.
  double evaluate(const Kinematics& kin, Eigen::Ref<Eigen::VectorXd> grad) const override;
  Eigen::VectorXd diagonalHessian(int tangent_size) const override;

 private:
  struct Piece {
    bool blend = false;
    double s0 = 0, len = 0;
    // segment: base from a to a + len * u; joints (rest) linear from ra with slope m0
    Eigen::VectorXd a, u;
    // blend: 8 control points (base) and those of its first three derivatives,
    // arc length table for the parameter
    std::vector<Eigen::VectorXd> ctrl;
    std::vector<std::vector<Eigen::VectorXd>> hodographs;  // [d]: control points of the d-th derivative
    std::vector<double> tau_table, s_table;
    // rest coordinates (joints): values and slopes at the piece's ends
    Eigen::VectorXd r0, r1, m0, m1;
    Eigen::VectorXd V;            // blend: the corner
    // blend: a ball around its control points; the curve lies in their
    // convex hull, so in the ball (project's lower bound)
    Eigen::VectorXd centre;
    double radius = 0;
  };
  double valueAndGradient(const Eigen::VectorXd& P, Eigen::VectorXd* grad) const;
  Eigen::VectorXd basePoint(const Piece& p, double tau, int derivative) const;
  static Eigen::VectorXd blendPoint(const Piece& p, double tau, int derivative);
  double arcLength(const Piece& p, double tau) const;  // from the piece start
  double tauAt(const Piece& p, double s_local) const;
  void rest(const Piece& p, double s_local, Eigen::VectorXd& r, Eigen::VectorXd& dr) const;
  std::vector<Piece> pieces_;
  double k_, tol_, length_ = 0;
  double joint_weight_ = 1.0;
  int n_ = 0;  // full coordinate size
  std::vector<Eigen::VectorXd> keys_;
};

}  // namespace acyclic
