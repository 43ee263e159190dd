#include "planner/search/contact_planner.h"

#include <chrono>
#include <cstdio>
#include <algorithm>
#include <deque>
#include <map>
#include <cmath>
#include <optional>
#include <queue>
#include <random>
#include <thread>

#include "planner/check/validity.h"
#include "planner/collision/collision_model.h"
#include "planner/search/swing_check.h"
#include "planner/search/guide_potential.h"
#include "planner/search/portfolio.h"

namespace acyclic {

const char* toString(PlanningResult::Status s) {
  switch (s) {
    case PlanningResult::Status::Solved: return "solved";
    case PlanningResult::Status::NoSolution: return "no solution";
    case PlanningResult::Status::NodeBudget: return "node budget exhausted";
    case PlanningResult::Status::PostureBudget: return "posture-call budget exhausted";
    case PlanningResult::Status::TimeLimit: return "time limit";
    case PlanningResult::Status::Cancelled: return "cancelled";
    case PlanningResult::Status::InvalidInput: return "invalid input";
  }
  return "?";
}

PlannerParameters::PlannerParameters() {
  // An iteration bound, not a time bound, ends each posture call: the same
  // scenario and seed give the same plan on any machine. The time limit is a
  // safety net far above a normal call.
  posture.max_iterations = 60;  // successes need 15-35 (bench_posture); failures stop early
  posture.max_seconds = 2.0;
  // Sherman-Morrison around the KKT system, not L-BFGS's rows in it (the
  // generator's default, faster per iteration): the searches are chaotic in
  // the witnesses, and with the rows sit_down with an upright seated key
  // posture (GuideAuthor.SitDownIsPlanned...LeaningLessOrMore) wandered off
  // the chair for 300 nodes. A scenario may choose (posture_lbfgs_in_kkt).
  posture.lbfgs_in_kkt = false;
  // A call that enters Ipopt's restoration phase gives up (see the option):
  // failures are most of the search's time.
  posture.stop_at_restoration = true;
  // FCL's distances, not the generator's faster default (Convex): with
  // them the chair's search (618 nodes instead of 407) made a plan with a
  // foot step, wedged between a chair leg and the other foot, that the
  // interpolator cannot make. A scenario may choose
  // (posture_distance_engine).
  posture.distance_engine = DistanceEngine::Fcl;
}

namespace {

// Distance of a link coordinate to the goal interval, squared, plus a small
// pull toward a reference posture (the parent's witness): the baseline
// potential of the ablation "distance to goal instead of f_T".
class GoalDistanceCost : public PostureCost {
 public:
  GoalDistanceCost(const GoalCondition& g, const Configuration& reference) : g_(g), ref_(reference, 0.01, 0.1, 0.01) {}
  double evaluate(const Kinematics& kin, Eigen::Ref<Eigen::VectorXd> grad) const override {
    double f = ref_.evaluate(kin, grad);
    const Eigen::Vector3d p = kin.linkPose(g_.link).translation();
    const double v = p[g_.axis];
    const double d = v < g_.min ? v - g_.min : v > g_.max ? v - g_.max : 0.0;
    if (d != 0) {
      Eigen::Vector3d e = Eigen::Vector3d::Zero();
      e[g_.axis] = 2 * d;
      kin.addPointGradient(g_.link, p, e, grad);
    }
    return f + d * d;
  }
  Eigen::VectorXd diagonalHessian(int n) const override { return ref_.diagonalHessian(n); }

 private:
  GoalCondition g_;
  ReferencePostureCost ref_;
};

}  // namespace

struct ContactPlanner::Impl {
  const Scenario& sc;
  PlannerParameters p;
  std::vector<std::unique_ptr<PostureGenerator>> pgs;  // one per thread
  ValidityChecker checker;
  Kinematics kin;  // the search is single-threaded: one for every key, goal and reach test
  Kinematics key_kin;  // the key postures' contacts (guideLimb)
  std::map<std::pair<int, int>, std::vector<std::size_t>> keys_holding;  // (spot, surface): key postures resting it there
  CollisionModel collisions;  // the hanging limbs' swings (swing_check.h)
  std::unique_ptr<GuidePotential> guide;
  std::mt19937 rng;

  enum class Change { Root, Added, Removed };
  // A pair (spot, surface) whose first candidate failed, and where the spot
  // was in the witness of the node where it failed.
  struct FailedPair {
    int spot, surface;
    Eigen::Isometry3d where;
  };
  struct Node {
    std::vector<ContactSpec> contacts;    // all supporting, for its sons
    std::vector<ContactSpec> transition;  // the stance its witness stands for
    Configuration q;
    double key = 0;
    int parent = -1;
    Change change = Change::Root;
    int generator = -1;                   // the pair generator that made it (lazy sons)
    int alternative = 0;                  // sons its pair generator made before it
    int depth = 0;                        // contact changes from the start (set by addNode)
    int changed_spot = -1;                // the spot of the contact added or removed from its parent
    bool dead = false;                    // no plan can be exported through it (exportPlan): not expanded
    bool verified = false;                // verify_on_expansion: its path was verified
    // The settled stance before it (settledWitness): the candidate used, and
    // the first one allowed (raised when the verifier refuses the transition into it).
    int settled_used = -1, settled_from = 0;
    std::vector<FailedPair> failed_pairs;  // first candidate failed here, or remembered from the parent
  };
  struct PairGenerator {
    int node, spot, surface;
    std::vector<std::pair<double, SearchVolume>> volumes;  // inherited key, volume
    int samples_left = 0;
    bool first = true;  // its next candidate is the first (the whole surface)
    int sons = 0;       // sons it made (nodes in the tree)
  };
  struct Entry {
    double key;
    long order;  // ties: first generated first (determinism)
    int node;
    bool operator<(const Entry& o) const { return key > o.key || (key == o.key && order > o.order); }
  };

