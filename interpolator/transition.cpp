#include "interpolator/transition.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <set>

#include "interpolator/body_path_planner.h"
#include "interpolator/limb_path_planner.h"
#include "interpolator/time_law.h"
#include "planner/common/geometry.h"
#include "planner/collision/collision_model.h"

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

// A body pivoting off its surface, where the contact changes: clear of the
// surface by kTouchMargin, its spot origin within kTouchAcross (in the plane)
// and kTouchAlong (along the normal) of the touch point, its normal within
// kTouchTilt (a bound on each orientation row): 0.73 mm and 0.81 degree at
// worst, inside the contract's 1 mm and 1 degree.
constexpr double kTouchMargin = 5e-5, kTouchAcross = 3e-4, kTouchAlong = 1e-4, kTouchTilt = 0.01;

// A body hanging from a contact of its own limb (a foot whose thigh rests on
// a seat) swings on an arc about the held link: it cannot rise straight off
// its surface, it scuffs along it first (about 5.7 times as far as it rises,
// a shank 10 degrees from vertical). It changes phase when it is
// kPendulumTouch off the surface, within kPendulumAcross of the touch point
// (0.86 mm at worst, inside the contract's 1 mm), and in between the knots
// follow the witnesses' interpolation with its position free, clear of the
// surface.
constexpr double kPendulumTouch = 1.5e-4, kPendulumAcross = 8.5e-4;
// A body free in the air on its limb's planned joints (solve(), last stage)
// need not scuff: it touches within kFreeBodyAcross on each axis across, 0.85
// mm on the diagonal. With kPendulumAcross on both axes a wrist came down on
// a table 1.09 mm from its contact point, outside the contract, and the piece
// after it failed on its first knot, which no refinement moves.
constexpr double kFreeBodyAcross = 6e-4;

std::string pair(int a, int b) { return "stances " + std::to_string(a) + " -> " + std::to_string(b); }

double distance(const Configuration& a, const Configuration& b) {
  return difference(a, b).cwiseAbs().maxCoeff();
}

}  // namespace

std::string designTransitions(const Plan& plan, std::vector<TransitionDesign>& out) {
  std::vector<int> kept(plan.stances.size());
  for (std::size_t k = 0; k < kept.size(); ++k) kept[k] = static_cast<int>(k);
  return designTransitions(plan, kept, out);
}

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
  // The robot links the failing check named (collisions, contacts), when the
  // attempt failed on a check and not on a posture the generator could not
  // find; none when a failing part names no link (equilibrium, joint limits).
  std::vector<int> failed_links;
  // Set when the attempt failed on a segment that no halving shortened (a
  // jump between two branches of the inverse kinematics), which bridges close.
  bool jumped = false;
  int attempts = 0;  // solveFixed's and solveMove's calls
  bool cancelled = false;
  std::vector<MotionPiece> pieces;
  // The moving body off its path, as a pendulum's (solve(), last stage).
  bool free_body = false;
  // Jumps between branches bridged (TransitionOptions::bridge_jumps).
  bool bridges = false;
};

struct TransitionSolver::FreeEnd {
  int spot;
  BodyPath path;
  // The limb's joints planned around what their interpolation sweeps it
  // through (limb_path_planner.h); then the knots take them as reference
  // instead of pulling the end along `path`.
  std::optional<LimbJointPath> joints;
};

TransitionSolver::TransitionSolver(const Scenario& sc, TransitionOptions options)
    : sc_(sc), opt_(std::move(options)), generator_(sc.robot, sc.scene, opt_.posture), checker_(sc.robot, sc.scene),
      kin_(sc.robot), collisions_(sc.robot, sc.scene) {
  if (opt_.steps < 1) throw std::invalid_argument("steps must be at least 1");
  if (!(opt_.wide_clearance >= 0)) throw std::invalid_argument("wide_clearance must be non-negative");
  if (opt_.wide_clearance > 0) {
    PostureGeneratorOptions wide = opt_.posture;
    wide.problem.collision_margin += opt_.wide_clearance;
    wide_generator_.emplace(sc.robot, sc.scene, wide);
  }
  // Thousands of checks in sequence, for their verdict only: pairs that
  // cannot be within 1 mm are not measured, the equilibrium LPs start from
  // the previous check's basis, and the previous check's forces, rebalanced,
  // decide most samples without an LP (validity.h).
  checker_.checkVerdictsInSequence();
  checker_.setForcesReused(true);
}

namespace {

// A sequence of knots with their path parameters, refined between neighbours
// whose middle fails the validity check. `solveAt(param, guess, bridge)`
// returns a knot or nothing (with the reason set): near the witnesses'
// interpolation at param, or with `bridge` near `guess` alone.
struct Refiner {
  ValidityChecker& checker;
  const std::vector<ContactSpec>& contacts;
  std::function<std::optional<Configuration>(double, const Configuration&, bool)> solveAt;
  int depth;
  int* refinements;
  std::string* reason;

  int checks;  // points checked inside each segment, equally spaced
  // Jumps between branches bridged: a segment that no halving along the path
  // shortens gets knots projected from the straight line between its two
  // knots (solveAt's `bridge`), halved while they converge, to kMaxBridgeDepth.
  bool bridges = false;
  // Per segment of the refined knots: whether it lies on a bridge (its
  // refinements in verify() are bridge knots too).
  std::vector<bool> bridged;
  // Set with `reason` when a check fails: the links it names (CheckPart::links).
  std::vector<int>* failed_links;
  // Set with `reason` when a segment fails unbridged and its last halving did
  // not converge (what bridges would have taken on).
  bool* jumped;

  // The failing parts of a report: the last one's first violation, and the
  // links they name; none if a failing part names none (an equilibrium lost
  // is not the free limbs' alone, whatever collides with it).
  static void failure(const ValidityReport& r, std::string* why, std::vector<int>* links) {
    links->clear();
    bool unplaced = false;
    for (const auto& p : r.parts)
      if (p.checked && !p.ok()) {
        *why = p.name + ": " + p.violations[0];
        unplaced = unplaced || p.links.empty();
        links->insert(links->end(), p.links.begin(), p.links.end());
      }
    if (unplaced) links->clear();
  }

  bool midValid(const Configuration& a, const Configuration& b, std::string* why, std::vector<int>* links) {
    for (int i = 1; i <= checks; ++i) {
      const ValidityReport r = checker.checkPosture(lerp(a, b, static_cast<double>(i) / (checks + 1)), contacts);
      if (r.valid()) continue;
      failure(r, why, links);
      return false;
    }
    return true;
  }

