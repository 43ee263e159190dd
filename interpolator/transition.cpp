#include "interpolator/transition.h"

#include <algorithm>
#include <cmath>
#include <functional>

#include "interpolator/time_law.h"
#include "planner/common/geometry.h"

namespace acyclic {

namespace {

bool sameContact(const ContactSpec& a, const ContactSpec& b) {
  return a.spot == b.spot && a.surface == b.surface && std::abs(a.placement.x - b.placement.x) <= 1e-3 &&
         std::abs(a.placement.y - b.placement.y) <= 1e-3 &&
         std::abs(std::remainder(a.placement.theta - b.placement.theta, 2 * M_PI)) <= M_PI / 180;  // as diffStances
}

// Contacts of `a` with no match in `b`.
std::vector<ContactSpec> missingFrom(const std::vector<ContactSpec>& a, const std::vector<ContactSpec>& b) {
  std::vector<ContactSpec> out;
  for (const auto& x : a) {
    bool found = false;
    for (const auto& y : b) found = found || sameContact(x, y);
    if (!found) out.push_back(x);
  }
  return out;
}

std::string pair(int a, int b) { return "stances " + std::to_string(a) + " -> " + std::to_string(b); }

double distance(const Configuration& a, const Configuration& b) {
  return difference(a, b).cwiseAbs().maxCoeff();
}

}  // namespace

std::string designTransitions(const Plan& plan, const std::vector<int>& kept, std::vector<TransitionDesign>& out) {
  out.clear();
  for (std::size_t i = 0; i + 1 < kept.size(); ++i) {
    const int a = kept[i], b = kept[i + 1];
    const auto A = plan.stances[a].specs(), B = plan.stances[b].specs();
    const auto added = missingFrom(B, A), removed = missingFrom(A, B);
    TransitionDesign d;
    d.from = a;
    d.to = b;
    if (added.empty() && removed.empty()) {
      if (A.size() != B.size()) return pair(a, b) + ": a contact appears twice";
      // Same contacts (or one support flipped): hold them all, supporting where either stance does.
      int flipped = 0;
      d.kind = TransitionDesign::Kind::Fixed;
      d.motion_contacts = A;
      d.motion_stance = a;
      for (auto& c : d.motion_contacts)
        for (const auto& y : B)
          if (sameContact(c, y) && y.supporting != c.supporting) {
            ++flipped;
            c.supporting = true;
            d.motion_stance = y.supporting ? b : a;
          }
      if (flipped > 1) return pair(a, b) + ": " + std::to_string(flipped) + " contacts change support at once";
    } else if (added.size() + removed.size() == 1) {
      d.kind = TransitionDesign::Kind::Move;
      if (removed.size() == 1) {
        d.leave = removed[0];
        d.spot = removed[0].spot;
        d.motion_contacts = B;
        d.motion_stance = b;
        // Removed, then added again for the same spot: one motion from the old contact to the new.
        if (i + 2 < kept.size()) {
          const int c = kept[i + 2];
          const auto C = plan.stances[c].specs();
          const auto added2 = missingFrom(C, B), removed2 = missingFrom(B, C);
          if (removed2.empty() && added2.size() == 1 && added2[0].spot == d.spot) {
            d.arrive = added2[0];
            d.to = c;
            ++i;
          }
        }
      } else {
        d.arrive = added[0];
        d.spot = added[0].spot;
        d.motion_contacts = A;
        d.motion_stance = a;
      }
    } else {
      return pair(a, b) + ": " + std::to_string(added.size()) + " contacts added and " +
             std::to_string(removed.size()) + " removed; a transition changes one contact";
    }
    bool supported = false;
    for (const auto& c : d.motion_contacts) supported = supported || c.supporting;
    if (!supported) return pair(a, b) + ": no supporting contact during the motion";
    out.push_back(d);
  }
  return "";
}

struct TransitionSolver::Attempt {
  const std::atomic<bool>* cancel = nullptr;
  long posture_calls = 0;
  double posture_seconds = 0;
  int refinements = 0;
  std::string reason;
  bool cancelled = false;
  std::vector<MotionPiece> pieces;
};

TransitionSolver::TransitionSolver(const Scenario& sc, TransitionOptions options)
    : sc_(sc), opt_(std::move(options)), generator_(sc.robot, sc.scene, opt_.posture), checker_(sc.robot, sc.scene),
      kin_(sc.robot) {
  if (opt_.steps < 1) throw std::invalid_argument("steps must be at least 1");
}

namespace {

// A sequence of knots with their path parameters, refined between neighbours
// whose middle fails the validity check. `solveAt(param, guess)` returns a
// knot or nothing (with the reason set).
struct Refiner {
  ValidityChecker& checker;
  const std::vector<ContactSpec>& contacts;
  std::function<std::optional<Configuration>(double, const Configuration&)> solveAt;
  int depth;
  int* refinements;
  std::string* reason;