  // deques: a son is added while references to its parent are held
  std::deque<Node> nodes;
  std::deque<PairGenerator> gens;
  std::priority_queue<Entry> open;
  PlanningStats stats;
  std::chrono::steady_clock::time_point t0;
  long order = 0;
  long nodes_at_best = 0;  // nodes generated when the best potential last fell (max_plateau_nodes)
  int goal_node = -1;
  std::vector<int> stance_owner;  // exportPlan: the node each stance of the plan comes from
  std::vector<char> stance_settled;  // exportPlan: the stance is a settledWitness (its owner's settled_used)
  ContactPlanner::Progress progress;  // the caller's, also told when a verification starts
  const std::atomic<bool>* cancel = nullptr;  // checked before every posture call
  ContactPlanner::MemberLink* link = nullptr;  // as a member of a portfolio
  // Calls of a batch solved but not yet taken in their turn (solveAll adds
  // them to posture_calls at once; taken() or notUsed() settles each).
  long pending_calls = 0;
  // The posture calls of the search made one call at a time, up to here:
  // what a portfolio compares (a batch's calls solved ahead of their turn
  // left out until it comes; those exporting a goal's plan left out, so that
  // a member's count stays the one it announced while it verifies that goal).
  long sequentialCalls() const { return stats.searchCalls() - pending_calls; }
  bool deferred = false;  // the last verification was stopped for a better goal another member verifies
  PlanningResult::Status stop = PlanningResult::Status::NoSolution;
  std::string stop_reason;

  Impl(const Scenario& s, PlannerParameters params)
      : sc(s), p(std::move(params)), checker(s.robot, s.scene), kin(s.robot), key_kin(s.robot), collisions(s.robot, s.scene),
        rng(s.seed) {
    for (int t = 0; t < std::max(1, p.threads); ++t)
      pgs.push_back(std::make_unique<PostureGenerator>(s.robot, s.scene, p.posture));
    if (p.verify_transitions && !p.verify_plan)
      throw std::invalid_argument("verify_transitions is set but no plan verifier was given (PlannerParameters::verify_plan)");
    if (p.guide_potential) {
      std::vector<Configuration> keys = sc.key_postures;
      if (keys.size() < 2) throw std::invalid_argument("the guide potential needs key postures (at least two)");
      guide = std::make_unique<GuidePotential>(keys, p.potential_k, p.smoothing_tolerance, p.guide_joint_weight);
    }
  }

  std::shared_ptr<const PostureCost> costFrom(const Configuration& parent) const {
    if (guide) return std::shared_ptr<const PostureCost>(guide.get(), [](const PostureCost*) {});
    return std::make_shared<GoalDistanceCost>(sc.goal, parent);
  }
  double keyOf(const Configuration& q) {
    kin.setConfiguration(q);
    Eigen::VectorXd g = Eigen::VectorXd::Zero(q.tangentSize());
    if (guide) return guide->evaluate(kin, g);
    return GoalDistanceCost(sc.goal, q).evaluate(kin, g);
  }
  double elapsed() const { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(); }

  // A portfolio's member past the posture calls another solved in cannot win.
  bool outrun(long calls) const { return link && link->outrun(calls); }
  void stopOutrun() {
    stop = PlanningResult::Status::Cancelled;
    stop_reason = "outrun: another member of the portfolio solved, and this one is past " +
                  std::to_string(link->cap()) + " posture calls";
  }

  bool budgetLeft() {
    // While another member verifies a goal this one cannot beat, wait here,
    // within an expansion too (one of chair_paper's made 132 nodes): its core
    // is the verifier's, and waiting changes nothing in this search.
    if (link) link->gate(sequentialCalls(), [&] { return (cancel && cancel->load()) || elapsed() > p.max_seconds; });
    if (outrun(sequentialCalls())) {
      stopOutrun();
      return false;
    }
    if (cancel && cancel->load()) {
      stop = PlanningResult::Status::Cancelled;
      stop_reason = "cancelled";
      return false;
    }
    if (stats.nodes_generated >= p.max_nodes) {
      stop = PlanningResult::Status::NodeBudget;
      stop_reason = std::to_string(p.max_nodes) + " nodes generated without reaching the goal";
      return false;
    }
    if (p.max_plateau_nodes > 0 && stats.nodes_generated - nodes_at_best >= p.max_plateau_nodes) {
      stop = PlanningResult::Status::NodeBudget;
      stop_reason = std::to_string(stats.nodes_generated - nodes_at_best) +
                    " nodes generated since the guide potential last fell (max_plateau_nodes; best " +
                    std::to_string(stats.best_potential) + " at node " + std::to_string(nodes_at_best) +
                    ") without reaching the goal";
      return false;
    }
    if (stats.posture_calls >= p.max_posture_calls) {
      stop = PlanningResult::Status::PostureBudget;
      stop_reason = std::to_string(p.max_posture_calls) + " posture calls without reaching the goal";
      return false;
    }
    if (elapsed() > p.max_seconds) {
      stop = PlanningResult::Status::TimeLimit;
      stop_reason = "no plan within " + std::to_string(p.max_seconds) + " s";
      return false;
    }
    return true;
  }


  static bool sameContacts(const std::vector<ContactSpec>& a, const std::vector<ContactSpec>& b, double dist,
                           double angle) {
    if (a.size() != b.size()) return false;
    for (const auto& ca : a) {
      bool found = false;
      for (const auto& cb : b)
        found = found || (ca.spot == cb.spot && ca.surface == cb.surface &&
                          std::hypot(ca.placement.x - cb.placement.x, ca.placement.y - cb.placement.y) <= dist &&
                          std::abs(std::remainder(ca.placement.theta - cb.placement.theta, 2 * M_PI)) <= angle);
      if (!found) return false;
    }
    return true;
  }

  bool isDuplicate(const std::vector<ContactSpec>& contacts) const {
    for (const auto& m : nodes)
      if (sameContacts(m.contacts, contacts, p.duplicate_distance, p.duplicate_angle)) return true;
    return false;
  }

  // Whether a spot can reach a surface from a posture: the distance from its
  // limb's root joint to the surface polygon is within the limb's length plus
  // a slack for the trunk and base. Conservative: it only skips pairs that no
  // posture near this one could realize.
  bool reachable(int spot, int surface, const Kinematics& k) const {
    const RobotModel& m = *sc.robot;
    const ContactSpot& s = m.spots()[spot];
    const std::vector<int>& chain = m.ancestorJoints(s.link);
    // the limb's root: the first joint below the trunk (a hip, a shoulder)
    const int root = m.limbRootJoint(s.link);
    if (root < 0) return true;
    // the limb's length: the rigid offsets from joint to joint below the root, then to the spot
    double reach = s.frame.translation().norm();
    for (std::size_t i = 1; i < chain.size(); ++i)
      if (m.jointMovesLink(root, m.joints()[chain[i]].child_link) && chain[i] != root)
        reach += (k.jointOrigin(chain[i]) - k.jointOrigin(chain[i - 1])).norm();
    const Surface& surf = sc.scene->surfaces()[surface];
    const Eigen::Vector3d o = surf.frame.inverse() * k.jointOrigin(root);
    const double in_plane = std::max(0.0, surf.polygon.signedDistance(o.head<2>()));
    const double distance = std::hypot(in_plane, o.z());
    return distance <= reach + p.reach_slack;
  }