  // Appends the refined knots strictly after (pa, a) up to and including (pb, b).
  // `converging`: the halving that made this segment split its parent in two (halved()).
  bool segment(double pa, const Configuration& a, double pb, const Configuration& b, int level,
               std::vector<Configuration>& out, std::vector<double>& out_params, bool converging = false,
               bool bridging = false) {
    std::string why;
    std::vector<int> links;
    if (midValid(a, b, &why, &links)) {
      out.push_back(b);
      out_params.push_back(pb);
      bridged.push_back(bridging);
      return true;
    }
    // Past `depth` halvings, only while the knots converge (converging()):
    // the drift of a held contact between two knots far apart, which each
    // halving divides by four, wants a few more; a jump between two branches
    // of the inverse kinematics, which no halving shortens, does not, unless
    // bridged: then its knots come from the straight line between the two
    // knots, and are halved while they converge.
    if (level >= depth && !(level < kMaxDepth && converging)) {
      if (!bridges || level >= kMaxBridgeDepth || (bridging && !converging)) {
        *reason = "between two knots, after " + std::to_string(level) + " refinements" +
                  (bridging ? " (bridged)" : "") + ": " + why;
        *failed_links = std::move(links);
        *jumped = !bridges && level > 0 && !converging;
        return false;
      }
      bridging = true;
    }
    const double pm = 0.5 * (pa + pb);
    const std::optional<Configuration> m = solveAt(pm, lerp(a, b, 0.5), bridging);
    if (!m) return false;
    ++*refinements;
    const bool halves = halved(a, *m, b);
    return segment(pa, a, pm, *m, level + 1, out, out_params, halves, bridging) &&
           segment(pm, *m, pb, b, level + 1, out, out_params, halves, bridging);
  }

  // Whether the knot found in the middle splits the segment into two shorter
  // ones (each at most kConverging of the whole, in the largest coordinate):
  // the knots lie on one continuous branch.
  static bool halved(const Configuration& a, const Configuration& m, const Configuration& b) {
    const double whole = difference(a, b).cwiseAbs().maxCoeff();
    return std::max(difference(a, m).cwiseAbs().maxCoeff(), difference(m, b).cwiseAbs().maxCoeff()) <=
           kConverging * whole;
  }
  static constexpr int kMaxDepth = 7;
  static constexpr int kMaxBridgeDepth = 12;
  static constexpr double kConverging = 0.75;

  bool refine(const std::vector<double>& params, const std::vector<Configuration>& knots,
              std::vector<Configuration>& out, std::vector<double>& out_params) {
    out = {knots.front()};
    out_params = {params.front()};
    bridged.clear();
    for (std::size_t k = 0; k + 1 < knots.size(); ++k)
      if (!segment(params[k], knots[k], params[k + 1], knots[k + 1], 0, out, out_params)) return false;
    return true;
  }

  // Every sample the time law makes of these knots, checked; the segment of a
  // failing sample gets a knot in its middle, up to `depth` rounds. This is
  // what makes every output sample valid, not only the checked points.
  bool verify(std::vector<double>& params, std::vector<Configuration>& knots, const TimeLawOptions& tl,
              const RobotModel& robot, Kinematics& kin) {
    for (int round = 0;; ++round) {
      const TimedPiece tp(knots, robot, kin, tl);
      std::set<int> bad;
      std::string why;
      std::vector<int> links;
      for (int i = 0; i <= tp.steps(); ++i) {
        const int seg = tp.segmentAt(i * tl.dt);
        if (bad.count(seg)) continue;
        const ValidityReport r = checker.checkPosture(tp.at(i * tl.dt), contacts);
        if (r.valid()) continue;
        bad.insert(seg);
        failure(r, &why, &links);
      }
      if (bad.empty()) return true;
      // A sample's violation shrinks with its segment (a finger grazing the
      // table top by 0.08 mm): a few more rounds than `depth`, which cost
      // one knot per failing segment.
      if (round >= std::max(depth, kMaxDepth)) {
        *reason = "a sample between two knots, after " + std::to_string(round) + " rounds of refinement: " + why;
        *failed_links = std::move(links);
        return false;
      }
      for (auto it = bad.rbegin(); it != bad.rend(); ++it) {  // from the last, so that indices stay valid
        const int k = *it;
        const double pm = 0.5 * (params[k] + params[k + 1]);
        const bool on_bridge = bridged[k];
        const std::optional<Configuration> m = solveAt(pm, lerp(knots[k], knots[k + 1], 0.5), on_bridge);
        if (!m) return false;
        ++*refinements;
        knots.insert(knots.begin() + k + 1, *m);
        params.insert(params.begin() + k + 1, pm);
        bridged.insert(bridged.begin() + k + 1, on_bridge);
      }
    }
  }
};

}  // namespace

std::string TransitionSolver::check(const Plan& plan, const TransitionDesign& d, const TransitionOutcome& o) {
  const int n = static_cast<int>(plan.stances.size());
  if (d.from < 0 || d.to <= d.from || d.to >= n) return "its stances are not the plan's";
  if (!o.ok) return "it is not a success";
  const Configuration& start = plan.stances[static_cast<std::size_t>(d.from)].configuration;
  const Configuration& end = plan.stances[static_cast<std::size_t>(d.to)].configuration;
  // A knot that starts or ends a transition is its witness, copied: the
  // same to within rounding.
  auto same = [](const Configuration& a, const Configuration& b) { return distance(a, b) <= 1e-9; };
  if (o.pieces.empty())
    return same(start, end) ? "" : "it has no motion between witnesses that differ";
  const std::size_t joints = sc_.robot->numJoints();
  const Configuration* last = &start;
  for (std::size_t p = 0; p < o.pieces.size(); ++p) {
    const MotionPiece& piece = o.pieces[p];
    const std::string where = "piece " + std::to_string(p) + ": ";
    if (piece.knots.empty()) return where + "no knots";
    for (const Configuration& q : piece.knots)
      if (static_cast<std::size_t>(q.joints.size()) != joints || !q.base_position.allFinite() ||
          !q.base_orientation.coeffs().allFinite() || !q.joints.allFinite() ||
          std::abs(q.base_orientation.norm() - 1) > 1e-6)
        return where + "a knot is not a configuration of the robot";
    if (!same(piece.knots.front(), *last))
      return where + (p == 0 ? "it does not start at stance " + std::to_string(d.from) + "'s witness"
                             : "it does not start where the previous piece ended");
    last = &piece.knots.back();
    for (const ContactSpec& c : piece.contacts) {
      bool known = false;
      for (int k = d.from; k <= d.to && !known; ++k)
        for (const PlanContact& pc : plan.stances[static_cast<std::size_t>(k)].contacts)
          known = known || (pc.spec.spot == c.spot && pc.spec.surface == c.surface &&
                            pc.spec.placement.x == c.placement.x && pc.spec.placement.y == c.placement.y &&
                            pc.spec.placement.theta == c.placement.theta);
      if (!known) return where + "it holds a contact that none of its stances holds";
    }
    const TimedPiece tp(piece.knots, *sc_.robot, kin_, opt_.timing);
    for (int i = 0; i <= tp.steps(); ++i) {
      const ValidityReport r = checker_.checkPosture(tp.at(i * opt_.timing.dt), piece.contacts);
      if (r.valid()) continue;
      std::string why;
      std::vector<int> links;
      Refiner::failure(r, &why, &links);  // as the solver's own samples say it
      return where + "sample " + std::to_string(i) + " is not valid: " + why;
    }
  }
  if (!same(*last, end)) return "it does not end at stance " + std::to_string(d.to) + "'s witness";
  return "";
}

