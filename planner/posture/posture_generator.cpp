#include "planner/posture/posture_generator.h"
#include "planner/posture/kkt_ldl.h"

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <set>

#include <IpIpoptApplication.hpp>
#include <IpTNLP.hpp>

extern "C" int acyclic_mumps_lock_linked();  // planner/posture/mumps_lock.cpp

namespace acyclic {

const char* toString(PostureResult::Status s) {
  switch (s) {
    case PostureResult::Status::Success: return "success";
    case PostureResult::Status::Infeasible: return "infeasible";
    case PostureResult::Status::IterationLimit: return "iteration limit";
    case PostureResult::Status::TimeLimit: return "time limit";
    case PostureResult::Status::BadInput: return "bad input";
    case PostureResult::Status::Stopped: return "stopped";
  }
  return "?";
}

const std::vector<std::string>& muOracles() {
  static const std::vector<std::string> names = {"quality-function", "probing", "loqo"};
  return names;
}

bool isMuOracle(const std::string& name) {
  const auto& all = muOracles();
  return std::find(all.begin(), all.end(), name) != all.end();
}

std::string muOracleChoices() {
  const auto& all = muOracles();
  std::string s;
  for (std::size_t i = 0; i < all.size(); ++i) s += (i == 0 ? "" : i + 1 == all.size() ? " or " : ", ") + all[i];
  return s;
}

namespace {

// Ipopt's view of a PostureProblem.
class PostureTNLP : public Ipopt::TNLP {
 public:
  enum class Hessian { LBFGS, Diagonal, Analytic };
  PostureTNLP(PostureProblem& p, const Eigen::VectorXd& x0, Hessian h) : p_(p), x0_(x0), hessian_(h) {}