  void traceExpansion(int ni) {
    if (!p.trace) return;
    const Node& n = nodes[ni];
    kin.setConfiguration(n.q);
    const Eigen::Vector3d w = kin.linkPose(sc.goal.link).translation();
    std::string line = "expand #" + std::to_string(ni) + " depth " + std::to_string(n.depth) + " key " +
                       std::to_string(n.key) + " goal link (" + std::to_string(w.x()).substr(0, 6) + ", " +
                       std::to_string(w.y()).substr(0, 6) + ", " + std::to_string(w.z()).substr(0, 6) + ")" +
                       (n.alternative > 0 ? ", its pair's son " + std::to_string(n.alternative + 1) : std::string()) +
                       ":";
    char buf[64];
    for (const auto& c : n.contacts) {
      std::snprintf(buf, sizeof buf, "(%.2f,%.2f)", c.placement.x, c.placement.y);
      line += " " + sc.robot->spots()[c.spot].name + "@" + sc.scene->surfaces()[c.surface].name + buf;
    }
    line += "  [" + std::to_string(stats.nodes_generated) + " nodes, " + std::to_string(stats.posture_calls) +
            " calls, " + std::to_string(elapsed()).substr(0, 6) + " s]";
    p.trace(line);
  }

  // The goal holds at the node's transition stance, or, for an addition, at
  // the stance where it settles (the new contact supporting too: the same
  // witness, valid, since a support more only widens the forces that balance
  // it); a goal that names supporting spots is often met only there.
  // Leaves kin at n.q.
  bool meetsGoal(const Node& n) {
    kin.setConfiguration(n.q);
    return sc.goal.satisfied(kin, n.transition) || (n.change == Change::Added && sc.goal.satisfied(kin, n.contacts));
  }

  // Adds a son if its witness passes the independent check and no node is too
  // close to it; returns its index or -1. Its key is computed here unless given.
  int addNode(Node n, bool key_given = false) {
    ++stats.nodes_generated;
    if (isDuplicate(n.contacts)) {
      ++stats.duplicates;
      return -1;
    }
    if (!checker.checkPosture(n.q, n.transition).valid()) {
      ++stats.check_refusals;
      return -1;
    }
    // A limb hanging from a contact both hold must swing from the parent's
    // witness to this one clear of the obstacles (swing_check.h); counted
    // with the check's refusals. Both hold every contact of the parent: a
    // son's transition stance is its parent's contacts with one added, or
    // with one no longer supporting, at the same place.
    if (p.swing_check && n.parent >= 0) {
      const Node& par = nodes[n.parent];
      if (!checkHangingSwings(sc, collisions, kin, par.contacts, par.q, n.q).empty()) {
        ++stats.check_refusals;
        return -1;
      }
    }
    n.depth = n.parent >= 0 ? nodes[n.parent].depth + 1 : 0;
    if (!key_given) n.key = keyOf(n.q);  // leaves kin at n.q
    else kin.setConfiguration(n.q);
    nodes.push_back(std::move(n));
    const int id = static_cast<int>(nodes.size()) - 1;
    if (goal_node < 0 && meetsGoal(nodes[id])) goal_node = id;
    // The open list's order: f_T, plus (when set) a cost per contact change
    // from the start, which lifts plateaus of equal f_T (weighted A*).
    open.push({nodes[id].key + p.depth_weight * nodes[id].depth +
                   p.potential_k * p.alternative_step * nodes[id].alternative,
               order++, id});
    if (stats.nodes_generated == 1 || nodes[id].key < stats.best_potential) {
      stats.best_potential = nodes[id].key;
      nodes_at_best = stats.nodes_generated;
    }
    return id;
  }

  // Solves a batch of requests on the planner's generators at once (p.threads),
  // each taking the next unsolved request when it is free; results in request
  // order. A solve depends on its request only (each builds its own problem
  // and Ipopt algorithm), so the results do not depend on which generator
  // took it, nor on timing. Requests beyond the posture-call budget, and
  // those left when a cancellation comes, are not solved: `ran` says which were.
  // `chain`: request k is needed only if every request before it fails (a
  // pair's candidates in turn, nextSon). Once one succeeds, those after it
  // are not started, and those running are stopped at their next iteration
  // (PostureGenerator::solve's stop flag) so that their generators are free
  // at once: `ran` is false for them, and the search never reads them (it
  // stops at the success). Which are stopped depends on timing; what the
  // search takes does not.
  struct Batch {
    std::vector<PostureResult> results;
    std::vector<char> ran;
  };
  // `budgeted` false: every request is solved (a plan's settled stances).
  Batch solveAll(const std::vector<PostureRequest>& rs, bool budgeted = true, bool chain = false) {
    Batch b;
    b.results.resize(rs.size());
    b.ran.assign(rs.size(), 0);
    const long size = static_cast<long>(rs.size());
    const std::size_t n =
        static_cast<std::size_t>(budgeted ? std::clamp<long>(p.max_posture_calls - stats.posture_calls, 0, size) : size);
    std::atomic<std::size_t> next{0};
    std::atomic<std::size_t> first_success{n};  // chain: the earliest request known to succeed
    const std::unique_ptr<std::atomic<bool>[]> stop(new std::atomic<bool>[n]{});
    std::atomic<long> stopped{0};
    auto run = [&](std::size_t w) {
      for (std::size_t i; (i = next.fetch_add(1)) < n;) {
        if (cancel && cancel->load()) break;
        if (chain && i > first_success.load()) break;
        PostureResult res = pgs[w]->solve(rs[i], chain ? &stop[i] : nullptr);
        if (res.status == PostureResult::Status::Stopped) {
          ++stopped;
          continue;
        }
        b.results[i] = std::move(res);
        b.ran[i] = 1;
        if (chain && b.results[i].success()) {
          std::size_t f = first_success.load();
          while (i < f && !first_success.compare_exchange_weak(f, i)) {
          }
          for (std::size_t j = i + 1; j < n; ++j) stop[j] = true;
        }
      }
    };
    const std::size_t workers = std::min(pgs.size(), n);
    if (workers <= 1) {
      run(0);
    } else {
      std::vector<std::thread> pool;
      for (std::size_t w = 1; w < workers; ++w) pool.emplace_back(run, w);
      run(0);
      for (auto& t : pool) t.join();
    }
    stats.calls_stopped += stopped.load();
    for (std::size_t i = 0; i < rs.size(); ++i)
      if (b.ran[i]) {
        stats.posture_calls += b.results[i].solves;  // a retry is a call
        pending_calls += b.results[i].solves;
        if (!b.results[i].success()) ++stats.posture_failures;
        if (b.results[i].retried) ++stats.limb_retries, stats.limb_retry_successes += b.results[i].success();
      }
    return b;
  }