  bool midValid(const Configuration& a, const Configuration& b, std::string* why) {
    const ValidityReport r = checker.checkPosture(lerp(a, b, 0.5), contacts);
    if (r.valid()) return true;
    for (const auto& p : r.parts)
      if (p.checked && !p.ok()) *why = p.name + ": " + p.violations[0];
    return false;
  }

  // Appends the refined knots strictly after (pa, a) up to and including (pb, b).
  bool segment(double pa, const Configuration& a, double pb, const Configuration& b, int level,
               std::vector<Configuration>& out) {
    std::string why;
    if (midValid(a, b, &why)) {
      out.push_back(b);
      return true;
    }
    if (level >= depth) {
      *reason = "between two knots, after " + std::to_string(depth) + " refinements: " + why;
      return false;
    }
    const double pm = 0.5 * (pa + pb);
    const std::optional<Configuration> m = solveAt(pm, lerp(a, b, 0.5));
    if (!m) return false;
    ++*refinements;
    return segment(pa, a, pm, *m, level + 1, out) && segment(pm, *m, pb, b, level + 1, out);
  }

  bool refine(const std::vector<double>& params, const std::vector<Configuration>& knots,
              std::vector<Configuration>& out) {
    out = {knots.front()};
    for (std::size_t k = 0; k + 1 < knots.size(); ++k)
      if (!segment(params[k], knots[k], params[k + 1], knots[k + 1], 0, out)) return false;
    return true;
  }
};

}  // namespace

TransitionOutcome TransitionSolver::solve(const Plan& plan, const TransitionDesign& d, const std::atomic<bool>* cancel) {
  TransitionOutcome out;
  Attempt at;
  at.cancel = cancel;
  if (d.kind == TransitionDesign::Kind::Fixed) {
    out.ok = solveFixed(plan, d, at);
  } else {
    // The body's ends: its pose in each witness, and the surface normal where it leaves or reaches one.
    BodyPathEnd e0, e1;
    kin_.setConfiguration(plan.stances[d.from].configuration);
    e0.pose = kin_.spotPose(d.spot);
    kin_.setConfiguration(plan.stances[d.to].configuration);
    e1.pose = kin_.spotPose(d.spot);
    if (d.leave) e0.normal = sc_.scene->surfaces()[d.leave->surface].frame.linear().col(2);
    if (d.arrive) e1.normal = sc_.scene->surfaces()[d.arrive->surface].frame.linear().col(2);
    const BodyPath path(e0, e1, opt_.lift);
    std::string reasons;
    for (int attempt = 0; attempt <= opt_.repair_attempts && !at.cancelled; ++attempt) {
      at.pieces.clear();
      const double h = attempt * opt_.repair_step;
      const BodyPath p = attempt == 0 ? path : path.raised(h);
      if (solveMove(plan, d, p, at)) {
        out.ok = true;
        out.repaired = attempt > 0;
        break;
      }
      char buf[64];
      std::snprintf(buf, sizeof buf, attempt == 0 ? "as planned: " : "via-point %.2f m up: ", h);
      reasons += (reasons.empty() ? "" : "; ") + std::string(buf) + at.reason;
    }
    if (!out.ok && !at.cancelled)
      at.reason = "the moving body's path (" + sc_.robot->spots()[d.spot].name + ") cannot be repaired: " + reasons;
  }
  out.cancelled = at.cancelled;
  out.reason = at.cancelled ? "cancelled" : at.reason;
  out.posture_calls = at.posture_calls;
  out.posture_seconds = at.posture_seconds;
  out.refinements = at.refinements;
  out.pieces = std::move(at.pieces);
  if (!out.ok) out.pieces.clear();
  return out;
}

bool TransitionSolver::solveFixed(const Plan& plan, const TransitionDesign& d, Attempt& at) {
  const Configuration& q0 = plan.stances[d.from].configuration;
  const Configuration& q1 = plan.stances[d.to].configuration;
  if (distance(q0, q1) < 1e-9) return true;  // the witnesses coincide: only the contacts' support changes
  auto solveAt = [&](double alpha, const Configuration& guess) -> std::optional<Configuration> {
    if (at.cancel && at.cancel->load()) {
      at.cancelled = true;
      at.reason = "cancelled";
      return std::nullopt;
    }
    PostureRequest r;
    r.contacts = d.motion_contacts;
    r.initial_guess = guess;
    const Configuration ref = lerp(q0, q1, alpha);
    r.cost = std::make_shared<ReferencePostureCost>(ref);
    PostureResult res = generator_.solve(r);
    ++at.posture_calls;
    at.posture_seconds += res.seconds;
    if (!res.success()) {  // from the interpolated witnesses instead of the previous step
      r.initial_guess = ref;
      res = generator_.solve(r);
      ++at.posture_calls;
      at.posture_seconds += res.seconds;
    }
    if (!res.success()) {
      at.reason = "no posture at step " + std::to_string(alpha) + ": " + res.reason;
      return std::nullopt;
    }
    return res.configuration;
  };
  // A small motion (a weight shift) needs fewer steps than n: one per
  // fixed_step of its largest coordinate change, n at most.
  int steps = opt_.steps;
  if (opt_.fixed_step > 0)
    steps = std::clamp(static_cast<int>(std::ceil(distance(q0, q1) / opt_.fixed_step)), 1, opt_.steps);
  std::vector<double> params{0.0};
  std::vector<Configuration> knots{q0};
  for (int i = 1; i < steps; ++i) {
    const double alpha = static_cast<double>(i) / steps;
    const auto k = solveAt(alpha, knots.back());
    if (!k) return false;
    params.push_back(alpha);
    knots.push_back(*k);
  }
  params.push_back(1.0);
  knots.push_back(q1);
  MotionPiece piece;
  piece.contacts = d.motion_contacts;
  piece.stance = d.motion_stance;
  Refiner ref{checker_, piece.contacts, solveAt, opt_.refine_depth, &at.refinements, &at.reason};
  if (!ref.refine(params, knots, piece.knots)) return false;
  at.pieces.push_back(std::move(piece));
  return true;
}

bool TransitionSolver::solveMove(const Plan& plan, const TransitionDesign& d, const BodyPath& path, Attempt& at) {
  const Configuration& q0 = plan.stances[d.from].configuration;
  const Configuration& q1 = plan.stances[d.to].configuration;
  std::vector<int> touch;
  if (d.leave) touch.push_back(sc_.scene->surfaces()[d.leave->surface].obstacle);
  if (d.arrive) touch.push_back(sc_.scene->surfaces()[d.arrive->surface].obstacle);
  auto solveAt = [&](double s, const Configuration& guess) -> std::optional<Configuration> {
    if (at.cancel && at.cancel->load()) {
      at.cancelled = true;
      at.reason = "cancelled";
      return std::nullopt;
    }
    PostureRequest r;
    r.contacts = d.motion_contacts;
    PoseTarget t;
    t.spot = d.spot;
    t.pose = path.pose(s);
    t.touch_obstacles = touch;
    t.orientation_tolerance = path.straightAt(s) ? 0.0 : opt_.air_orientation_tolerance;
    r.pose_target = t;
    r.initial_guess = guess;
    const Configuration ref = lerp(q0, q1, s);
    r.cost = std::make_shared<ReferencePostureCost>(ref);
    PostureResult res = generator_.solve(r);
    ++at.posture_calls;
    at.posture_seconds += res.seconds;
    if (!res.success()) {
      r.initial_guess = ref;
      res = generator_.solve(r);
      ++at.posture_calls;
      at.posture_seconds += res.seconds;
    }
    if (!res.success()) {
      char buf[64];
      std::snprintf(buf, sizeof buf, "no posture at path parameter %.3f: ", s);
      at.reason = buf + res.reason;
      return std::nullopt;
    }
    return res.configuration;
  };
  const double s0 = path.leaveParameter(opt_.touch_clearance), s1 = path.arriveParameter(opt_.touch_clearance);
  // The knots in the air (the first and last only touch their surfaces when the body has none to leave or reach).
  std::vector<double> params;
  std::vector<Configuration> knots;
  for (int i = 0; i <= opt_.steps; ++i) {
    const double s = s0 + (s1 - s0) * i / opt_.steps;
    if (i == 0 && !d.leave) {
      knots.push_back(q0);
    } else if (i == opt_.steps && !d.arrive) {
      knots.push_back(q1);
    } else {
      const auto k = solveAt(s, knots.empty() ? q0 : knots.back());
      if (!k) return false;
      knots.push_back(*k);
    }
    params.push_back(s);
  }
  auto addPiece = [&](std::vector<double> ps, std::vector<Configuration> ks, const std::vector<ContactSpec>& contacts,
                      int stance) {
    MotionPiece piece;
    piece.contacts = contacts;
    piece.stance = stance;
    Refiner ref{checker_, piece.contacts, solveAt, opt_.refine_depth, &at.refinements, &at.reason};
    if (!ref.refine(ps, ks, piece.knots)) return false;
    at.pieces.push_back(std::move(piece));
    return true;
  };
  if (d.leave && !addPiece({0.0, s0}, {q0, knots.front()}, plan.stances[d.from].specs(), d.from)) return false;
  if (!addPiece(params, knots, d.motion_contacts, d.motion_stance)) return false;
  if (d.arrive && !addPiece({s1, 1.0}, {knots.back(), q1}, plan.stances[d.to].specs(), d.to)) return false;
  return true;
}

}  // namespace acyclic