  bool get_nlp_info(Ipopt::Index& n, Ipopt::Index& m, Ipopt::Index& nnz_jac, Ipopt::Index& nnz_h,
                    IndexStyleEnum& style) override {
    n = p_.numVariables();
    m = p_.numConstraints();
    nnz_jac = static_cast<Ipopt::Index>(p_.jacobianStructure().size());
    nnz_h = hessian_ == Hessian::Diagonal ? n
            : hessian_ == Hessian::Analytic ? static_cast<Ipopt::Index>(p_.hessianStructure().size())
                                            : 0;
    style = C_STYLE;
    return true;
  }
  bool get_bounds_info(Ipopt::Index n, Ipopt::Number* xl, Ipopt::Number* xu, Ipopt::Index m, Ipopt::Number* gl,
                       Ipopt::Number* gu) override {
    Eigen::VectorXd a, b, c, d;
    p_.bounds(a, b, c, d);
    std::copy(a.data(), a.data() + n, xl);
    std::copy(b.data(), b.data() + n, xu);
    std::copy(c.data(), c.data() + m, gl);
    std::copy(d.data(), d.data() + m, gu);
    return true;
  }
  bool get_starting_point(Ipopt::Index n, bool init_x, Ipopt::Number* x, bool, Ipopt::Number*, Ipopt::Number*,
                          Ipopt::Index, bool, Ipopt::Number*) override {
    if (init_x) std::copy(x0_.data(), x0_.data() + n, x);
    return true;
  }
  bool eval_f(Ipopt::Index n, const Ipopt::Number* x, bool, Ipopt::Number& f) override {
    f = p_.cost(map(n, x));
    return std::isfinite(f);
  }
  bool eval_grad_f(Ipopt::Index n, const Ipopt::Number* x, bool, Ipopt::Number* g) override {
    const Eigen::VectorXd gr = p_.costGradient(map(n, x));
    std::copy(gr.data(), gr.data() + n, g);
    return gr.allFinite();
  }
  bool eval_g(Ipopt::Index n, const Ipopt::Number* x, bool, Ipopt::Index m, Ipopt::Number* g) override {
    const Eigen::VectorXd v = p_.constraints(map(n, x));
    std::copy(v.data(), v.data() + m, g);
    return v.allFinite();
  }
  bool eval_jac_g(Ipopt::Index n, const Ipopt::Number* x, bool, Ipopt::Index, Ipopt::Index, Ipopt::Index* rows,
                  Ipopt::Index* cols, Ipopt::Number* values) override {
    if (!values) {
      const auto& s = p_.jacobianStructure();
      for (std::size_t k = 0; k < s.size(); ++k) rows[k] = s[k].first, cols[k] = s[k].second;
      return true;
    }
    p_.jacobianValues(map(n, x), values);
    return true;
  }
  bool eval_h(Ipopt::Index n, const Ipopt::Number* x, bool, Ipopt::Number obj_factor, Ipopt::Index m,
              const Ipopt::Number* lambda, bool, Ipopt::Index, Ipopt::Index* rows, Ipopt::Index* cols,
              Ipopt::Number* values) override {
    if (hessian_ == Hessian::Analytic) {
      if (!values) {
        const auto& s = p_.hessianStructure();
        for (std::size_t k = 0; k < s.size(); ++k) rows[k] = s[k].first, cols[k] = s[k].second;
        return true;
      }
      p_.hessianValues(map(n, x), obj_factor, Eigen::Map<const Eigen::VectorXd>(lambda, m), values);
      return true;
    }
    if (!values) {
      for (Ipopt::Index i = 0; i < n; ++i) rows[i] = cols[i] = i;
      return true;
    }
    if (hdiag_.size() != n) hdiag_ = p_.hessianDiagonal();
    for (Ipopt::Index i = 0; i < n; ++i) values[i] = std::max(obj_factor, 1e-3) * hdiag_[i];
    return true;
  }
  bool intermediate_callback(Ipopt::AlgorithmMode mode, Ipopt::Index iter, Ipopt::Number, Ipopt::Number,
                             Ipopt::Number, Ipopt::Number, Ipopt::Number, Ipopt::Number, Ipopt::Number,
                             Ipopt::Number, Ipopt::Index, const Ipopt::IpoptData*,
                             Ipopt::IpoptCalculatedQuantities*) override {
    iterations = iter;
    if (stop && stop->load(std::memory_order_relaxed)) {
      stopped = true;
      return false;  // USER_REQUESTED_STOP
    }
    if (stop_at_restoration && mode == Ipopt::RestorationPhaseMode) {
      entered_restoration = true;
      return false;  // Ipopt stops with USER_REQUESTED_STOP
    }
    return true;
  }
  void finalize_solution(Ipopt::SolverReturn status, Ipopt::Index n, const Ipopt::Number* x, const Ipopt::Number*,
                         const Ipopt::Number*, Ipopt::Index, const Ipopt::Number*, const Ipopt::Number*,
                         Ipopt::Number obj, const Ipopt::IpoptData*, Ipopt::IpoptCalculatedQuantities*) override {
    final_status = status;
    x_final = map(n, x);
    final_cost = obj;
  }

  Ipopt::SolverReturn final_status = Ipopt::INTERNAL_ERROR;
  bool stop_at_restoration = false;
  bool entered_restoration = false;
  const std::atomic<bool>* stop = nullptr;  // the caller's (PostureGenerator::solve)
  bool stopped = false;
  Eigen::VectorXd x_final;
  double final_cost = 0;
  int iterations = 0;