  // A batch's result taken in its turn: a call of the sequential search.
  void taken(const Batch& b, std::size_t i) {
    if (b.ran[i]) pending_calls -= b.results[i].solves;
  }

  // A batch's result that the search does not take (solved ahead, its turn
  // never came): counted apart from the posture calls.
  void notUsed(const Batch& b, std::size_t i) {
    if (!b.ran[i]) return;
    pending_calls -= b.results[i].solves;
    stats.posture_calls -= b.results[i].solves;
    if (b.results[i].retried) --stats.limb_retries, stats.limb_retry_successes -= b.results[i].success();
    if (!b.results[i].success()) --stats.posture_failures;
    ++stats.calls_ahead_unused;
  }

  void traceCall(const std::string& what, const PostureResult& res) const {
    if (p.trace)
      p.trace("  " + what + ": " + toString(res.status) + (res.retried ? " with the guide's limb" : "") +
              (res.footprint_turned ? " with its footprint turned" : "") + " (" +
              std::to_string(res.iterations) + " it, " + std::to_string(res.seconds * 1e3).substr(0, 5) + " ms)");
  }

  // The removal sons' requests of node ni: each contact geometric only in
  // turn, unless the stance without it is a node already. `removed` gets
  // the index of each request's contact.
  void removalRequests(int ni, std::vector<PostureRequest>& requests, std::vector<std::size_t>& removed) {
    if (nodes[ni].contacts.size() < 2) return;
    for (std::size_t c = 0; c < nodes[ni].contacts.size(); ++c) {
      std::vector<ContactSpec> rest = nodes[ni].contacts;
      rest.erase(rest.begin() + c);
      if (isDuplicate(rest)) continue;  // known before any posture call
      PostureRequest r;
      r.contacts = nodes[ni].contacts;
      r.contacts[c].supporting = false;
      r.initial_guess = nodes[ni].q;
      r.cost = costFrom(nodes[ni].q);
      requests.push_back(std::move(r));
      removed.push_back(c);
    }
  }

  // The son that removing contact c of node ni makes, from its request's result.
  void acceptRemoval(int ni, std::size_t c, const PostureRequest& request, const PostureResult& res) {
    traceCall("remove " + sc.robot->spots()[nodes[ni].contacts[c].spot].name, res);
    if (!res.success()) return;
    Node son;
    son.transition = request.contacts;
    son.contacts = nodes[ni].contacts;
    son.contacts.erase(son.contacts.begin() + c);
    son.q = res.configuration;
    son.parent = ni;
    son.change = Change::Removed;
    son.changed_spot = nodes[ni].contacts[c].spot;
    addNode(son);
  }

  // The joints of the limb carrying `spot` set as the guide holds them for
  // the contact (PlannerParameters::guide_limb_guess): from the key posture
  // in which the spot rests on `surface` (spotNearSurface) whose base is
  // nearest q's. The guide at q itself may not hold the limb there yet: a
  // knee that goes down is still a squatting leg in the guide until the
  // posture with the knee on the floor. False when no key posture holds the
  // spot there, or taking its limb changes nothing (1e-3 rad).
  bool guideLimb(int spot, int surface, Configuration& q) {
    const int root = sc.robot->spotLimbRootJoint(spot);
    if (root < 0) return false;
    auto [holding, fresh] = keys_holding.try_emplace({spot, surface});
    if (fresh)
      for (std::size_t k = 0; k < sc.key_postures.size(); ++k) {
        key_kin.setConfiguration(sc.key_postures[k]);
        if (spotNearSurface(sc.scene->surfaces()[surface], key_kin.spotPose(spot))) holding->second.push_back(k);
      }
    const Configuration* best = nullptr;
    double nearest = std::numeric_limits<double>::infinity();
    for (std::size_t k : holding->second) {
      const double d = (sc.key_postures[k].base_position - q.base_position).norm();
      if (d < nearest) nearest = d, best = &sc.key_postures[k];
    }
    if (!best) return false;
    double moved = 0;
    for (int j : sc.robot->jointsMovedBy(root)) {
      moved = std::max(moved, std::abs(q.joints[j] - best->joints[j]));
      q.joints[j] = best->joints[j];
    }
    return moved > 1e-3;
  }

  // A pair generator's next request: its best remaining volume (or a random
  // sample); false when it has none left.
  struct Candidate {
    PostureRequest request;
    ContactSpec added;
    SearchVolume volume;
  };
  bool nextCandidate(int gi, Candidate& cand) {
    PairGenerator& g = gens[gi];
    const Node& n = nodes[g.node];
    PostureRequest& r = cand.request;
    r = PostureRequest();
    r.contacts = n.contacts;
    r.initial_guess = n.q;
    if (p.guide_limb_guess && guide) {
      Configuration q = n.q;
      if (guideLimb(g.spot, g.surface, q)) r.retry_guess = q;
    }
    r.cost = costFrom(n.q);
    ContactSpec& added = cand.added;
    added = ContactSpec();
    added.spot = g.spot;
    added.surface = g.surface;
    added.supporting = false;
    if (p.optimized_candidates) {
      if (g.volumes.empty()) return false;
      // the volume whose parent candidate was best, first
      std::size_t best = 0;
      for (std::size_t k = 1; k < g.volumes.size(); ++k)
        if (g.volumes[k].first < g.volumes[best].first) best = k;
      cand.volume = g.volumes[best].second;
      g.volumes.erase(g.volumes.begin() + best);
      FloatingContact f;
      f.spot = g.spot;
      f.surface = g.surface;
      f.volume = cand.volume;
      r.floating = f;
    } else {
      if (g.samples_left-- <= 0) return false;
      // the paper's earlier method: a random placement on the surface
      const Surface& s = sc.scene->surfaces()[g.surface];
      Eigen::Vector2d lo(1e9, 1e9), hi(-1e9, -1e9);
      for (const auto& v : s.polygon.vertices()) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
      std::uniform_real_distribution<double> u(0, 1);
      do {
        added.placement.x = lo.x() + (hi.x() - lo.x()) * u(rng);
        added.placement.y = lo.y() + (hi.y() - lo.y()) * u(rng);
      } while (!s.polygon.contains({added.placement.x, added.placement.y}));
      added.placement.theta = -M_PI + 2 * M_PI * u(rng);
      r.contacts.push_back(added);
    }
    return true;
  }