TransitionOutcome TransitionSolver::solve(const Plan& plan, const TransitionDesign& d, const std::atomic<bool>* cancel) {
  const auto t0 = std::chrono::steady_clock::now();
  TransitionOutcome out;
  Attempt at;
  at.cancel = cancel;
  planned_limbs_.clear();
  // A body that only reaches (or only leaves) a surface and already touches
  // it where the other witness has it (a wrist laid on the table beside the
  // forearm already there, as the witness placed it) does not move: the
  // transition holds the other stance's contacts, that one touching, as a
  // support flip does (a Move's path of zero length leaves the posture
  // generator an over-determined body).
  const std::optional<TransitionDesign> still = stillBody(plan, d);
  const TransitionDesign& fd = still ? *still : d;
  out.still = still.has_value();
  if (fd.kind == TransitionDesign::Kind::Fixed) {
    // First the knots nearest the witnesses' interpolation. When it cuts
    // through an obstacle the knots slide along it at the collision margin,
    // and their optimum can jump from one branch to another between two steps
    // (a trunk along a table's edge, a knee by 0.06 rad), a jump no refinement
    // makes valid: then each knot also near its neighbour, as a Move's.
    // Last, both again with more clearance for the knots (wide_clearance).
    // Then, a free limb (an arm) that the witnesses' interpolation sweeps
    // through an obstacle on its joints planned around it (limb_path_planner.h),
    // with the knots near the witnesses', then each also near its neighbour.
    std::string reasons;
    std::vector<LimbJointPath> limbs;
    bool limbs_planned = false;
    // Then the knots as planned with each jump between two branches bridged.
    const char* what[] = {"as planned", "each knot near its neighbour too", "with more clearance",
                          "with more clearance, each knot near its neighbour", "with the free limbs' joints planned",
                          "with the free limbs' joints planned, each knot near its neighbour",
                          "with bridges across branch jumps"};
    constexpr int kBridges = 6, kLimbsPlanned = 4;
    std::vector<int> order{0, 1, 2, 3, 4, 5};
    if (opt_.bridge_jumps) order.push_back(kBridges);
    for (std::size_t k = 0; k < order.size() && !out.ok && !at.cancelled; ++k) {
      const int attempt = order[k];
      const bool follow = attempt % 2 == 1, wide = attempt == 2 || attempt == 3,
                 planned = attempt == 4 || attempt == 5, bridged = attempt == kBridges;
      if (wide && !wide_generator_) continue;
      if (planned && !limbs_planned) {
        limbs_planned = true;
        if (opt_.free_limb_paths && opt_.limb_joint_paths) {
          const Configuration& q0 = plan.stances[fd.from].configuration;
          const Configuration& q1 = plan.stances[fd.to].configuration;
          for (int e : freeLimbEnds(fd))
            if (auto l = plannedLimbJoints(q0, q1, sc_.robot->spotLimbRootJoint(e))) limbs.push_back(std::move(*l));
        }
      }
      if (planned && limbs.empty()) continue;
      at.pieces.clear();
      at.bridges = bridged;
      out.ok = solveFixed(plan, fd, follow, wide, planned ? limbs : std::vector<LimbJointPath>{}, at);
      at.bridges = false;
      out.repaired = out.ok && attempt > 0;
      if (out.ok) out.how = what[attempt];
      if (!out.ok && !at.cancelled) {
        reasons += (reasons.empty() ? "" : "; ") + (attempt > 0 ? std::string(what[attempt]) + ": " : "") + at.reason;
        // A first failure that says which repair it needs gets it next: a
        // collision of the free limbs alone (an arm the witnesses'
        // interpolation sweeps through the table, its knots jumping across
        // the edge) their planned joints, before the attempts that change the
        // knots of the whole body; a jump between branches that drags or
        // presses a held contact alone (a palm 3 mm off its point between two
        // knots) its bridges.
        if (attempt == 0 && opt_.order_by_failure) {
          std::vector<int> next{0};
          const NamedRepair named = namedRepair(fd, at);
          if (named == NamedRepair::FreeLimbs && opt_.free_limb_paths && opt_.limb_joint_paths)
            next.push_back(kLimbsPlanned);
          else if (named == NamedRepair::Bridges)
            next.push_back(kBridges);
          for (int a : order)
            if (std::find(next.begin(), next.end(), a) == next.end()) next.push_back(a);
          order = std::move(next);
        }
      }
    }
    if (!out.ok && !at.cancelled) at.reason = reasons;
  } else {
    // The body's ends: its pose in each witness, and the surface normal where it leaves or reaches one.
    BodyPathEnd e0, e1;
    kin_.setConfiguration(plan.stances[d.from].configuration);
    e0.pose = kin_.spotPose(d.spot);
    kin_.setConfiguration(plan.stances[d.to].configuration);
    e1.pose = kin_.spotPose(d.spot);
    if (d.leave) e0.normal = sc_.scene->surfaces()[d.leave->surface].frame.linear().col(2);
    if (d.arrive) e1.normal = sc_.scene->surfaces()[d.arrive->surface].frame.linear().col(2);
    // A body that only leaves (or only reaches) a surface and is, in the other
    // witness, already less than the lift above it rises no higher than that:
    // a thigh leaving the seat with its foot planted cannot rise 3 cm.
    double lift = opt_.lift;
    auto heightOver = [](const BodyPathEnd& on, const BodyPathEnd& other) {
      return on.normal->dot(other.pose.translation() - on.pose.translation());
    };
    const double h = d.leave && !d.arrive ? heightOver(e0, e1) : d.arrive && !d.leave ? heightOver(e1, e0) : -1;
    if (h > 0 && h < lift) lift = std::max(h, 2 * opt_.touch_clearance);
    if (hangsFromItsLimb(d)) lift = 2 * kPendulumTouch;
    const BodyPath path(e0, e1, lift);
    // The links held on their contacts during the motion, where the first witness has them.
    std::vector<PlacedShape> held;
    kin_.setConfiguration(plan.stances[d.from].configuration);
    for (const auto& c : d.motion_contacts) {
      const int link = sc_.robot->spots()[c.spot].link;
      if (link == sc_.robot->spots()[d.spot].link) continue;
      for (const auto& shape : sc_.robot->links()[link].shapes) held.push_back({&shape, kin_.linkPose(link) * shape.pose});
    }
    std::string reasons;
    // The body's path planned with OMPL, once, when the splines have failed.
    std::optional<BodyPathPlan> planned;
    // One attempt on the body's path: as planned (attempt 0), or repaired.
    auto tryAttempt = [&](const std::vector<FreeEnd>* free, const std::string& label, int attempt) {
      at.pieces.clear();
      const double h = attempt * opt_.repair_step;
      // A repair: the bridge raised by h, or a detour h to either side (the
      // bridge moved sideways, or one via-point a quarter, half or three
      // quarters of the way), whichever carries the body farthest from the
      // obstacles and the held links (the raised one on a tie). Raising alone
      // does not get a foot past a post; a foot between a post and the other
      // foot has to step sideways first, then back.
      BodyPath p = path;
      std::string how = "as planned";
      if (attempt > 0) {
        double best = -std::numeric_limits<double>::infinity();
        auto consider = [&](BodyPath candidate, std::string label) {
          const double c = sweepClearance(candidate, *sc_.robot, *sc_.scene, d.spot, held);
          if (c > best + 1e-9) best = c, p = std::move(candidate), how = std::move(label);
        };
        char buf[96];
        std::snprintf(buf, sizeof buf, "via-point %.2f m up", h);
        consider(path.raised(h), buf);
        for (double side : {1.0, -1.0}) {
          const char* name = side > 0 ? "left" : "right";
          std::snprintf(buf, sizeof buf, "detour %.2f m %s", h, name);
          consider(path.bridged(0, side * h), buf);
          for (double f : {0.25, 0.5, 0.75}) {
            std::snprintf(buf, sizeof buf, "detour %.2f m %s at %.2f of the way", h, name, f);
            consider(path.detoured(f, side * h), buf);
          }
        }
      }
      if (solveMove(plan, d, p, opt_.air_orientation_tolerance, free, at)) {
        out.repaired = attempt > 0 || free;
        out.how = label + how;
        return true;
      }
      reasons += (reasons.empty() ? "" : "; ") + label + how + ": " + at.reason;
      return false;
    };
    // Attempts `first` to the last, then the body's path planned with OMPL.
    auto tryPaths = [&](const std::vector<FreeEnd>* free, const std::string& label, int first) {
      for (int attempt = first; attempt <= opt_.repair_attempts && !at.cancelled; ++attempt)
        if (tryAttempt(free, label, attempt)) return true;
      // Last, the body's path planned with OMPL: through a gap no spline
      // passes, its orientation planned with it and followed closely (the
      // orientation left free, the knots turn the body one way, then the
      // other). The body passes every link outside its own limb where the
      // first witness has them: the other foot, and the shank above it that a
      // foot stepping over that foot would strike.
      if (at.cancelled || opt_.repair_attempts == 0 || !opt_.plan_body_path) return false;
      at.pieces.clear();
      if (!planned)
        planned = planBodyPath(path, *sc_.robot, *sc_.scene, d.spot, outsideLimb(plan.stances[d.from].configuration, d.spot));
      if (!planned->path) {
        reasons += "; " + label + planned->reason;
        return false;
      }
      if (solveMove(plan, d, *planned->path, opt_.planned_orientation_tolerance, free, at)) {
        out.repaired = true;
        out.how = label + "a path planned by OMPL";
        return true;
      }
      reasons += "; " + label + "a path planned by OMPL through " + std::to_string(planned->path->vias().size()) +
                 " waypoints: " + at.reason;
      return false;
    };
    // The stages, each its attempts: the body's path alone; then with the
    // free limbs on paths of their own (freeEnds: a free foot that the
    // witnesses' interpolation swings into the other foot or a chair's leg);
    // then with the joints of each free limb that their interpolation sweeps
    // through an obstacle planned (an elbow through a table's edge, which no
    // path of the hand alone keeps clear). Every attempt of every stage is
    // made until one succeeds; only their order can change, so the verdict
    // does not depend on it. The body's path as planned comes first; when it
    // fails on the free limbs alone (the free right hand through a chair's
    // back while a foot steps), the free limbs' stages are tried as planned
    // next, before the repairs of the body's path, which do not move them out
    // of the way (chair_paper's OMPL-guided plan: its 35 -> 37 went through
    // five of those, 3.3 s, before its free limbs' stage succeeded).
    const char* free_label = "with the free limbs on their own paths, ";
    const char* joints_label = "with the free limbs' joints planned, ";
    const bool free_stages = opt_.repair_attempts > 0 && opt_.free_limb_paths;
    const bool joint_stage = free_stages && opt_.limb_joint_paths;
    // Each stage's free limbs found when it is first tried (a limb with no
    // joint path costs seconds of state checks).
    std::vector<FreeEnd> free, with_joints;
    bool free_made = false, joints_made = false;
    auto freeStage = [&]() -> const std::vector<FreeEnd>& {
      if (!free_made) free = freeEnds(plan, d), free_made = true;
      return free;
    };
    auto jointStage = [&]() -> const std::vector<FreeEnd>& {
      if (!joints_made) {
        joints_made = true;
        with_joints = withPlannedJoints(plan, d, freeStage());
        if (std::none_of(with_joints.begin(), with_joints.end(), [](const FreeEnd& f) { return f.joints.has_value(); }))
          with_joints.clear();  // no limb planned: nothing this stage would change
      }
      return with_joints;
    };
    // The path as planned with each jump between two branches of the inverse
    // kinematics bridged (Refiner::bridges): a right thigh moved while the
    // left palm is held on the table, whose knots jump 0.006 apart in path
    // parameter, the palm 1.39 mm into the table between them, whatever
    // via-point or detour. Last, unless the first attempt's failure was such
    // a jump.
    bool bridges_tried = false;
    auto tryBridges = [&]() {
      bridges_tried = true;
      at.pieces.clear();
      at.bridges = true;
      const bool ok = solveMove(plan, d, path, opt_.air_orientation_tolerance, nullptr, at);
      at.bridges = false;
      if (ok) {
        out.repaired = true;
        out.how = "as planned, with bridges across branch jumps";
      } else if (!at.cancelled) {
        reasons += (reasons.empty() ? "" : "; ") + std::string("as planned, with bridges across branch jumps: ") +
                   at.reason;
      }
      return ok;
    };
    out.ok = tryAttempt(nullptr, "", 0);
    // What the first failure says it needs, before the rest in their order: a
    // jump that fails on the held contacts alone (a held palm pressed into the
    // table between two knots) is bridged next, one of the moving body (a foot
    // past a chair's leg, which a detour avoids) is not.
    const NamedRepair named = out.ok || at.cancelled ? NamedRepair::None : namedRepair(d, at);
    if (named == NamedRepair::Bridges) out.ok = tryBridges();
    const bool free_first = named == NamedRepair::FreeLimbs && free_stages;
    if (free_first) {
      if (!freeStage().empty()) out.ok = tryAttempt(&free, free_label, 0);
      if (!out.ok && !at.cancelled && joint_stage && !jointStage().empty())
        out.ok = tryAttempt(&with_joints, joints_label, 0);
    }
    const int first = free_first ? 1 : 0;
    if (!out.ok && !at.cancelled) out.ok = tryPaths(nullptr, "", 1);
    if (!out.ok && !at.cancelled && free_stages && !freeStage().empty()) out.ok = tryPaths(&free, free_label, first);
    if (!out.ok && !at.cancelled && joint_stage && !jointStage().empty())
      out.ok = tryPaths(&with_joints, joints_label, first);
    // Last, a body on a limb that holds no other contact (a forearm lifted
    // off the table, the hand beyond it free) leaves its path: held only where
    // it touches (as a foot hanging from its thigh, hangsFromItsLimb), its
    // limb's joints on their interpolation between the witnesses, or planned
    // around what that sweeps them through, the other free limbs as in the
    // stage before. A forearm's pose along a spline between two witnesses
    // that turn it about the elbow asks the shoulder for places the seated
    // trunk cannot give (a chair plan: no posture at 0.3 of the path,
    // whichever via-point).
    if (!out.ok && !at.cancelled && joint_stage && onFreeLimb(d)) {
      std::vector<FreeEnd> limbs = withPlannedJoints(plan, d, freeStage());
      const Configuration& q0 = plan.stances[d.from].configuration;
      const Configuration& q1 = plan.stances[d.to].configuration;
      const int root = sc_.robot->spotLimbRootJoint(d.spot);
      std::optional<LimbJointPath> own = plannedLimbJoints(q0, q1, root, true);
      if (!own) own = straightLimbPath(*sc_.robot, root, q0, q1);
      limbs.push_back({d.spot, BodyPath(e0, e0, 0), std::move(own)});
      at.pieces.clear();
      at.free_body = true;
      out.ok = solveMove(plan, d, BodyPath(e0, e1, 2 * kPendulumTouch), opt_.air_orientation_tolerance, &limbs, at);
      at.free_body = false;
      out.repaired = out.ok;
      if (out.ok) out.how = "the body free in the air, its limb's joints interpolated";
      if (!out.ok && !at.cancelled) reasons += "; the body free in the air, its limb's joints interpolated: " + at.reason;
    }
    // Last, the path as planned with its jumps bridged (tryBridges), unless already tried.
    if (!out.ok && !at.cancelled && opt_.bridge_jumps && !bridges_tried) out.ok = tryBridges();
    if (!out.ok && !at.cancelled)
      at.reason = "the moving body's path (" + sc_.robot->spots()[d.spot].name + ") cannot be repaired: " + reasons;
  }
  out.cancelled = at.cancelled;
  out.reason = at.cancelled ? "cancelled" : at.reason;
  out.posture_calls = at.posture_calls;
  out.posture_seconds = at.posture_seconds;
  out.refinements = at.refinements;
  out.attempts = at.attempts;
  out.pieces = std::move(at.pieces);
  if (!out.ok) out.pieces.clear();
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

bool TransitionSolver::hangsFromItsLimb(const TransitionDesign& d) const {
  if (d.kind != TransitionDesign::Kind::Move || d.spot < 0) return false;
  const RobotModel& m = *sc_.robot;
  const int link = m.spots()[d.spot].link;
  for (const auto& c : d.motion_contacts) {
    const int held = m.spots()[c.spot].link;
    if (held == link) continue;
    // The held link is an ancestor of the moving one: a joint on the way to the body hangs from it.
    for (int j : m.ancestorJoints(link))
      if (m.joints()[j].parent_link == held) return true;
  }
  return false;
}

std::optional<TransitionDesign> TransitionSolver::stillBody(const Plan& plan, const TransitionDesign& d) {
  if (d.kind != TransitionDesign::Kind::Move || d.leave.has_value() == d.arrive.has_value()) return std::nullopt;
  kin_.setConfiguration(plan.stances[d.from].configuration);
  const Eigen::Isometry3d a = kin_.spotPose(d.spot);
  kin_.setConfiguration(plan.stances[d.to].configuration);
  const Eigen::Isometry3d b = kin_.spotPose(d.spot);
  // Within the contract's contact tolerances of each other (1 mm, 1 degree).
  if ((a.translation() - b.translation()).norm() > 1e-3 ||
      Eigen::AngleAxisd(a.linear().transpose() * b.linear()).angle() > M_PI / 180)
    return std::nullopt;
  TransitionDesign f = d;
  f.kind = TransitionDesign::Kind::Fixed;
  f.motion_stance = d.arrive ? d.to : d.from;
  f.motion_contacts = plan.stances[f.motion_stance].specs();
  for (auto& c : f.motion_contacts)
    if (c.spot == d.spot) c.supporting = false;
  return f;
}

bool TransitionSolver::solveFixed(const Plan& plan, const TransitionDesign& d, bool follow, bool wide,
                                  const std::vector<LimbJointPath>& limbs, Attempt& at) {
  PostureGenerator& generator = wide ? *wide_generator_ : generator_;
  at.failed_links.clear();
  at.jumped = false;
  ++at.attempts;
  const Configuration& q0 = plan.stances[d.from].configuration;
  const Configuration& q1 = plan.stances[d.to].configuration;
  if (distance(q0, q1) < 1e-9) return true;  // the witnesses coincide: only the contacts' support changes
  auto solveAt = [&](double alpha, const Configuration& guess, bool bridge) -> std::optional<Configuration> {
    if (at.cancel && at.cancel->load()) {
      at.cancelled = true;
      at.reason = "cancelled";
      return std::nullopt;
    }
    PostureRequest r;
    r.contacts = d.motion_contacts;
    r.initial_guess = guess;
    Configuration ref = lerp(q0, q1, alpha);
    for (const auto& l : limbs) ref = l.apply(ref, alpha);
    Configuration target = ref;
    if (bridge) {
      target = guess;  // a bridge knot: the straight line between its neighbours
    } else if (follow) {
      // Planned limbs on their paths even when following the previous knot (solveMove).
      target = lerp(guess, ref, 0.5);
      for (const auto& l : limbs) target = l.apply(target, alpha);
    }
    r.cost = std::make_shared<ReferencePostureCost>(target);
    PostureResult res = generator.solve(r);
    ++at.posture_calls;
    at.posture_seconds += res.seconds;
    if (!res.success()) {  // from the interpolated witnesses instead of the previous step
      r.initial_guess = ref;
      res = generator.solve(r);
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
    const auto k = solveAt(alpha, knots.back(), false);
    if (!k) return false;
    params.push_back(alpha);
    knots.push_back(*k);
  }
  params.push_back(1.0);
  knots.push_back(q1);
  MotionPiece piece;
  piece.contacts = d.motion_contacts;
  piece.stance = d.motion_stance;
  Refiner ref{checker_, piece.contacts, solveAt, opt_.refine_depth, &at.refinements, &at.reason, opt_.segment_checks,
              at.bridges, {}, &at.failed_links, &at.jumped};
  std::vector<double> piece_params;
  if (!ref.refine(params, knots, piece.knots, piece_params)) return false;
  if (opt_.verify_samples && !ref.verify(piece_params, piece.knots, opt_.timing, *sc_.robot, kin_)) return false;
  at.pieces.push_back(std::move(piece));
  return true;
}

// The free limbs (no contact on them, and not the moving body's): each one's
// end (its most distal spot: a foot, a palm) on a path of its own from where
// the first witness has it to where the last does, straight, or planned
// around what the straight line cuts (a free foot the witnesses move from
// beside the other foot to behind it). Left to the witnesses' interpolation
// alone, in joint space, it can swing into an obstacle, slide along it from
// knot to knot, and jump past it.
std::vector<TransitionSolver::FreeEnd> TransitionSolver::freeEnds(const Plan& plan, const TransitionDesign& d) {
  const Configuration& q0 = plan.stances[d.from].configuration;
  const Configuration& q1 = plan.stances[d.to].configuration;
  const RobotModel& m = *sc_.robot;
  const std::vector<int> ends = freeLimbEnds(d);
  std::vector<FreeEnd> out;
  const BodyPathPlanOptions po;
  for (int e : ends) {
    BodyPathEnd a, b;
    kin_.setConfiguration(q0);
    a.pose = kin_.spotPose(e);
    kin_.setConfiguration(q1);
    b.pose = kin_.spotPose(e);
    BodyPath path(a, b, 0);
    const std::vector<PlacedShape> others = outsideLimb(q0, e);
    if (sweepClearance(path, m, *sc_.scene, e, others) < po.clearance) {
      BodyPathPlan planned = planBodyPath(path, m, *sc_.scene, e, others, po);
      if (planned.path) path = std::move(*planned.path);
    }
    out.push_back({e, std::move(path), std::nullopt});
  }
  return out;
}

std::vector<TransitionSolver::FreeEnd> TransitionSolver::withPlannedJoints(const Plan& plan, const TransitionDesign& d,
                                                                           std::vector<FreeEnd> out) {
  const Configuration& q0 = plan.stances[d.from].configuration;
  const Configuration& q1 = plan.stances[d.to].configuration;
  const RobotModel& m = *sc_.robot;
  for (auto& f : out) f.joints = plannedLimbJoints(q0, q1, m.spotLimbRootJoint(f.spot));
  // The joints beyond the moving body in its own limb (a hand beyond a
  // forearm that leaves the table), which its path does not hold: planned
  // the same way where their interpolation sweeps them into an obstacle.
  if (d.spot >= 0) {
    const int link = m.spots()[d.spot].link;
    for (const auto& j : m.joints()) {
      if (j.parent_link != link) continue;
      if (auto l = plannedLimbJoints(q0, q1, j.index)) {
        const BodyPathEnd here{kin_.spotPose(d.spot), std::nullopt};
        out.push_back({d.spot, BodyPath(here, here, 0), std::move(l)});
      }
    }
  }
  return out;
}

std::vector<int> TransitionSolver::freeLimbEnds(const TransitionDesign& d) const {
  const RobotModel& m = *sc_.robot;
  auto depth = [&](int spot) { return m.ancestorJoints(m.spots()[spot].link).size(); };
  std::vector<int> ends;  // per free limb, its most distal spot
  for (int i = 0; i < static_cast<int>(m.spots().size()); ++i) {
    const int root = m.spotLimbRootJoint(i);
    bool held = root < 0 || (d.spot >= 0 && root == m.spotLimbRootJoint(d.spot));
    for (const auto& c : d.motion_contacts) held = held || m.spotLimbRootJoint(c.spot) == root;
    if (held) continue;
    const auto same = std::find_if(ends.begin(), ends.end(), [&](int e) { return m.spotLimbRootJoint(e) == root; });
    if (same == ends.end())
      ends.push_back(i);
    else if (depth(i) > depth(*same))
      *same = i;
  }
  return ends;
}

// The joints themselves, where their interpolation sweeps the limb (an
// elbow, not only the end) into an obstacle or another link (within half
// the planner's clearance: the posture generator's margin is kept by knots
// that hug an obstacle, and the interpolation between them dips below it).
std::optional<LimbJointPath> TransitionSolver::plannedLimbJoints(const Configuration& q0, const Configuration& q1,
                                                                 int root, bool touching_ends) {
  auto same = [](const Configuration& a, const Configuration& b) {
    return a.base_position == b.base_position && a.base_orientation.coeffs() == b.base_orientation.coeffs() &&
           a.joints == b.joints;
  };
  for (const PlannedLimb& p : planned_limbs_)
    if (p.root == root && p.touching_ends == touching_ends && same(p.q0, q0) && same(p.q1, q1)) return p.path;
  std::optional<LimbJointPath> path = planLimbJoints(q0, q1, root, touching_ends);
  planned_limbs_.push_back({q0, q1, root, touching_ends, path});
  return path;
}

std::optional<LimbJointPath> TransitionSolver::planLimbJoints(const Configuration& q0, const Configuration& q1, int root,
                                                              bool touching_ends) {
  LimbPathPlanOptions lo;
  lo.touching_ends = touching_ends;
  if (limbSweepClearance(collisions_, kin_, root, q0, q1, lo.clearance) >= 0.5 * lo.clearance) return std::nullopt;
  // Narrower where the limb must pass a gap (a forearm between a table's
  // edge and the trunk, 5 mm from the edge in both witnesses: no path 10 mm
  // clear, one 3 mm clear); the knots keep the posture generator's margin
  // around it and every sample is checked. Then the narrow passes again with
  // ten times the states: an arm hanging behind the pelvis, swung up onto a
  // table's top past its edge, has a path 5 mm clear that RRTConnect finds
  // in 200,000 checks and not in 20,000 (chair_paper with its feet kept off
  // the seat, 160 -> 161; about 10 us a check, so this costs seconds only
  // where no path exists).
  //
  // The ten-fold budgets only for a whole limb (more than 3 joints: an arm
  // from its shoulder). A short one (a wrist beyond a moving forearm, a
  // gripper beyond a palm: s and at most 3 joints) has been explored by
  // 20,000 checks where 200,000 find nothing more: in chair_paper's two
  // shipped plans every search of one that failed at 20,000 failed again at
  // 200,000, 0.7 to 1.1 s each, 3 s of the OMPL-guided plan's 27 s.
  const double wide = lo.clearance;
  const long checks = lo.max_checks;
  const bool whole_limb = sc_.robot->jointsMovedBy(root).size() > 3;
  const std::pair<double, long> tries[] = {
      {wide, checks}, {0.005, checks}, {0.003, checks}, {0.005, 10 * checks}, {0.003, 10 * checks}};
  for (const auto& [clearance, budget] : tries) {
    if (budget > checks && !whole_limb) continue;
    lo.clearance = clearance;
    lo.max_checks = budget;
    LimbPathPlan planned = planLimbPath(collisions_, kin_, root, q0, q1, lo);
    if (planned.path) return std::move(planned.path);
  }
  return std::nullopt;
}

bool TransitionSolver::onFreeLimb(const TransitionDesign& d) const {
  if (d.kind != TransitionDesign::Kind::Move || d.spot < 0) return false;
  const RobotModel& m = *sc_.robot;
  const int root = m.spotLimbRootJoint(d.spot);
  if (root < 0) return false;
  for (const auto& c : d.motion_contacts)
    if (m.spotLimbRootJoint(c.spot) == root) return false;
  return true;
}

bool TransitionSolver::onHeldBodiesOnly(const TransitionDesign& d, const std::vector<int>& links) const {
  if (links.empty()) return false;
  const RobotModel& m = *sc_.robot;
  const int moving = d.spot >= 0 ? m.spots()[d.spot].link : -1;
  return std::all_of(links.begin(), links.end(), [&](int link) {
    return link != moving && std::any_of(d.motion_contacts.begin(), d.motion_contacts.end(),
                                         [&](const ContactSpec& c) { return m.spots()[c.spot].link == link; });
  });
}

TransitionSolver::NamedRepair TransitionSolver::namedRepair(const TransitionDesign& d, const Attempt& failed) const {
  if (!opt_.order_by_failure) return NamedRepair::None;
  if (onFreeLimbsOnly(d, failed.failed_links)) return NamedRepair::FreeLimbs;
  if (failed.jumped && opt_.bridge_jumps && onHeldBodiesOnly(d, failed.failed_links)) return NamedRepair::Bridges;
  return NamedRepair::None;
}

bool TransitionSolver::onFreeLimbsOnly(const TransitionDesign& d, const std::vector<int>& links) const {
  if (links.empty()) return false;
  const RobotModel& m = *sc_.robot;
  const std::vector<int> ends = freeLimbEnds(d);
  return std::all_of(links.begin(), links.end(), [&](int link) {
    return std::any_of(ends.begin(), ends.end(), [&](int e) { return m.jointMovesLink(m.spotLimbRootJoint(e), link); });
  });
}

std::vector<PlacedShape> TransitionSolver::outsideLimb(const Configuration& q, int spot) {
  const RobotModel& m = *sc_.robot;
  const int link = m.spots()[spot].link, root = m.limbRootJoint(link);
  std::vector<PlacedShape> out;
  kin_.setConfiguration(q);
  for (const auto& l : m.links())
    if (root >= 0 ? !m.jointMovesLink(root, l.index) : l.index != link)
      for (const auto& shape : l.shapes) out.push_back({&shape, kin_.linkPose(l.index) * shape.pose});
  return out;
}

bool TransitionSolver::solveMove(const Plan& plan, const TransitionDesign& d, const BodyPath& path,
                                 double orientation_tolerance, const std::vector<FreeEnd>* free_ends, Attempt& at) {
  at.failed_links.clear();
  at.jumped = false;
  ++at.attempts;
  const Configuration& q0 = plan.stances[d.from].configuration;
  const Configuration& q1 = plan.stances[d.to].configuration;
  std::vector<int> touch;
  if (d.leave) touch.push_back(sc_.scene->surfaces()[d.leave->surface].obstacle);
  if (d.arrive) touch.push_back(sc_.scene->surfaces()[d.arrive->surface].obstacle);
  const bool pendulum = hangsFromItsLimb(d) || at.free_body;
  const double touch_clearance = pendulum ? kPendulumTouch : opt_.touch_clearance;
  const double s0 = path.leaveParameter(touch_clearance), s1 = path.arriveParameter(touch_clearance);
  bool loose_only = false;
  auto solveAt = [&](double s, const Configuration& guess, bool bridge) -> std::optional<Configuration> {
    if (at.cancel && at.cancel->load()) {
      at.cancelled = true;
      at.reason = "cancelled";
      return std::nullopt;
    }
    Configuration ref = lerp(q0, q1, s);
    // Cost: the squared distance to the witnesses' interpolation plus the
    // squared distance to the neighbouring knot (the guess), i.e. the distance
    // to their midpoint: the knots stay on one branch of the body's inverse
    // kinematics instead of jumping between them.
    std::vector<ReferencePostureCost::SpotTarget> free_targets;
    if (free_ends)
      for (const auto& f : *free_ends) {
        if (f.joints)
          ref = f.joints->apply(ref, s);
        else
          free_targets.push_back({f.spot, f.path.pose(s).translation(), opt_.free_limb_weight});
      }
    // A limb whose joints were planned follows its path, not halfway to the
    // previous knot: that half lagged the arm behind its path until the
    // optimum jumped to the far side of the table's edge between two knots
    // (0.12 rad at s = 0.4008 of a chair plan's transition), which no
    // refinement closes. Its path is continuous in s already.
    // A bridge knot (Refiner::bridges) is near the straight line between its
    // neighbours alone.
    Configuration target = bridge ? guess : lerp(guess, ref, 0.5);
    if (free_ends && !bridge)
      for (const auto& f : *free_ends)
        if (f.joints) target = f.joints->apply(target, s);
    const auto cost = std::make_shared<ReferencePostureCost>(target, 1.0, 10.0, 1.0, free_targets);
    auto attempt = [&](const PoseTarget& t, const Configuration& g) {
      PostureRequest r;
      r.contacts = d.motion_contacts;
      r.pose_target = t;
      r.initial_guess = g;
      r.cost = cost;
      PostureResult res = generator_.solve(r);
      ++at.posture_calls;
      at.posture_seconds += res.seconds;
      return res;
    };
    PoseTarget t;
    t.spot = d.spot;
    t.pose = path.pose(s);
    t.touch_obstacles = touch;
    std::vector<PoseTarget> targets;
    if (pendulum) {
      // Hanging from its limb's contact: where the contact changes, near the
      // touch point; elsewhere anywhere clear of the surface, the cost
      // (the witnesses' interpolation) swinging it on its arc.
      PoseTarget swing = t;
      swing.touch_margin = kTouchMargin;
      if ((d.leave && s == s0) || (d.arrive && s == s1)) {
        const double across = at.free_body ? kFreeBodyAcross : kPendulumAcross;
        swing.position_tolerance = Eigen::Vector3d(across, across, kTouchAlong);
        swing.orientation_tolerance = kTouchTilt;
      } else {
        swing.position_tolerance.setConstant(10.0);
        swing.orientation_tolerance = 0.99;  // the widest a pose target takes: free within 80 degrees
      }
      targets.push_back(swing);
    } else if (!path.straightAt(s)) {  // in the air
      t.orientation_tolerance = orientation_tolerance;
      targets.push_back(t);
      // Failing that, within straight_slack of it: a body that had to pivot
      // off its surface (held at its other end) cannot follow every point of
      // a spline, and neither can a thigh coming down the last millimetres
      // onto a seat beside the other thigh, both feet planted (that leg's
      // thigh and foot contacts leave the solver a degenerate problem that
      // it did not solve in 100 iterations at the exact point; sit_down).
      // A body that misses its path by more than that is repaired.
      PoseTarget loose = t;
      loose.touch_margin = kTouchMargin;
      loose.position_tolerance.setConstant(opt_.straight_slack);
      targets.push_back(loose);
    } else {
      // Near the surface: first exactly on the path (straight along the
      // normal, orientation held: a sole or a palm leaves flat).
      targets.push_back(t);
      // A body whose other end is held cannot: a thigh with its foot planted
      // has its knee move across the shank only, so it pivots off the seat.
      // Then only the height along the normal is held, the body clear of the surface.
      PoseTarget loose = t;
      loose.touch_margin = kTouchMargin;
      if ((d.leave && s == s0) || (d.arrive && s == s1)) {
        // Where the contact changes: within the contract's contact tolerances too.
        loose.position_tolerance = Eigen::Vector3d(kTouchAcross, kTouchAcross, kTouchAlong);
        loose.orientation_tolerance = kTouchTilt;
      } else {
        loose.position_tolerance = Eigen::Vector3d(opt_.straight_slack, opt_.straight_slack, 0);
        loose.orientation_tolerance = orientation_tolerance;
      }
      targets.push_back(loose);
    }
    // Once the body could not follow its path exactly, the rest of this
    // attempt uses the slack at once (the same body, the same constraint).
    if (loose_only) targets.erase(targets.begin());
    PostureResult res;
    for (std::size_t k = 0; k < targets.size(); ++k) {
      res = attempt(targets[k], guess);
      if (!res.success()) res = attempt(targets[k], ref);  // from the interpolated witnesses instead of the previous step
      // Last, for the loosest target only (a stricter one has the next
      // target to fall back on): from the witnesses, the nearer first, which
      // hold the motion's contacts as the interpolation does not. A thigh
      // pivoting off a seat, its leg's thigh and foot contacts
      // over-constraining the solver, found no posture at the top of its
      // lift from the previous step or the interpolation, and one from the
      // witness it rises to.
      for (const Configuration* w : {s < 0.5 ? &q0 : &q1, s < 0.5 ? &q1 : &q0}) {
        if (res.success() || k + 1 < targets.size()) break;
        res = attempt(targets[k], *w);
      }
      if (res.success()) {
        loose_only = loose_only || k > 0;
        return res.configuration;
      }
    }
    char buf[64];
    std::snprintf(buf, sizeof buf, "no posture at path parameter %.3f: ", s);
    at.reason = buf + res.reason;
    return std::nullopt;
  };
  // The knots in the air (the first and last only touch their surfaces when
  // the body has none to leave or reach): n steps, and the two ends of the
  // spline, so that the straight parts are interpolated between knots on them.
  std::vector<double> params;
  for (int i = 0; i <= opt_.steps; ++i) params.push_back(i == opt_.steps ? s1 : s0 + (s1 - s0) * i / opt_.steps);
  for (double j : {path.liftEndParameter(), path.arriveStartParameter()})
    if (j > s0 + 1e-6 && j < s1 - 1e-6) params.push_back(j);
  std::sort(params.begin(), params.end());
  params.erase(std::unique(params.begin(), params.end(), [](double a, double b) { return b - a < 1e-6; }), params.end());
  std::vector<Configuration> knots;
  for (std::size_t i = 0; i < params.size(); ++i) {
    if (i == 0 && !d.leave) {
      knots.push_back(q0);
    } else if (i + 1 == params.size() && !d.arrive) {
      knots.push_back(q1);
    } else {
      const auto k = solveAt(params[i], knots.empty() ? q0 : knots.back(), false);
      if (!k) return false;
      knots.push_back(*k);
    }
  }
  auto addPiece = [&](std::vector<double> ps, std::vector<Configuration> ks, const std::vector<ContactSpec>& contacts,
                      int stance) {
    MotionPiece piece;
    piece.contacts = contacts;
    piece.stance = stance;
    Refiner ref{checker_, piece.contacts, solveAt, opt_.refine_depth, &at.refinements, &at.reason, opt_.segment_checks,
                at.bridges, {}, &at.failed_links, &at.jumped};
    std::vector<double> piece_params;
    if (!ref.refine(ps, ks, piece.knots, piece_params)) return false;
    if (opt_.verify_samples && !ref.verify(piece_params, piece.knots, opt_.timing, *sc_.robot, kin_)) return false;
    at.pieces.push_back(std::move(piece));
    return true;
  };
  if (d.leave && !addPiece({0.0, s0}, {q0, knots.front()}, plan.stances[d.from].specs(), d.from)) return false;
  if (!addPiece(params, knots, d.motion_contacts, d.motion_stance)) return false;
  if (d.arrive && !addPiece({s1, 1.0}, {knots.back(), q1}, plan.stances[d.to].specs(), d.to)) return false;
  return true;
}

}  // namespace acyclic