 private:
  static Eigen::VectorXd map(Ipopt::Index n, const Ipopt::Number* x) { return Eigen::Map<const Eigen::VectorXd>(x, n); }
  PostureProblem& p_;
  Eigen::VectorXd x0_;
  Hessian hessian_;
  Eigen::VectorXd hdiag_;
};

}  // namespace

struct PostureGenerator::Ipopt {
  ::Ipopt::SmartPtr<::Ipopt::IpoptApplication> app;
};

PostureGenerator::PostureGenerator(std::shared_ptr<const RobotModel> robot, std::shared_ptr<const Scene> scene,
                                   PostureGeneratorOptions options)
    : robot_(std::move(robot)), scene_(std::move(scene)),
      collision_(std::make_shared<CollisionModel>(robot_, scene_, options.distance_engine)), opt_(options),
      ipopt_(std::make_unique<Ipopt>()) {
  (void)acyclic_mumps_lock_linked();  // keeps the interposers' library in every link
  auto& app = ipopt_->app;
  app = IpoptApplicationFactory();
  auto o = app->Options();
  o->SetStringValue("sb", "yes");  // no banner
  o->SetIntegerValue("print_level", opt_.print_level);
  if (opt_.print_level >= 4) o->SetStringValue("print_timing_statistics", "yes");
  if (opt_.hessian != "diagonal" && opt_.hessian != "lbfgs" && opt_.hessian != "analytic")
    throw std::invalid_argument("PostureGeneratorOptions::hessian: expected lbfgs, analytic or diagonal, got '" +
                                opt_.hessian + "'");
  o->SetStringValue("hessian_approximation", opt_.hessian == "lbfgs" ? "limited-memory" : "exact");
  if (opt_.hessian == "lbfgs" && opt_.lbfgs_in_kkt) o->SetStringValue("limited_memory_aug_solver", "extended");
  if (opt_.linear_solver == "ldl") {
    if (opt_.hessian == "analytic")
      throw std::invalid_argument(
          "PostureGeneratorOptions::linear_solver \"ldl\" needs a diagonal Hessian block (hessian lbfgs or "
          "diagonal); use \"mumps\" with hessian analytic");
    kkt::registerWithIpopt();
    o->SetStringValue("linear_solver", "ma27");  // the loader's name for what registerWithIpopt supplies
    o->SetStringValue("linear_system_scaling", "none");
    o->SetNumericValue("ma27_la_init_factor", 1.0);   // its workspace estimates are exact
    o->SetNumericValue("ma27_liw_init_factor", 1.0);
    o->SetNumericValue("ma27_pivtolmax", 1e-8);       // no pivoting: nothing to raise
    o->SetNumericValue("ma27_pivtol", 1e-8);
  } else if (opt_.linear_solver != "mumps") {
    throw std::invalid_argument("PostureGeneratorOptions::linear_solver: expected ldl or mumps, got '" +
                                opt_.linear_solver + "'");
  }
  o->SetStringValue("mu_strategy", "adaptive");
  if (!isMuOracle(opt_.mu_oracle))
    throw std::invalid_argument("PostureGeneratorOptions::mu_oracle: expected " + muOracleChoices() + ", got '" +
                                opt_.mu_oracle + "'");
  o->SetStringValue("mu_oracle", opt_.mu_oracle);
  o->SetNumericValue("tol", opt_.tolerance);
  o->SetNumericValue("constr_viol_tol", opt_.tolerance);
  // A witness posture needs feasibility, not a polished optimum: stop once
  // feasible with an objective that has settled (L-BFGS polishes slowly).
  o->SetNumericValue("acceptable_tol", 1e10);  // judged by the criteria below, not by dual infeasibility
  o->SetNumericValue("acceptable_constr_viol_tol", opt_.tolerance);
  o->SetNumericValue("acceptable_dual_inf_tol", 1e10);
  o->SetNumericValue("acceptable_compl_inf_tol", 1e-3);
  o->SetNumericValue("acceptable_obj_change_tol", 1e-2);
  o->SetIntegerValue("acceptable_iter", 1);
  // Out-of-reach contacts are common in the search: enter the restoration
  // phase early, so that local infeasibility is found fast.
  o->SetStringValue("expect_infeasible_problem", "yes");
  o->SetIntegerValue("max_iter", opt_.max_iterations);
  o->SetNumericValue("max_cpu_time", opt_.max_seconds);
  for (const auto& kv : opt_.ipopt_options) {
    const auto eq = kv.find('=');
    if (eq == std::string::npos) throw std::invalid_argument("Ipopt option '" + kv + "': expected name=value");
    const std::string name = kv.substr(0, eq), value = kv.substr(eq + 1);
    char* end = nullptr;
    const double num = std::strtod(value.c_str(), &end);
    bool ok;
    if (end && *end == '\0' && !value.empty())
      ok = value.find_first_of(".eE") == std::string::npos ? o->SetIntegerValue(name, static_cast<int>(num))
                                                          : o->SetNumericValue(name, num);
    else
      ok = o->SetStringValue(name, value);
    if (!ok) throw std::invalid_argument("Ipopt refuses option '" + kv + "'");
  }
  if (app->Initialize() != ::Ipopt::Solve_Succeeded) throw std::runtime_error("Ipopt failed to initialize");
}

PostureGenerator::~PostureGenerator() = default;

namespace {

// A call solved a second time answers with the second solve, costed with
// both: its solves, iterations and wall time.
void countEarlierSolve(PostureResult& second, const PostureResult& first) {
  second.solves += first.solves;
  second.iterations += first.iterations;
  second.seconds += first.seconds;
}

}  // namespace

PostureResult PostureGenerator::solve(const PostureRequest& request, const std::atomic<bool>* stop) {
  PostureResult res = solveHeld(request, stop);
  if (res.success() || res.status == PostureResult::Status::BadInput ||
      res.status == PostureResult::Status::Stopped || !request.retry_guess)
    return res;
  PostureRequest again = request;
  again.initial_guess = *request.retry_guess;
  again.retry_guess.reset();
  PostureResult second = solveHeld(again, stop);
  second.retried = true;
  countEarlierSolve(second, res);
  return second;
}

bool PostureGenerator::footprintOffTheSurface(const PostureRequest& request, const PostureResult& res,
                                              bool half_turn_only) const {
  if (!request.floating || !res.success()) return false;
  const FloatingContact& f = *request.floating;
  const Surface& s = scene_->surfaces()[f.surface];
  Kinematics kin(robot_);
  kin.setConfiguration(res.configuration);
  const Eigen::Isometry3d spot = kin.spotPose(f.spot);
  if (half_turn_only && spot.linear().col(0).dot(contactFrame(s, res.floating).linear().col(0)) >= 0) return false;
  const Eigen::Isometry3d in_surface = s.frame.inverse() * spot;
  for (const auto& v : robot_->spots()[f.spot].polygon.vertices())
    if (s.polygon.signedDistance((in_surface * Eigen::Vector3d(v.x(), v.y(), 0)).head<2>()) > kContactPolygonTolerance)
      return true;
  return false;
}

// The contact rows fix the floating spot's angle only modulo pi, and the
// footprint rows hold its polygon at the solver's angle: a solve that ends
// with the spot half a turn from that angle (a sole on a surface whose frame
// faces the other way) has held the sole turned about its origin, which for
// a polygon that is not its own half turn is another footprint (HRP-2's
// sole: 6.3 cm along the foot). When the spot's own footprint is then off
// the surface (beyond the contract's tolerance: what the independent check
// would refuse), the request is solved again with the footprint rows turned
// (FloatingContact::footprint_turned), from the same guess: the solve ends
// on the same branch, its footprint now the spot's. Solves whose footprint
// the check accepts are kept as they are: their witnesses, and every search
// built on them, are what they were.
PostureResult PostureGenerator::solveHeld(const PostureRequest& request, const std::atomic<bool>* stop) {
  PostureResult res = solveOnce(request, stop);
  if (!request.floating || request.floating->footprint_turned || !footprintOffTheSurface(request, res, true))
    return res;
  PostureRequest turned = request;
  turned.floating->footprint_turned = true;
  PostureResult second = solveOnce(turned, stop);
  second.footprint_turned = true;
  countEarlierSolve(second, res);
  if (footprintOffTheSurface(turned, second, false)) {  // ended on the other branch: neither footprint held
    second.status = PostureResult::Status::Infeasible;
    second.reason = "the floating spot's footprint leaves its surface with its polygon held either way";
  }
  return second;
}

PostureResult PostureGenerator::solveOnce(const PostureRequest& request, const std::atomic<bool>* stop) {
  const auto t0 = std::chrono::steady_clock::now();
  PostureResult res;
  res.configuration = request.initial_guess;
  auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(); };
  std::unique_ptr<PostureProblem> problem;
  try {
    problem = std::make_unique<PostureProblem>(robot_, scene_, collision_, request, opt_.problem);
  } catch (const std::invalid_argument& e) {
    res.status = PostureResult::Status::BadInput;
    res.reason = e.what();
    res.seconds = elapsed();
    return res;
  }