  // The son a candidate's result makes, or -1 (failed, duplicate, refused).
  int acceptCandidate(int gi, Candidate& cand, const PostureResult& res) {
    const PairGenerator& g = gens[gi];
    traceCall("add " + sc.robot->spots()[g.spot].name + "@" + sc.scene->surfaces()[g.surface].name, res);
    const bool first = g.first;
    gens[gi].first = false;
    if (!res.success()) {  // that volume (or sample) holds no feasible contact
      if (first && p.optimized_candidates) {
        kin.setConfiguration(nodes[g.node].q);
        nodes[g.node].failed_pairs.push_back({g.spot, g.surface, kin.spotPose(g.spot)});
      }
      return -1;
    }
    const double key = keyOf(res.configuration);  // leaves kin at the witness
    if (p.optimized_candidates) {
      cand.added.placement = res.floating;
      // The contact rows fix the in-plane angle modulo pi: the placement
      // takes the witness's actual angle, so that the plan's contact frames
      // are the witness's spot frames. (The search volume keeps the solver's
      // angle: its parts are cut around it.)
      cand.added.placement.theta =
          projectOnSurface(sc.scene->surfaces()[g.surface], kin.spotPose(g.spot)).theta;
    }
    Node son;
    son.transition = nodes[g.node].contacts;
    son.transition.push_back(cand.added);
    son.contacts = son.transition;
    son.contacts.back().supporting = true;
    son.q = res.configuration;
    son.parent = g.node;
    son.change = Change::Added;
    son.changed_spot = g.spot;
    son.generator = gi;
    son.alternative = gens[gi].sons;
    son.key = key;  // also orders the parts of its volume
    if (p.optimized_candidates)
      for (auto& part : subtractBox(cand.volume, res.floating, p.box)) gens[gi].volumes.push_back({son.key, part});
    const int id = addNode(son, true);
    if (id >= 0) ++gens[gi].sons;
    return id;
  }

  // The next son of a pair generator, or -1 when it has none left: its
  // candidates in turn until one makes a son. With several posture
  // generators, twice as many candidates as generators at a time, as a chain
  // (solveAll): one that fails leaves the pair's volumes as they were but for
  // its own, so the candidate after it is known before it is solved, and a
  // generator that finishes its candidate takes the next one instead of
  // waiting for the other's. One solved ahead whose turn does not come (the
  // one before it made a son, or was feasible and dropped: that one's volume
  // parts change what comes next) goes back to the pair, and its call is
  // counted apart (stats.calls_ahead_unused, or stats.calls_stopped when the
  // success came first and stopped it): the tree is the one of solving them
  // one by one. Measured on chair_paper (docs/design.md section 7): two at a
  // time without stops left a generator idle for 7 of the search's 12 idle
  // seconds, waiting for the other's candidate or solving one a success had
  // made useless; four with stops take 6% off the search.
  int nextSon(int gi) {
    const std::size_t ahead = p.optimized_candidates ? 2 * pgs.size() : 1;  // random draws: one at a time
    while (budgetLeft() && goal_node < 0) {
      std::vector<Candidate> cands;
      std::vector<std::vector<std::pair<double, SearchVolume>>> left;  // the pair's volumes after each is taken
      for (std::size_t k = 0; k < ahead; ++k) {
        Candidate c;
        if (!nextCandidate(gi, c)) break;
        cands.push_back(std::move(c));
        if (ahead > 1) left.push_back(gens[gi].volumes);
      }
      if (cands.empty()) return -1;
      std::vector<PostureRequest> requests;
      for (const auto& c : cands) requests.push_back(c.request);
      const Batch b = solveAll(requests, true, true);
      // Candidates k.. are not used: back to the pair, before the parts that
      // candidate k - 1 added (their order is the sequential search's).
      auto giveBack = [&](std::size_t k) {
        std::vector<std::pair<double, SearchVolume>> v = left[k - 1];
        v.insert(v.end(), gens[gi].volumes.begin() + static_cast<long>(left.back().size()), gens[gi].volumes.end());
        gens[gi].volumes = std::move(v);
        for (std::size_t j = k; j < cands.size(); ++j) notUsed(b, j);
      };
      for (std::size_t k = 0; k < cands.size(); ++k) {
        if (k > 0 && (!budgetLeft() || goal_node >= 0)) {
          giveBack(k);
          return -1;
        }
        if (!b.ran[k]) {  // cancelled, or out of posture calls
          if (k + 1 < cands.size()) giveBack(k + 1);
          return -1;
        }
        taken(b, k);
        const int id = acceptCandidate(gi, cands[k], b.results[k]);
        if (id >= 0 || b.results[k].success()) {
          if (k + 1 < cands.size()) giveBack(k + 1);
          if (id >= 0) return id;
          break;  // feasible but dropped: the next candidates from the volumes as they are now
        }
      }
    }
    return -1;
  }

  // Whether the failure memory says pair (spot, surface) fails at node ni: its
  // first candidate failed at ni's parent or was remembered there, and ni's
  // witness holds the spot where it was when it failed (within the failure
  // memory's tolerances). Remembered at ni too, for its own sons. Measured
  // from where it failed, not from the parent: a robot shuffling its feet a
  // few centimetres at a time toward a chair would otherwise carry a thigh's
  // failure all the way to the seat, and never try it there (sit_down from
  // 0.3 m away: not found in 3,000 nodes; without the memory, 64). Not past
  // a change on the spot's own limb: a thigh that could not lie flat on the
  // seat with its foot where it was may once that foot is moved (the leg's
  // chain from hip to foot is what failed), and was never retried there.
  bool rememberedFailure(int ni, int spot, int surface) {
    if (!p.failure_memory || !p.optimized_candidates) return false;
    const int pi = nodes[ni].parent;
    if (pi < 0) return false;
    const RobotModel& m = *sc.robot;
    if (nodes[ni].changed_spot >= 0 && m.spotLimbRootJoint(nodes[ni].changed_spot) == m.spotLimbRootJoint(spot))
      return false;
    const auto& failed = nodes[pi].failed_pairs;
    auto it = std::find_if(failed.begin(), failed.end(),
                           [&](const FailedPair& f) { return f.spot == spot && f.surface == surface; });
    if (it == failed.end()) return false;
    const FailedPair f = *it;
    kin.setConfiguration(nodes[ni].q);
    const Eigen::Isometry3d now = kin.spotPose(spot);
    const double moved = (now.translation() - f.where.translation()).norm();
    const double turned = Eigen::AngleAxisd(f.where.linear().transpose() * now.linear()).angle();
    if (moved > p.failure_memory_distance || turned > p.failure_memory_angle) return false;
    nodes[ni].failed_pairs.push_back(f);
    ++stats.pairs_remembered;
    return true;
  }

  // The pair generators of node ni, one per pair (spot, surface) that the
  // failure memory and the reachability test leave to try.
  std::vector<int> pairGenerators(int ni) {
    std::vector<int> pairs;
    if (nodes[ni].contacts.size() >= static_cast<std::size_t>(p.max_contacts)) return pairs;
    for (int spot : sc.allowed_spots) {
      bool used = false;
      for (const auto& c : nodes[ni].contacts) used = used || c.spot == spot;
      if (used) continue;
      for (int surface : sc.allowed_surfaces) {
        if (!sc.allows(spot, surface)) continue;  // forbidden_contacts
        if (rememberedFailure(ni, spot, surface)) continue;
        kin.setConfiguration(nodes[ni].q);
        if (!reachable(spot, surface, kin)) continue;
        PairGenerator g;
        g.node = ni;
        g.spot = spot;
        g.surface = surface;
        g.volumes.push_back({0.0, fullVolume(sc.scene->surfaces()[surface].polygon)});
        g.samples_left = p.random_samples_per_pair;
        gens.push_back(g);
        pairs.push_back(static_cast<int>(gens.size()) - 1);
      }
    }
    return pairs;
  }

  // Eager sons (the ablation): every removal son, then up to
  // eager_candidates_per_pair sons of each pair, one after the other.
  void expandEagerly(int ni) {
    if (budgetLeft()) {
      std::vector<PostureRequest> requests;
      std::vector<std::size_t> removed;
      removalRequests(ni, requests, removed);
      const Batch b = solveAll(requests);
      for (std::size_t k = 0; k < requests.size() && goal_node < 0; ++k)
        if (b.ran[k]) acceptRemoval(ni, removed[k], requests[k], b.results[k]);
      for (std::size_t k = 0; k < requests.size(); ++k) taken(b, k);  // every one counted, as the ablation always did
    }
    const std::vector<int> pairs = pairGenerators(ni);
    const int sons = p.optimized_candidates ? p.eager_candidates_per_pair : p.random_samples_per_pair;
    for (int gi : pairs)
      for (int k = 0; k < sons && budgetLeft() && goal_node < 0; ++k)
        if (nextSon(gi) < 0) break;
  }

  // Expands node ni; `selected_from` is the pair generator that made it (-1
  // for none), whose next son is due now that this one is taken (lazy sons,
  // paper 2.8). The calls that do not depend on each other's results go to
  // the generators as one batch: the removal sons, each pair's first son, and
  // the selected generator's next candidate. Their results are then taken in
  // the order of the sequential search (removals, pairs, the next son), and a
  // candidate that makes no son goes on alone (its pair's remaining volumes),
  // so the tree is the one that solving them one by one would grow.
  void expand(int ni, int selected_from) {
    ++stats.nodes_expanded;
    traceExpansion(ni);
    if (!p.lazy_sons) {
      expandEagerly(ni);
      return;
    }
    if (!budgetLeft()) return;
    std::vector<PostureRequest> requests;
    std::vector<std::size_t> removed;
    removalRequests(ni, requests, removed);
    const std::size_t n_removals = requests.size();
    const std::vector<int> pairs = pairGenerators(ni);
    std::vector<Candidate> cands(pairs.size());
    std::vector<int> with_candidate;
    for (std::size_t k = 0; k < pairs.size(); ++k)
      if (nextCandidate(pairs[k], cands[k])) {
        requests.push_back(cands[k].request);
        with_candidate.push_back(static_cast<int>(k));
      }
    // The selected generator's next candidate, taken from it now: put back if
    // the search ends before its turn (a goal whose plan cannot be exported
    // lets the search go on, and that generator must still hold it). A random
    // candidate draws from the search's generator of random numbers, in the
    // order of the sequential search: drawn in its turn, not ahead.
    Candidate next;
    std::optional<PairGenerator> before;
    if (selected_from >= 0 && p.optimized_candidates) {
      before = gens[selected_from];
      if (nextCandidate(selected_from, next)) requests.push_back(next.request);
      else before.reset();
    }
    const Batch b = solveAll(requests);
    std::vector<char> used(requests.size(), 0);
    for (std::size_t k = 0; k < n_removals && goal_node < 0; ++k)
      if (b.ran[k]) taken(b, k), acceptRemoval(ni, removed[k], requests[k], b.results[k]), used[k] = 1;
    if (budgetLeft() && goal_node < 0) {
      for (std::size_t j = 0; j < with_candidate.size() && goal_node < 0; ++j) {
        const std::size_t r = n_removals + j;
        if (!b.ran[r]) break;  // cancelled, or out of posture calls
        const int k = with_candidate[j];
        used[r] = 1;
        taken(b, r);
        if (acceptCandidate(pairs[k], cands[k], b.results[r]) < 0 && b.results[r].success()) nextSon(pairs[k]);
      }
    }
    if (before) {
      const std::size_t r = requests.size() - 1;
      if (budgetLeft() && goal_node < 0 && b.ran[r]) {
        used[r] = 1;
        taken(b, r);
        if (acceptCandidate(selected_from, next, b.results[r]) < 0) nextSon(selected_from);
      } else {
        gens[selected_from] = *before;
      }
    } else if (selected_from >= 0) {
      nextSon(selected_from);
    }
    // Results the search ended before taking: solved ahead, not used.
    for (std::size_t r = 0; r < requests.size(); ++r)
      if (!used[r]) notUsed(b, r);
  }