  Eigen::VectorXd x0 = problem->initialPoint();
  for (int round = 0; round <= opt_.collision_rounds; ++round) {
    const auto kind = opt_.hessian == "lbfgs"      ? PostureTNLP::Hessian::LBFGS
                      : opt_.hessian == "analytic" ? PostureTNLP::Hessian::Analytic
                                                   : PostureTNLP::Hessian::Diagonal;
    ::Ipopt::SmartPtr<PostureTNLP> nlp = new PostureTNLP(*problem, x0, kind);
    nlp->stop_at_restoration = opt_.stop_at_restoration;
    nlp->stop = stop;
    const double budget = opt_.max_seconds - elapsed();
    if (budget <= 0) {
      res.status = PostureResult::Status::TimeLimit;
      res.reason = "time limit reached before the solve";
      break;
    }
    ipopt_->app->Options()->SetNumericValue("max_cpu_time", budget);
    ipopt_->app->OptimizeTNLP(nlp);
    res.iterations += nlp->iterations;
    const Eigen::VectorXd& x = nlp->x_final.size() ? nlp->x_final : x0;
    res.configuration = problem->configurationAt(x);
    res.floating = problem->floatingAt(x);
    res.forces = problem->forcesAt(x);
    res.cost = nlp->final_cost;
    switch (nlp->final_status) {
      case ::Ipopt::SUCCESS:
      case ::Ipopt::STOP_AT_ACCEPTABLE_POINT:
        res.status = PostureResult::Status::Success;
        break;
      case ::Ipopt::MAXITER_EXCEEDED:
        res.status = PostureResult::Status::IterationLimit;
        res.reason = "no feasible posture within " + std::to_string(opt_.max_iterations) + " iterations";
        break;
      case ::Ipopt::CPUTIME_EXCEEDED:
        res.status = PostureResult::Status::TimeLimit;
        res.reason = "no feasible posture within the time limit";
        break;
      case ::Ipopt::USER_REQUESTED_STOP:
        if (nlp->stopped) {
          res.status = PostureResult::Status::Stopped;
          res.reason = "stopped by its caller";
          break;
        }
        res.status = PostureResult::Status::Infeasible;
        res.reason = nlp->entered_restoration
                         ? "no step toward feasibility from the initial guess (the solver entered its restoration phase)"
                         : "the solver was stopped";
        break;
      case ::Ipopt::LOCAL_INFEASIBILITY:
        res.status = PostureResult::Status::Infeasible;
        res.reason = "the constraints are locally infeasible";
        break;
      default:
        res.status = PostureResult::Status::Infeasible;
        res.reason = "the solver stopped without a feasible posture (Ipopt status " +
                     std::to_string(static_cast<int>(nlp->final_status)) + ")";
        break;
    }
    if (!res.success()) break;
    // Pairs left out of the problem may collide at the solution: add those
    // near it (the problem drops a contacting body's own surface) and, if one
    // of them collides, solve again from there.
    Kinematics kin(robot_);
    kin.setConfiguration(res.configuration);
    const std::set<int> before(problem->collisionPairs().begin(), problem->collisionPairs().end());
    problem->addCollisionPairs(collision_->pairsWithin(kin, opt_.problem.collision_cutoff));
    bool collides = false;
    for (int p : problem->collisionPairs())
      if (!before.count(p) && collision_->pairDistance(kin, p, false).distance < 0) collides = true;
    if (!collides) break;
    if (round == opt_.collision_rounds) {
      res.status = PostureResult::Status::Infeasible;
      res.reason = "collisions with pairs outside the problem remain after " + std::to_string(round + 1) + " solves";
      break;
    }
    x0 = x;  // warm start from the colliding solution with the new rows
  }
  res.seconds = elapsed();
  return res;
}

}  // namespace acyclic