  // A witness for the stance `contacts` between a removal (witness `removed`)
  // and an addition (witness `added`), accepted by the independent check, or
  // none (see exportPlan).
  // Candidates in order, from the `from`-th; `used` gets the one returned.
  std::optional<Configuration> settledWitness(const std::vector<ContactSpec>& contacts, const Configuration& added,
                                              const Configuration& removed, int from, int& used) {
    auto valid = [&](const Configuration& q) { return checker.checkPosture(q, contacts).valid(); };
    auto solve = [&](const Configuration& guess, PostureGenerator* generator) -> std::optional<Configuration> {
      PostureRequest r;
      r.contacts = contacts;
      r.initial_guess = guess;
      r.cost = costFrom(guess);
      PostureResult res;
      if (generator) {
        res = generator->solve(r);
        ++stats.posture_calls;
        if (!res.success()) ++stats.posture_failures;
      } else {
        const Batch one = solveAll({r}, false);
        taken(one, 0);
        res = one.results[0];
      }
      if (res.success() && valid(res.configuration)) return res.configuration;
      return std::nullopt;
    };
    used = 0;
    if (from <= 0)
      if (auto q = solve(added, nullptr)) return q;
    used = 1;
    if (from <= 1)
      if (auto q = solve(removed, nullptr)) return q;
    used = 2;
    if (from <= 2 && valid(removed)) return removed;
    used = 3;
    if (from > 3) return std::nullopt;
    PostureGeneratorOptions patient = p.posture;
    patient.max_iterations = std::max(300, p.posture.max_iterations);
    patient.stop_at_restoration = false;  // the last resort: an answer whenever there is one
    PostureGenerator generator(sc.robot, sc.scene, patient);
    return solve(added, &generator);
  }

  // The plan along the path to `last`: each node's transition stance, with a
  // stance between two of them where the earlier change settles (an added
  // contact starts to support, a removed one is gone), so that consecutive
  // stances differ by one contact (docs/design.md section 8).
  // Returns false, and marks the node where it fails dead, when a settled
  // stance gets no valid witness.
  bool exportPlan(int last, Plan& plan) {
    std::vector<int> path;
    for (int n = last; n >= 0; n = nodes[n].parent) path.insert(path.begin(), n);
    plan = Plan();
    plan.scenario = sc.path;
    plan.robot = sc.robot->descriptionPath();
    stance_owner.clear();
    stance_settled.clear();
    auto push = [&](const std::vector<ContactSpec>& specs, const Configuration& q, int owner) {
      stance_owner.push_back(owner);
      stance_settled.push_back(0);
      PlanStance st;
      st.configuration = q;
      st.potential = keyOf(q);
      QuasiStaticReport eq;
      checker.checkPosture(q, specs, &eq);
      for (std::size_t i = 0; i < specs.size(); ++i) {
        PlanContact c;
        c.spec = specs[i];
        c.frame = contactFrame(sc.scene->surfaces()[specs[i].surface], specs[i].placement);
        if (specs[i].supporting && i < eq.points.size()) c.points = eq.points[i], c.forces = eq.forces[i];
        st.contacts.push_back(c);
      }
      plan.stances.push_back(st);
    };
    push(nodes[path[0]].transition, nodes[path[0]].q, path[0]);
    for (std::size_t i = 1; i < path.size(); ++i) {
      const Node& prev = nodes[path[i - 1]];
      const Node& cur = nodes[path[i]];
      if (i >= 2) {
        // The settled stance prev.contacts: its witness touches exactly its contacts.
        if (prev.change == Change::Added) {
          push(prev.contacts, prev.q, path[i - 1]);
        } else if (cur.change == Change::Removed) {
          push(prev.contacts, cur.q, path[i]);
        } else {
          // prev was a removal and cur adds a contact: prev's witness still
          // touches with the removed contact, cur's with the added one. The
          // first the independent check accepts: a witness of its own from
          // cur's, then from prev's; prev's own (the removed body may rest
          // on its surface's edge of validity); from cur's with a long
          // iteration budget. Without one no plan goes through cur.
          Node& owner = nodes[path[i]];
          std::optional<Configuration> settled =
              settledWitness(prev.contacts, cur.q, prev.q, owner.settled_from, owner.settled_used);
          if (!settled) {
            owner.dead = true;
            return false;
          }
          push(prev.contacts, *settled, path[i]);
          stance_settled.back() = 1;
        }
      }
      push(cur.transition, cur.q, path[i]);
    }
    // A goal met where the last addition settles ends on that stance.
    const Node& end = nodes[path.back()];
    kin.setConfiguration(end.q);
    if (!sc.goal.satisfied(kin, end.transition)) push(end.contacts, end.q, path.back());
    plan.stats.nodes_generated = stats.nodes_generated;
    plan.stats.nodes_expanded = stats.nodes_expanded;
    plan.stats.posture_calls = stats.posture_calls;
    plan.stats.posture_failures = stats.posture_failures;
    plan.stats.seconds = elapsed();
    return true;
  }

  // Runs the plan verifier with a stop flag raised on a cancel or when the
  // time budget runs out (checked every 20 ms).
  // `announce`: the progress callback is told a plan is being verified
  // (a goal's, not each expanded node's).
  PlanVerdict verify(const Plan& plan, bool announce) {
    const double start = elapsed();
    if (progress && announce) {
      stats.seconds = start;
      stats.verifying = true;
      progress(stats);
      stats.verifying = false;
    }
    std::atomic<bool> stop_flag{false}, done{false}, beaten{false};
    const long calls_now = sequentialCalls();
    std::thread watch([&] {
      while (!done.load()) {
        if ((cancel && cancel->load()) || elapsed() > p.max_seconds || outrun(calls_now)) stop_flag = true;
        // A portfolio's member beaten by a goal another verifies defers its own (verifyPath).
        if (announce && link && link->beaten(calls_now)) beaten = stop_flag = true;
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
      }
    });
    PlanVerdict v;
    try {
      v = p.verify_plan(plan, stop_flag);
    } catch (...) {
      done = true;
      watch.join();
      throw;
    }
    done = true;
    watch.join();
    deferred = v.stopped && beaten.load();
    if (announce && !deferred) ++stats.plans_verified;
    stats.transitions_solved += v.solved;
    stats.verify_seconds += elapsed() - start;
    return v;
  }

  // Exports the path to `node` and, with verify_transitions, verifies it.
  // The first transition that cannot be made drops the node its stance
  // comes from (and so its subtree); a transition into a settled stance
  // (between a removal and an addition) first gets that stance's next
  // witness candidate, and so does one out of a settled stance into its own
  // node's transition stance (the settled witness is where the added body's
  // motion starts). Transitions solved once are remembered by the verifier.
  // Refused goals are recorded in `out` (`goal`); a stop (cancel or budget)
  // during verification sets the stop's reason.
  // Deferred: a portfolio's member stopped verifying its goal because
  // another verifies a better one; the goal is verified again after that
  // one's verdict, unless it was accepted.
  enum class Verified { Ok, Dropped, Stopped, Deferred };
  Verified verifyPath(int node, Plan& plan, PlanningResult& out, bool goal) {
    while (true) {
      const long before_export = stats.posture_calls;
      const bool exported = exportPlan(node, plan);
      stats.export_calls += stats.posture_calls - before_export;
      if (!exported) {
        ++stats.check_refusals;
        return Verified::Dropped;
      }
      if (!p.verify_transitions) return Verified::Ok;
      const PlanVerdict v = verify(plan, goal);
      if (v.ok()) return Verified::Ok;
      if (deferred && budgetLeft()) return Verified::Deferred;
      if (v.stopped) {
        budgetLeft();  // the stop's reason: outrun, cancel or a budget
        if (stop == PlanningResult::Status::NoSolution) stop = PlanningResult::Status::TimeLimit;
        stop_reason = std::string(goal ? "a plan of " + std::to_string(plan.stances.size()) +
                                             " stances was found but its transitions were not all verified: "
                                       : "stopped while verifying the transitions into a stance: ") +
                      stop_reason;
        return Verified::Stopped;
      }
      if (goal) {
        ++stats.plans_refused;
        out.refusals.push_back("stances " + std::to_string(v.failed_from) + " -> " + std::to_string(v.failed_to) +
                               ": " + v.reason.substr(0, 300));
        if (p.keep_refused_plans) out.refused_plans.push_back({plan, v.failed_from, v.failed_to, v.reason});
      }
      const auto to = static_cast<std::size_t>(v.failed_to);
      const auto from = static_cast<std::size_t>(v.failed_from);
      const int owner = stance_owner.at(to);
      const bool settled_end = stance_settled.at(to) || (stance_settled.at(from) && stance_owner.at(from) == owner);
      const bool retry = settled_end && nodes[owner].settled_used < 3;
      if (p.trace)
        p.trace("verification: stances " + std::to_string(v.failed_from) + " -> " + std::to_string(v.failed_to) +
                " cannot be interpolated (" + v.reason.substr(0, 160) + "): node " + std::to_string(owner) +
                (retry ? ": its settled stance's next witness" : " dropped"));
      if (!retry) {
        nodes[owner].dead = true;
        return Verified::Dropped;
      }
      nodes[owner].settled_from = nodes[owner].settled_used + 1;
    }
  }

  bool deadPath(int n) const {
    for (; n >= 0; n = nodes[n].parent)
      if (nodes[n].dead) return true;
    return false;
  }
};

long PlanningResult::portfolioNodes() const {
  if (members.empty()) return stats.nodes_generated;
  long n = 0;
  for (const Member& m : members) n += m.stats.nodes_generated;
  return n;
}

ContactPlanner::ContactPlanner(const Scenario& scenario, PlannerParameters params) {
  if (params.portfolio.empty()) impl_ = std::make_unique<Impl>(scenario, std::move(params));
  else portfolio_ = std::make_unique<Portfolio>(scenario, params);
}
ContactPlanner::~ContactPlanner() = default;

void ContactPlanner::setTimeBudget(double seconds) { impl_->p.max_seconds = seconds; }

PlanningResult ContactPlanner::plan(const std::atomic<bool>* cancel, const Progress& progress) {
  return portfolio_ ? portfolio_->plan(cancel, progress) : search(cancel, progress, nullptr);
}

PlanningResult ContactPlanner::search(const std::atomic<bool>* cancel, const Progress& progress, MemberLink* link) {
  Impl& I = *impl_;
  I.link = link;
  I.t0 = std::chrono::steady_clock::now();
  I.cancel = cancel;
  I.progress = progress;
  PlanningResult out;
  Impl::Node root;
  root.contacts = I.sc.start_stance;
  root.transition = I.sc.start_stance;
  root.q = I.sc.start;
  const ValidityReport rep = I.checker.checkPosture(root.q, root.contacts);
  if (!rep.valid()) {
    out.status = PlanningResult::Status::InvalidInput;
    for (const auto& part : rep.parts)
      if (!part.ok()) out.reason = "the start stance is not valid: " + part.name + ": " + part.violations[0];
    return out;
  }
  I.addNode(root);
  double last_report = -1;
  Plan plan;
  bool exported = false;
  while (true) {
    if (link) {
      // While another member verifies a goal this one cannot beat, its
      // core is the verifier's (waiting changes nothing in this search).
      link->gate(I.sequentialCalls(), [&] { return (cancel && cancel->load()) || I.elapsed() > I.p.max_seconds; });
      if (I.outrun(I.sequentialCalls())) {
        I.stopOutrun();
        break;
      }
    }
    if (I.goal_node >= 0) {
      // A goal whose plan cannot be exported (a settled stance without a
      // valid witness) or whose transitions cannot all be made is dropped
      // with the node where it fails; the search goes on.
      if (link) link->verifying(I.sequentialCalls());
      const Impl::Verified v = I.verifyPath(I.goal_node, plan, out, true);
      if (v == Impl::Verified::Ok) {
        exported = true;  // still "verifying" for the others until the portfolio sets their caps
        break;
      }
      if (link) link->verifying(-1);
      if (v == Impl::Verified::Stopped) break;
      if (v == Impl::Verified::Deferred) continue;  // to the gate, then verified again or outrun
      I.goal_node = -1;
    }
    if (!I.budgetLeft()) break;
    if (I.open.empty()) {
      I.stop = PlanningResult::Status::NoSolution;
      I.stop_reason = "every stance reachable from the start was explored";
      break;
    }
    const Impl::Entry e = I.open.top();
    I.open.pop();
    if (I.deadPath(e.node)) continue;
    if (I.p.verify_transitions && I.p.verify_on_expansion && !I.nodes[e.node].verified) {
      // Its path from the start verified before any son is built on it.
      I.nodes[e.node].verified = true;
      ++I.stats.nodes_verified;
      const Impl::Verified v = I.verifyPath(e.node, plan, out, false);
      if (v == Impl::Verified::Stopped) break;
      if (v == Impl::Verified::Dropped) {
        ++I.stats.nodes_refused;
        continue;
      }
    }
    I.expand(e.node, I.p.lazy_sons ? I.nodes[e.node].generator : -1);
    I.stats.seconds = I.elapsed();
    if (progress && I.stats.seconds - last_report >= 0.5) {
      progress(I.stats);
      last_report = I.stats.seconds;
    }
  }
  I.stats.seconds = I.elapsed();
  out.stats = I.stats;
  if (exported) {
    out.status = PlanningResult::Status::Solved;
    out.plan = std::move(plan);
    out.stats = I.stats;
    out.plan.stats.seconds = out.stats.seconds = I.elapsed();
  } else {
    out.status = I.stop;
    out.reason = I.stop_reason;
  }
  if (progress) progress(out.stats);
  return out;
}

}  // namespace acyclic
