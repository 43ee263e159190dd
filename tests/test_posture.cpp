// The posture generator: its derivatives against finite differences, and the
// cases of the posture-generator issue, each result re-verified by the
// independent validity check (limits, contacts, collisions, quasi-static LP).
#include <dlfcn.h>
#include <gtest/gtest.h>

#include <atomic>
#include <functional>
#include <random>
#include <regex>
#include <set>
#include <sstream>
#include <thread>

#include "planner/check/quasi_static.h"
#include "planner/check/validity.h"
#include "planner/plan/plan.h"
#include "planner/posture/kkt_ldl.h"
#include "planner/posture/posture_generator.h"
#include "planner/scene/friction.h"
#include "test_support.h"

using namespace acyclic;

namespace {

const Scenario& chair() {
  static Scenario sc = Scenario::load(test::sourcePath("models/scenarios/chair_table.yaml"));
  return sc;
}

ContactSpec contactOf(const Scenario& sc, const std::string& spot, const std::string& surface, bool supporting,
                      const Configuration& at) {
  Kinematics k(sc.robot);
  k.setConfiguration(at);
  ContactSpec c;
  c.spot = sc.robot->spotIndex(spot);
  c.surface = sc.scene->surfaceIndex(surface);
  c.supporting = supporting;
  c.placement = projectOnSurface(sc.scene->surfaces()[c.surface], k.spotPose(c.spot));
  return c;
}

// Every part of the contract holds for the result (independent check).
void expectValid(const Scenario& sc, const PostureResult& r, std::vector<ContactSpec> stance) {
  ValidityChecker checker(sc.robot, sc.scene);
  const ValidityReport rep = checker.checkPosture(r.configuration, stance);
  for (const auto& p : rep.parts) {
    EXPECT_TRUE(p.checked) << p.name;
    EXPECT_TRUE(p.ok()) << p.name << ": " << p.summary << (p.violations.empty() ? "" : " | " + p.violations[0]);
  }
}

Configuration perturbed(const Configuration& q, std::mt19937& rng, double joint_sigma, double base_sigma) {
  std::normal_distribution<double> n(0, 1);
  Configuration p = q;
  for (int j = 0; j < p.joints.size(); ++j) p.joints[j] += joint_sigma * n(rng);
  p.base_position += base_sigma * Eigen::Vector3d(n(rng), n(rng), n(rng));
  return p;
}

PostureRequest wristOnTable(const Scenario& sc) {
  PostureRequest r;
  r.contacts = sc.start_stance;
  r.initial_guess = sc.start;
  FloatingContact f;
  f.spot = sc.robot->spotIndex("l_wrist");
  f.surface = sc.scene->surfaceIndex("table_top");
  f.volume.polygon = sc.scene->surfaces()[f.surface].polygon;  // anywhere on the table top
  r.floating = f;
  return r;
}

// The floating contact of a request, placed where a result put it: geometric
// only (being added), as the next stance of a search holds it.
ContactSpec placedContact(const PostureRequest& r, const PostureResult& res) {
  ContactSpec c;
  c.spot = r.floating->spot;
  c.surface = r.floating->surface;
  c.supporting = false;
  c.placement = res.floating;
  return c;
}

// Central differences of the problem's cost at x, variable by variable.
Eigen::VectorXd numericCostGradient(PostureProblem& p, const Eigen::VectorXd& x) {
  Eigen::VectorXd g(x.size());
  for (int i = 0; i < x.size(); ++i) {
    const double h = 1e-6;
    Eigen::VectorXd a = x, b = x;
    a[i] += h;
    b[i] -= h;
    g[i] = (p.cost(a) - p.cost(b)) / (2 * h);
  }
  return g;
}

}  // namespace

// Stability margins: the statics rows' corners and generators change (and
// so every derivative through them).
PostureOptions withMargins() {
  PostureOptions o;
  o.support_inset = 0.02;
  o.support_inset_y = 0.03;
  o.friction_share = 0.8;
  return o;
}

// The problems whose derivatives are checked: the left wrist floating on the
// table, with and without stability margins, its footprint rows as they are
// and held half a turn round (FloatingContact::footprint_turned).
struct DerivativeCase {
  std::string name;
  PostureOptions options;
  PostureRequest request;
};
std::vector<DerivativeCase> derivativeCases(const Scenario& sc) {
  std::vector<DerivativeCase> cases;
  for (const bool margins : {false, true})
    for (const bool turned : {false, true}) {
      DerivativeCase c{std::string(margins ? "with margins" : "without margins") + (turned ? ", footprint turned" : ""),
                       margins ? withMargins() : PostureOptions{}, wristOnTable(sc)};
      c.request.floating->footprint_turned = turned;
      cases.push_back(std::move(c));
    }
  return cases;
}

TEST(PostureProblem, DerivativesMatchFiniteDifferences) {
  const Scenario& sc = chair();
  auto cm = std::make_shared<CollisionModel>(sc.robot, sc.scene);
  for (const DerivativeCase& dc : derivativeCases(sc)) {
  SCOPED_TRACE(dc.name);
  PostureProblem p(sc.robot, sc.scene, cm, dc.request, dc.options);
  std::mt19937 rng(3);
  std::normal_distribution<double> n(0, 0.05);
  for (int trial = 0; trial < 2; ++trial) {
    Eigen::VectorXd x = p.initialPoint();
    for (int i = 0; i < p.numVariables(); ++i) x[i] += i < sc.robot->tangentSize() + 3 ? n(rng) : std::abs(n(rng));
    const Eigen::MatrixXd J = p.constraintJacobian(x);
    const Eigen::VectorXd gf = p.costGradient(x);
    Eigen::MatrixXd Jn(J.rows(), J.cols());
    for (int i = 0; i < x.size(); ++i) {
      const double h = 1e-6;
      Eigen::VectorXd a = x, b = x;
      a[i] += h;
      b[i] -= h;
      Jn.col(i) = (p.constraints(a) - p.constraints(b)) / (2 * h);
    }
    EXPECT_LT(test::relativeError(gf, numericCostGradient(p, x)), 1e-6);
    auto block = [&](int r0, int r1) {
      return test::relativeError(J.middleRows(r0, r1 - r0), Jn.middleRows(r0, r1 - r0));
    };
    EXPECT_LT(block(0, p.contactRows()), 1e-6) << "contact rows";
    EXPECT_LT(block(p.contactRows(), p.statics_row()), 1e-6) << "floating-contact rows";
    EXPECT_LT(block(p.statics_row(), p.collisionRow()), 1e-6) << "statics rows";
    // Collision rows are signed distances; their gradients are exact where
    // the shapes are apart (GJK witness points), an estimate where they
    // overlap (MPR depth): compared on the pairs apart at x.
    const Eigen::VectorXd g = p.constraints(x);
    std::vector<int> apart;
    for (int r = p.collisionRow(); r < p.numConstraints(); ++r)
      if (g[r] > 1e-3) apart.push_back(r);
    ASSERT_GT(apart.size(), 10u) << "too few collision pairs apart to compare";
    Eigen::MatrixXd Ja(apart.size(), J.cols()), Jna(apart.size(), J.cols());
    for (std::size_t k = 0; k < apart.size(); ++k) Ja.row(k) = J.row(apart[k]), Jna.row(k) = Jn.row(apart[k]);
    EXPECT_LT(test::relativeError(Ja, Jna), 1e-3) << "collision rows of pairs apart (GJK accuracy)";
    // The declared sparsity covers every nonzero.
    std::set<std::pair<int, int>> s(p.jacobianStructure().begin(), p.jacobianStructure().end());
    for (int r = 0; r < J.rows(); ++r)
      for (int c = 0; c < J.cols(); ++c)
        if (std::abs(Jn(r, c)) > 1e-7) {
          EXPECT_TRUE(s.count({r, c})) << "row " << r << " col " << c;
        }
  }
  }
}

TEST(PostureProblem, SpotTargetsOfTheReferenceCostMatchFiniteDifferences) {
  // The reference cost with two spots pulled toward world points (a free
  // foot and a free hand kept on their paths by the interpolator).
  const Scenario& sc = chair();
  auto cm = std::make_shared<CollisionModel>(sc.robot, sc.scene);
  PostureRequest r = wristOnTable(sc);
  std::vector<ReferencePostureCost::SpotTarget> targets(2);
  targets[0].spot = sc.robot->spotIndex("r_sole");
  targets[0].point = Eigen::Vector3d(0.1, -0.2, 0.05);
  targets[0].weight = 100;
  targets[1].spot = sc.robot->spotIndex("r_palm");
  targets[1].point = Eigen::Vector3d(0.3, -0.3, 0.7);
  targets[1].weight = 30;
  r.cost = std::make_shared<ReferencePostureCost>(sc.start, 1.0, 10.0, 1.0, targets);
  PostureProblem p(sc.robot, sc.scene, cm, r, {});
  std::mt19937 rng(5);
  std::normal_distribution<double> n(0, 0.05);
  Eigen::VectorXd x = p.initialPoint();
  for (int i = 0; i < sc.robot->tangentSize(); ++i) x[i] += n(rng);
  const Eigen::VectorXd g = p.costGradient(x);
  EXPECT_LT(test::relativeError(g, numericCostGradient(p, x)), 1e-6);
  // The targets count: without them the cost and its gradient differ.
  PostureRequest plain = r;
  plain.cost = std::make_shared<ReferencePostureCost>(sc.start);
  PostureProblem q(sc.robot, sc.scene, cm, plain, {});
  EXPECT_GT(p.cost(x) - q.cost(x), 1.0);
  EXPECT_GT((g - q.costGradient(x)).norm(), 1.0);
}

TEST(PostureProblem, LagrangianHessianMatchesFiniteDifferences) {
  // Every block but the collision rows' curvature (left out, multipliers zero
  // here) and the base rotation's own block (second-order parameterization
  // terms, checked loosely) against differences of the constraint Jacobian.
  const Scenario& sc = chair();
  auto cm = std::make_shared<CollisionModel>(sc.robot, sc.scene);
  for (const DerivativeCase& dc : derivativeCases(sc)) {
  SCOPED_TRACE(dc.name);
  PostureProblem p(sc.robot, sc.scene, cm, dc.request, dc.options);
  std::mt19937 rng(2);
  std::normal_distribution<double> n(0, 0.05);
  Eigen::VectorXd x = p.initialPoint();
  for (int i = 0; i < p.numVariables(); ++i)
    if (i < 3 || (i >= 6 && i < sc.robot->tangentSize() + 3)) x[i] += n(rng);  // base rotation at the guess
  Eigen::VectorXd y = Eigen::VectorXd::Zero(p.numConstraints());
  for (int i = 0; i < p.collisionRow(); ++i) y[i] = 10 * n(rng);  // contact, floating and statics rows
  const Eigen::MatrixXd H = p.lagrangianHessian(x, 0.0, y);
  EXPECT_LT((H - H.transpose()).norm(), 1e-12);
  Eigen::MatrixXd Hn(x.size(), x.size());
  for (int i = 0; i < x.size(); ++i) {
    Eigen::VectorXd a = x, b = x;
    a[i] += 1e-6;
    b[i] -= 1e-6;
    // the Jacobian is a reference to the problem's cache: copy each product before the next evaluation
    const Eigen::VectorXd ga = p.constraintJacobian(a).transpose() * y;
    const Eigen::VectorXd gb = p.constraintJacobian(b).transpose() * y;
    Hn.col(i) = (ga - gb) / 2e-6;
  }
  const int nq = sc.robot->tangentSize(), nx = p.numVariables();
  auto block = [&](int r0, int nr, int c0, int nc) {
    return test::relativeError(H.block(r0, c0, nr, nc), Hn.block(r0, c0, nr, nc));
  };
  EXPECT_LT(block(6, nq - 6, 6, nq - 6), 1e-6) << "joints x joints";
  EXPECT_LT(block(0, 3, 0, nq), 1e-6) << "base translation x configuration";
  EXPECT_LT(block(3, 3, 6, nq - 6), 1e-6) << "base rotation x joints";
  EXPECT_LT(block(3, 3, 3, 3), 1e-3) << "base rotation x base rotation";
  EXPECT_LT(block(nq, 3, 0, nq + 3), 1e-6) << "floating contact";
  EXPECT_LT(block(nq + 3, nx - nq - 3, 0, nq), 1e-6) << "forces x configuration";
  }
}

// The chair's start stance with the left wrist held at a world pose (the
// interpolator's moving body): its current pose raised and turned a little.
PostureRequest wristAtPose(const Scenario& sc) {
  PostureRequest r;
  r.contacts = sc.start_stance;
  r.initial_guess = sc.start;
  Kinematics k(sc.robot);
  k.setConfiguration(sc.start);
  PoseTarget t;
  t.spot = sc.robot->spotIndex("l_wrist");
  t.pose = k.spotPose(t.spot);
  t.pose.translation() += Eigen::Vector3d(0.02, -0.01, 0.03);
  t.pose.linear() = Eigen::AngleAxisd(0.1, Eigen::Vector3d(1, 2, 0).normalized()).toRotationMatrix() * t.pose.linear();
  r.pose_target = t;
  return r;
}

TEST(PostureProblem, PoseTargetRowsMatchFiniteDifferences) {
  const Scenario& sc = chair();
  auto cm = std::make_shared<CollisionModel>(sc.robot, sc.scene);
  PostureProblem p(sc.robot, sc.scene, cm, wristAtPose(sc), {});
  // 4 contacts, then the pose target's 6 rows.
  ASSERT_EQ(p.contactRows(), 6 * 5);
  std::mt19937 rng(5);
  std::normal_distribution<double> n(0, 0.05);
  Eigen::VectorXd x = p.initialPoint();
  for (int i = 0; i < sc.robot->tangentSize(); ++i)
    if (i < 3 || i >= 6) x[i] += n(rng);  // base rotation at the guess (see the Hessian test)
  const Eigen::MatrixXd J = p.constraintJacobian(x);
  const Eigen::VectorXd g0 = p.constraints(x);
  EXPECT_GT(g0.segment(24, 6).norm(), 1e-3);  // the target is not met at the guess
  Eigen::MatrixXd Jn(J.rows(), J.cols());
  for (int i = 0; i < x.size(); ++i) {
    Eigen::VectorXd a = x, b = x;
    a[i] += 1e-6;
    b[i] -= 1e-6;
    Jn.col(i) = (p.constraints(a) - p.constraints(b)) / 2e-6;
  }
  EXPECT_LT(test::relativeError(J.middleRows(24, 6), Jn.middleRows(24, 6)), 1e-6) << "pose target rows";
  std::set<std::pair<int, int>> s(p.jacobianStructure().begin(), p.jacobianStructure().end());
  for (int r = 24; r < 30; ++r)
    for (int c = 0; c < J.cols(); ++c)
      if (std::abs(Jn(r, c)) > 1e-7) {
        EXPECT_TRUE(s.count({r, c})) << "row " << r << " col " << c;
      }
  // Its curvature in the Lagrangian's Hessian, multipliers on its rows only.
  Eigen::VectorXd y = Eigen::VectorXd::Zero(p.numConstraints());
  for (int r = 24; r < 30; ++r) y[r] = 10 * n(rng);
  const Eigen::MatrixXd H = p.lagrangianHessian(x, 0.0, y);
  Eigen::MatrixXd Hn(x.size(), x.size());
  for (int i = 0; i < x.size(); ++i) {
    Eigen::VectorXd a = x, b = x;
    a[i] += 1e-6;
    b[i] -= 1e-6;
    const Eigen::VectorXd ga = p.constraintJacobian(a).transpose() * y;
    const Eigen::VectorXd gb = p.constraintJacobian(b).transpose() * y;
    Hn.col(i) = (ga - gb) / 2e-6;
  }
  const int nq = sc.robot->tangentSize();
  EXPECT_LT(test::relativeError(H.block(6, 6, nq - 6, nq - 6), Hn.block(6, 6, nq - 6, nq - 6)), 1e-6);
  EXPECT_LT(test::relativeError(H.block(0, 0, 3, nq), Hn.block(0, 0, 3, nq)), 1e-6);
}

TEST(PostureGenerator, PoseTargetIsReached) {
  const Scenario& sc = chair();
  PostureGenerator pg(sc.robot, sc.scene);
  const PostureRequest r = wristAtPose(sc);
  const PostureResult res = pg.solve(r);
  ASSERT_TRUE(res.success()) << toString(res.status) << ": " << res.reason;
  Kinematics k(sc.robot);
  k.setConfiguration(res.configuration);
  const Eigen::Isometry3d at = k.spotPose(r.pose_target->spot);
  EXPECT_LT((at.translation() - r.pose_target->pose.translation()).norm(), 1e-5);
  EXPECT_LT(Eigen::AngleAxisd(at.linear().transpose() * r.pose_target->pose.linear()).angle(), 1e-4);
  expectValid(sc, res, sc.start_stance);
  // A pose target on a spot that is also in a contact is refused with a reason.
  PostureRequest bad = r;
  bad.pose_target->spot = sc.robot->spotIndex("r_sole");
  const PostureResult b = pg.solve(bad);
  EXPECT_EQ(b.status, PostureResult::Status::BadInput);
  EXPECT_NE(b.reason.find("r_sole"), std::string::npos) << b.reason;
}

TEST(PostureGenerator, PoseTargetOrientationTolerance) {
  // Seated, the hanging left arm cannot raise its wrist 2 cm keeping the
  // wrist's orientation exactly; within a tolerance on the orientation rows it can.
  const Scenario& sc = chair();
  PostureGenerator pg(sc.robot, sc.scene);
  Kinematics k(sc.robot);
  k.setConfiguration(sc.start);
  PostureRequest r;
  r.contacts = sc.start_stance;
  r.initial_guess = sc.start;
  PoseTarget t;
  t.spot = sc.robot->spotIndex("l_wrist");
  t.pose = k.spotPose(t.spot);
  t.pose.translation().z() += 0.02;
  r.pose_target = t;
  EXPECT_FALSE(pg.solve(r).success());
  r.pose_target->orientation_tolerance = 0.3;
  const PostureResult res = pg.solve(r);
  ASSERT_TRUE(res.success()) << res.reason;
  expectValid(sc, res, sc.start_stance);
  k.setConfiguration(res.configuration);
  const Eigen::Isometry3d at = k.spotPose(t.spot);
  EXPECT_LT((at.translation() - t.pose.translation()).norm(), 1e-5);
  const Eigen::Matrix3d S = at.linear(), T = t.pose.linear();
  for (double row : {S.col(2).dot(T.col(0)), S.col(2).dot(T.col(1)), S.col(0).dot(T.col(1))})
    EXPECT_LE(std::abs(row), 0.3 + 1e-6);
  // The bound is checked: outside [0, 1) the request is refused.
  r.pose_target->orientation_tolerance = 1.5;
  EXPECT_EQ(pg.solve(r).status, PostureResult::Status::BadInput);
  // Position bounds in the target's frame: held within 1 cm across its z, exactly along it.
  r.pose_target->orientation_tolerance = 0.3;
  r.pose_target->pose.translation() += t.pose.linear() * Eigen::Vector3d(0.05, 0, 0);  // 5 cm off along its x
  r.pose_target->position_tolerance = Eigen::Vector3d(0.01, 0.01, 0);
  const PostureResult boxed = pg.solve(r);
  ASSERT_TRUE(boxed.success()) << boxed.reason;
  k.setConfiguration(boxed.configuration);
  const Eigen::Vector3d off = r.pose_target->pose.linear().transpose() *
                              (k.spotPose(t.spot).translation() - r.pose_target->pose.translation());
  EXPECT_LE(std::abs(off.x()), 0.01 + 1e-6);
  EXPECT_LE(std::abs(off.y()), 0.01 + 1e-6);
  EXPECT_LE(std::abs(off.z()), 1e-6);
  expectValid(sc, boxed, sc.start_stance);
}

TEST(PostureProblem, StaticsRowsAreSimbodysGravityTorques) {
  // With no contact force the joint rows are Simbody's g(q) / weight.
  const Scenario& sc = chair();
  auto cm = std::make_shared<CollisionModel>(sc.robot, sc.scene);
  PostureRequest r;
  r.contacts = sc.start_stance;
  r.initial_guess = sc.start;
  PostureProblem p(sc.robot, sc.scene, cm, r, {});
  Eigen::VectorXd x = Eigen::VectorXd::Zero(p.numVariables());
  const Eigen::VectorXd g = p.constraints(x);
  Kinematics k(sc.robot);
  k.setConfiguration(sc.start);
  const double W = sc.robot->totalMass() * 9.81;
  const Eigen::VectorXd simbody = k.gravityTorques() / W;
  EXPECT_LT((g.segment(p.statics_row(), 3) - simbody.head<3>()).norm(), 1e-12);
  EXPECT_LT((g.segment(p.statics_row() + 6, 30) - simbody.tail(30)).norm(), 1e-12);
}

TEST(PostureGenerator, ChairStartFromPerturbedGuess) {  // (a)
  const Scenario& sc = chair();
  PostureGenerator pg(sc.robot, sc.scene);
  std::mt19937 rng(1);
  for (int trial = 0; trial < 3; ++trial) {
    PostureRequest r;
    r.contacts = sc.start_stance;
    r.initial_guess = perturbed(sc.start, rng, 0.08, 0.03);
    r.cost = std::make_shared<ReferencePostureCost>(sc.start);
    const PostureResult res = pg.solve(r);
    ASSERT_TRUE(res.success()) << toString(res.status) << ": " << res.reason;
    expectValid(sc, res, sc.start_stance);
    ASSERT_EQ(res.forces.size(), 4u);  // every start contact supports
  }
}

TEST(PostureGenerator, EveryLinearSolverSolvesTheSameStance) {
  // The linear solver (kkt_ldl.h's LDL^T or MUMPS) and where L-BFGS's
  // low-rank part goes (rows of the KKT system, or Sherman-Morrison around
  // it) change how Ipopt solves its linear systems, not the problem: the
  // chair's start stance from the same perturbed guess is solved each way, to
  // the same posture within the solver's tolerances, and the independent
  // check accepts each.
  const Scenario& sc = chair();
  PostureRequest r;
  r.contacts = sc.start_stance;
  r.initial_guess = sc.start;
  r.initial_guess.base_position += Eigen::Vector3d(0.02, -0.01, 0.01);
  r.initial_guess.joints.array() += 0.05;
  r.cost = std::make_shared<ReferencePostureCost>(sc.start);
  PostureGeneratorOptions o;
  ASSERT_EQ(o.linear_solver, "ldl");  // the defaults
  ASSERT_TRUE(o.lbfgs_in_kkt);
  std::vector<PostureResult> results;
  for (const char* solver : {"ldl", "mumps"})
    for (bool in_kkt : {true, false}) {
      o.linear_solver = solver;
      o.lbfgs_in_kkt = in_kkt;
      results.push_back(PostureGenerator(sc.robot, sc.scene, o).solve(r));
    }
  ValidityChecker checker(sc.robot, sc.scene);
  for (const PostureResult& res : results) {
    ASSERT_TRUE(res.success()) << res.reason;
    EXPECT_LT(difference(results[0].configuration, res.configuration).cwiseAbs().maxCoeff(), 0.02);
    EXPECT_TRUE(checker.checkPosture(res.configuration, r.contacts).valid());
  }
}

TEST(PostureGenerator, MisuseIsRefusedAtConstruction) {
  // The LDL^T needs a diagonal Hessian block; a full one is misuse, said at
  // construction rather than as a failed solve.
  const Scenario& sc = chair();
  PostureGeneratorOptions o;
  o.hessian = "analytic";
  EXPECT_THROW(PostureGenerator(sc.robot, sc.scene, o), std::invalid_argument);
  o.linear_solver = "mumps";
  EXPECT_NO_THROW(PostureGenerator(sc.robot, sc.scene, o));
  o.linear_solver = "pardiso";
  EXPECT_THROW(PostureGenerator(sc.robot, sc.scene, o), std::invalid_argument);
  PostureGeneratorOptions m;
  m.mu_oracle = "probing";
  EXPECT_NO_THROW(PostureGenerator(sc.robot, sc.scene, m));
  m.mu_oracle = "fast";
  EXPECT_THROW(PostureGenerator(sc.robot, sc.scene, m), std::invalid_argument);
}

TEST(PostureGenerator, HalfSittingDoubleSupport) {  // (b)
  const Scenario& sc = chair();
  const Configuration hs = sc.robot->posture("half_sitting");
  Configuration at = hs;
  at.base_position = Eigen::Vector3d(-0.6, -0.8, hs.base_position.z());  // in the open
  const std::vector<ContactSpec> stance = {contactOf(sc, "r_sole", "floor", true, at),
                                           contactOf(sc, "l_sole", "floor", true, at)};
  PostureGenerator pg(sc.robot, sc.scene);
  std::mt19937 rng(2);
  PostureRequest r;
  r.contacts = stance;
  r.initial_guess = perturbed(at, rng, 0.1, 0.05);
  r.cost = std::make_shared<ReferencePostureCost>(at);
  const PostureResult res = pg.solve(r);
  ASSERT_TRUE(res.success()) << toString(res.status) << ": " << res.reason;
  expectValid(sc, res, stance);
  // Both feet carry the weight: total normal force = weight.
  double fz = 0;
  for (const auto& c : res.forces)
    for (const auto& f : c.forces) fz += f.z();
  EXPECT_NEAR(fz, sc.robot->totalMass() * 9.81, 1e-3);
}

// On the left foot alone (the right one on the floor but not loaded): the
// CoM is above the centre of pressure. Without margins the posture nearest
// half-sitting puts it on the sole's edge; with an inset of 2 cm it is at
// least 2 cm inside every edge, and the friction used within its share.
TEST(PostureGenerator, StabilityMarginsKeepTheCentreOfPressureInside) {
  const Scenario& sc = chair();
  const Configuration hs = sc.robot->posture("half_sitting");
  Configuration at = hs;
  at.base_position = Eigen::Vector3d(-0.6, -0.8, hs.base_position.z());  // in the open
  const std::vector<ContactSpec> stance = {contactOf(sc, "r_sole", "floor", false, at),
                                           contactOf(sc, "l_sole", "floor", true, at)};
  const ConvexPolygon& sole = sc.robot->spots()[stance[1].spot].polygon;
  const Eigen::Isometry3d frame = contactFrame(sc.scene->surfaces()[stance[1].surface], stance[1].placement);
  auto comDepth = [&](const PostureResult& res) {  // the CoM's distance inside the sole's edges
    Kinematics k(sc.robot);
    k.setConfiguration(res.configuration);
    const Eigen::Vector3d c = frame.inverse() * k.centerOfMass();
    return -sole.signedDistance(c.head<2>());
  };
  PostureRequest r;
  r.contacts = stance;
  r.initial_guess = at;
  r.cost = std::make_shared<ReferencePostureCost>(at);
  PostureGeneratorOptions plain;
  const PostureResult edge = PostureGenerator(sc.robot, sc.scene, plain).solve(r);
  ASSERT_TRUE(edge.success()) << toString(edge.status) << ": " << edge.reason;
  expectValid(sc, edge, stance);
  EXPECT_LT(comDepth(edge), 0.01);
  PostureGeneratorOptions margins;
  margins.problem.support_inset = 0.02;
  margins.problem.friction_share = 0.8;
  const PostureResult inside = PostureGenerator(sc.robot, sc.scene, margins).solve(r);
  ASSERT_TRUE(inside.success()) << toString(inside.status) << ": " << inside.reason;
  expectValid(sc, inside, stance);
  EXPECT_GT(comDepth(inside), 0.02 - 1e-4);
  const Eigen::Vector3d n = frame.linear().col(2);
  const double mu = sc.scene->surfaces()[stance[1].surface].friction;
  for (const auto& c : inside.forces)
    for (std::size_t k = 0; k < c.forces.size(); ++k) {
      const Eigen::Vector3d p = frame.inverse() * c.points[k];
      EXPECT_NEAR(-sole.signedDistance(p.head<2>()), 0.02, 1e-9);  // a corner of the inset polygon
      EXPECT_LE(coneRatio(c.forces[k], n, mu), 0.8 + 1e-9);
    }
}

namespace {
std::atomic<int> observed{0}, observed_rows{0};
void countSystem(int n, int nz, const int*, const int*, const double*) {
  ++observed;
  observed_rows = n;
}
}  // namespace

TEST(PostureGenerator, ItsKktSystemsReachAnObserverWhileOneIsSet) {
  // bench_kkt collects Ipopt's systems through kkt::observeFactorizations:
  // each factorization of a solve is seen, a system as large as the problem
  // (its variables, two rows per inequality, one per equality), and none
  // once the observer is gone.
  const Scenario& sc = chair();
  PostureGenerator pg(sc.robot, sc.scene);
  PostureRequest r;
  r.contacts = sc.start_stance;
  r.initial_guess = sc.start;
  acyclic::kkt::observeFactorizations(countSystem);
  const PostureResult res = pg.solve(r);
  acyclic::kkt::observeFactorizations(nullptr);
  ASSERT_TRUE(res.success()) << res.reason;
  EXPECT_GT(observed.load(), 0);
  EXPECT_GE(observed.load(), res.iterations);
  EXPECT_GT(observed_rows.load(), 36 + 2 * 30);  // 36 coordinates, 30 two-sided torque rows at least
  const int seen = observed.load();
  pg.solve(r);
  EXPECT_EQ(observed.load(), seen);
}

TEST(PostureGenerator, LeftWristAnywhereOnTheTable) {  // (c)
  const Scenario& sc = chair();
  PostureGenerator pg(sc.robot, sc.scene);
  const PostureRequest r = wristOnTable(sc);
  const PostureResult res = pg.solve(r);
  ASSERT_TRUE(res.success()) << toString(res.status) << ": " << res.reason;
  EXPECT_TRUE(sc.scene->surfaces()[r.floating->surface].polygon.contains({res.floating.x, res.floating.y}));
  std::vector<ContactSpec> stance = sc.start_stance;
  stance.push_back(placedContact(r, res));
  expectValid(sc, res, stance);
}

TEST(PostureGenerator, AFloatingContactsPlacementIsAcceptedAsAFixedContact) {
  // The solver meets the floating polygon's bounds only to its tolerance; the
  // same placement, fixed in the next request, must not be refused.
  const Scenario& sc = chair();
  PostureGenerator pg(sc.robot, sc.scene);
  PostureRequest r = wristOnTable(sc);
  r.floating->volume.polygon = ConvexPolygon({{-0.4, -0.6}, {-0.3, -0.6}, {-0.3, 0.6}, {-0.4, 0.6}});  // the near edge
  const PostureResult a = pg.solve(r);
  ASSERT_TRUE(a.success()) << a.reason;
  PostureRequest next;
  next.contacts = sc.start_stance;
  next.contacts.push_back(placedContact(r, a));
  next.initial_guess = a.configuration;
  const PostureResult b = pg.solve(next);
  EXPECT_NE(b.status, PostureResult::Status::BadInput) << b.reason;
  EXPECT_TRUE(b.success()) << b.reason;
}

TEST(PostureGenerator, AFloatingSoleKeepsItsOwnFootprintOnASurfaceFacingTheOtherWay) {
  // The contact rows fix a spot's angle only modulo pi. On a pad whose frame
  // faces the other way than the robot, the solver's angle starts half a
  // turn from the sole's and stays there, and the footprint rows held the
  // sole turned about its ankle: HRP-2's sole reaches 0.14 m ahead of the
  // ankle and 0.077 m behind, so on this pad 0.24 m long, pulled back
  // toward where the foot stands, its toe ended 40 mm over the pad's front
  // edge and the independent check refused the posture. The generator now
  // solves such a request again with the footprint turned: valid. On the
  // same pad facing the robot's way one solve is enough.
  for (const double yaw : {180.0, 0.0}) {
    SCOPED_TRACE("pad frame turned " + std::to_string(yaw) + " degrees");
    test::TempDir dir;
    const Scenario sc = Scenario::load(test::padScenario(dir, yaw));
    PostureRequest r;
    for (const auto& c : sc.start_stance)
      if (sc.robot->spots()[c.spot].name == "l_sole") r.contacts.push_back(c);
    ASSERT_EQ(r.contacts.size(), 1u);
    r.initial_guess = sc.start;
    FloatingContact f;
    f.spot = sc.robot->spotIndex("r_sole");
    f.surface = sc.scene->surfaceIndex("pad");
    f.volume.polygon = sc.scene->surfaces()[f.surface].polygon;  // anywhere on the pad, any angle
    r.floating = f;
    PostureGenerator pg(sc.robot, sc.scene);
    const PostureResult res = pg.solve(r);
    ASSERT_TRUE(res.success()) << toString(res.status) << ": " << res.reason;
    EXPECT_EQ(res.footprint_turned, yaw == 180.0);
    EXPECT_EQ(res.solves, yaw == 180.0 ? 2 : 1);
    EXPECT_FALSE(res.retried);
    // The solver's angle and the sole's: half a turn apart on the turned pad.
    Kinematics k(sc.robot);
    k.setConfiguration(res.configuration);
    const double sole = projectOnSurface(sc.scene->surfaces()[f.surface], k.spotPose(f.spot)).theta;
    EXPECT_NEAR(std::abs(std::remainder(sole - res.floating.theta, 2 * M_PI)), yaw == 180.0 ? M_PI : 0.0, 0.2);
    std::vector<ContactSpec> stance = r.contacts;
    stance.push_back(placedContact(r, res));
    expectValid(sc, res, stance);  // the sole's corners on the pad among the rest
  }
}

TEST(PostureGenerator, ContactOutOfReachIsInfeasibleWithinItsTimeLimit) {  // (d)
  const Scenario& sc = chair();
  PostureGeneratorOptions o;
  o.max_seconds = 0.5;
  PostureGenerator pg(sc.robot, sc.scene, o);
  PostureRequest r = wristOnTable(sc);
  // The far edge of the table, a metre from the seated robot's shoulder.
  r.floating->volume.polygon = ConvexPolygon({{0.35, -0.1}, {0.4, -0.1}, {0.4, 0.1}, {0.35, 0.1}});
  const PostureResult res = pg.solve(r);
  EXPECT_EQ(res.status, PostureResult::Status::Infeasible) << toString(res.status) << ": " << res.reason;
  EXPECT_FALSE(res.reason.empty());
  EXPECT_LT(res.seconds, o.max_seconds * 1.5);
}

// stop_at_restoration (the planner's setting): a call that enters Ipopt's
// restoration phase gives up there, as infeasible; a feasible stance reached
// without it is still found.
TEST(PostureGenerator, StopAtRestorationGivesUpEarlierAndKeepsWhatIsReachable) {
  const Scenario& sc = chair();
  PostureGeneratorOptions patient, quick;
  quick.stop_at_restoration = true;
  PostureGenerator slow_pg(sc.robot, sc.scene, patient), quick_pg(sc.robot, sc.scene, quick);
  PostureRequest far = wristOnTable(sc);
  far.floating->volume.polygon = ConvexPolygon({{0.35, -0.1}, {0.4, -0.1}, {0.4, 0.1}, {0.35, 0.1}});
  const PostureResult a = slow_pg.solve(far), b = quick_pg.solve(far);
  EXPECT_FALSE(a.success());
  EXPECT_EQ(b.status, PostureResult::Status::Infeasible) << toString(b.status) << ": " << b.reason;
  EXPECT_NE(b.reason.find("restoration"), std::string::npos) << b.reason;
  EXPECT_LT(b.iterations, a.iterations);
  const PostureRequest anywhere = wristOnTable(sc);
  const PostureResult c = quick_pg.solve(anywhere);
  ASSERT_TRUE(c.success()) << c.reason;
  std::vector<ContactSpec> stance = sc.start_stance;
  stance.push_back(placedContact(anywhere, c));
  expectValid(sc, c, stance);
}

// The stop flag (the planner's chains of candidates, where a success makes
// the candidates after it useless): a flag left down changes nothing; one
// raised during the solve ends it at Ipopt's next iteration, as Stopped; one
// raised before, at once, with no retry. The flag is raised here from the
// KKT observer, on the solving thread at its fifth factorization, so that
// where it stops does not depend on timing; the planner raises it from the
// other generator's thread.
namespace {
std::atomic<int> factorizations{0};
std::atomic<bool> stop_flag{false};
void raiseStopAtTheFifth(int, int, const int*, const int*, const double*) {
  if (++factorizations == 5) stop_flag = true;
}
}  // namespace

TEST(PostureGenerator, AStopFlagEndsTheSolveAtTheNextIteration) {
  const Scenario& sc = chair();
  PostureGeneratorOptions o;
  o.max_seconds = 1e6;  // bounded by iterations only
  PostureGenerator pg(sc.robot, sc.scene, o);
  const PostureRequest r = wristOnTable(sc);
  const PostureResult plain = pg.solve(r);
  ASSERT_TRUE(plain.success()) << plain.reason;
  ASSERT_GT(plain.iterations, 10);  // long enough to stop in the middle

  stop_flag = false;
  const PostureResult down = pg.solve(r, &stop_flag);
  ASSERT_TRUE(down.success()) << down.reason;
  EXPECT_EQ(down.iterations, plain.iterations);
  EXPECT_EQ(down.configuration.joints, plain.configuration.joints);
  EXPECT_EQ(down.configuration.base_position, plain.configuration.base_position);

  factorizations = 0;
  acyclic::kkt::observeFactorizations(raiseStopAtTheFifth);
  const PostureResult stopped = pg.solve(r, &stop_flag);
  acyclic::kkt::observeFactorizations(nullptr);
  EXPECT_EQ(stopped.status, PostureResult::Status::Stopped) << toString(stopped.status) << ": " << stopped.reason;
  EXPECT_FALSE(stopped.reason.empty());
  EXPECT_GE(stopped.iterations, 1);
  EXPECT_LE(stopped.iterations, 5);  // at least one factorization per iteration: stopped by the sixth

  PostureRequest with_retry = r;
  with_retry.retry_guess = sc.start;
  stop_flag = true;
  const PostureResult at_once = pg.solve(with_retry, &stop_flag);
  EXPECT_EQ(at_once.status, PostureResult::Status::Stopped);
  EXPECT_EQ(at_once.iterations, 0);
  EXPECT_EQ(at_once.solves, 1);
}

TEST(PostureGenerator, OneThighWithTheCenterOfMassFarOutsideFailsOnEquilibrium) {  // (e)
  const Scenario& sc = chair();
  PostureGenerator pg(sc.robot, sc.scene);
  // All four start contacts kept in place; only the right thigh supports.
  std::vector<ContactSpec> stance = sc.start_stance;
  for (auto& c : stance) c.supporting = sc.robot->spots()[c.spot].name == "r_thigh";
  PostureRequest r;
  r.contacts = stance;
  r.initial_guess = sc.start;
  const PostureResult res = pg.solve(r);
  EXPECT_FALSE(res.success()) << "balanced on one thigh strip";
  // The same geometry with every contact supporting is feasible: equilibrium is what fails.
  r.contacts = sc.start_stance;
  EXPECT_TRUE(pg.solve(r).success());
  // The independent check agrees on the sitting posture.
  Kinematics k(sc.robot);
  k.setConfiguration(sc.start);
  const QuasiStaticReport q = QuasiStaticChecker(sc.robot, sc.scene).check(k, stance);
  EXPECT_FALSE(q.feasible);
  EXPECT_FALSE(q.reason.empty());
}

TEST(PostureGenerator, TorqueLimitsBind) {  // (f)
  // Standing on the right foot with the left foot held far forward (touching
  // the floor, not supporting): the left hip pitch holds the left leg out, and
  // no posture can take that load off it. With its limit cut to 3 N m the
  // same request has no solution, and the check refuses the strong robot's
  // posture, naming the joint.
  const Scenario& sc = chair();
  test::TempDir dir;
  std::string urdf = test::readFile(test::sourcePath("models/hrp2/hrp2.urdf"));
  const std::regex limit("(<joint name=\"LLEG_JOINT2\"[\\s\\S]*?effort=\")150(\")");
  urdf = std::regex_replace(urdf, limit, "$013$2", std::regex_constants::format_first_only);
  ASSERT_NE(urdf.find("effort=\"3\""), std::string::npos);
  dir.write("hrp2.urdf", urdf);
  dir.write("hrp2.yaml", test::readFile(test::sourcePath("models/hrp2/hrp2.yaml")));
  auto weak = RobotModel::load(dir.path() + "/hrp2.yaml");

  Configuration at = sc.robot->posture("half_sitting");
  at.base_position.x() = -0.6;
  at.base_position.y() = -0.8;
  ContactSpec right = contactOf(sc, "r_sole", "floor", true, at);
  ContactSpec left = contactOf(sc, "l_sole", "floor", false, at);
  left.placement.x += 0.45;  // a long step forward, not yet supporting
  PostureRequest r;
  r.contacts = {right, left};
  Configuration guess = at;
  guess.joints[sc.robot->jointIndex("LLEG_JOINT2")] = -0.8;
  guess.joints[sc.robot->jointIndex("LLEG_JOINT3")] = 0.4;
  r.initial_guess = guess;

  PostureGenerator strong_pg(sc.robot, sc.scene);
  const PostureResult strong = strong_pg.solve(r);
  ASSERT_TRUE(strong.success()) << toString(strong.status) << ": " << strong.reason;
  expectValid(sc, strong, r.contacts);

  PostureGenerator weak_pg(weak, sc.scene);
  const PostureResult w = weak_pg.solve(r);
  EXPECT_FALSE(w.success());
  Kinematics k(weak);
  k.setConfiguration(strong.configuration);
  const QuasiStaticReport q = QuasiStaticChecker(weak, sc.scene).check(k, r.contacts);
  EXPECT_FALSE(q.feasible);
  EXPECT_NE(q.reason.find("LLEG_JOINT2"), std::string::npos) << q.reason;
  EXPECT_GT(q.worst_torque_ratio, 1.0);
}

TEST(PostureGenerator, BadRequestsAreRefusedWithAReason) {
  const Scenario& sc = chair();
  PostureGenerator pg(sc.robot, sc.scene);
  PostureRequest r;
  r.contacts = sc.start_stance;
  r.initial_guess = sc.start;
  r.initial_guess.joints.resize(3);
  PostureResult res = pg.solve(r);
  EXPECT_EQ(res.status, PostureResult::Status::BadInput);
  EXPECT_NE(res.reason.find("joints"), std::string::npos) << res.reason;
  r.initial_guess = sc.start;
  for (auto& c : r.contacts) c.supporting = false;
  res = pg.solve(r);
  EXPECT_EQ(res.status, PostureResult::Status::BadInput);
  EXPECT_NE(res.reason.find("supporting"), std::string::npos) << res.reason;
  r.contacts = sc.start_stance;
  r.contacts.push_back(r.contacts[0]);
  EXPECT_EQ(pg.solve(r).status, PostureResult::Status::BadInput);
}

TEST(PostureGenerator, TwoGeneratorsOnTwoThreadsAgreeWithOne) {
  const Scenario& sc = chair();
  std::vector<PostureRequest> reqs;
  std::mt19937 rng(9);
  for (int i = 0; i < 4; ++i) {
    PostureRequest r;
    r.contacts = sc.start_stance;
    r.initial_guess = perturbed(sc.start, rng, 0.05, 0.02);
    reqs.push_back(r);
  }
  auto run = [&](std::vector<Eigen::VectorXd>& out) {
    // Bounded by iterations, not time: Ipopt's CPU time is the process's,
    // both threads' together, and a loaded machine must not change a result.
    PostureGeneratorOptions o;
    o.max_seconds = 1e6;
    PostureGenerator pg(sc.robot, sc.scene, o);
    for (const auto& r : reqs) {
      const PostureResult res = pg.solve(r);
      EXPECT_TRUE(res.success()) << res.reason;
      out.push_back(res.configuration.joints);
    }
  };
  std::vector<Eigen::VectorXd> ref, a, b;
  run(ref);
  std::thread ta([&] { run(a); }), tb([&] { run(b); });
  ta.join();
  tb.join();
  for (std::size_t i = 0; i < ref.size(); ++i) {
    EXPECT_EQ(ref[i], a[i]) << i;
    EXPECT_EQ(ref[i], b[i]) << i;
  }
}

// libacyclic_ipopt_interposers.so must be the definition the process uses
// for the MUMPS entry points it replaces: dmumps_c (the lock) and the
// per-call memory-save estimate (a fifth of a solve's CPU,
// planner/posture/mumps_lock.cpp), for Ipopt's clock (ipopt_clock.cpp), and
// for its MA27 interface's Backsolve (ipopt_backsolve.cpp).
// A link order that puts libdmumps_seq or libipopt first would silently lose them.
namespace {
// The file of the shared object that the process's lookup of `symbol` finds,
// or "" when nothing defines it.
std::string libraryDefining(const char* symbol) {
  void* sym = dlsym(RTLD_DEFAULT, symbol);
  Dl_info info{};
  if (!sym || !dladdr(sym, &info) || !info.dli_fname) return "";
  return info.dli_fname;
}
}  // namespace

TEST(PostureGenerator, MumpsInterposersAreTheOnesInUse) {
  for (const char* name : {"dmumps_c", "__dmumps_save_restore_MOD_dmumps_compute_memory_save", "_ZN5Ipopt7CpuTimeEv",
                           "_ZN5Ipopt7SysTimeEv", "_ZN5Ipopt20Ma27TSolverInterface9BacksolveEiPd"}) {
    const std::string lib = libraryDefining(name);
    EXPECT_NE(lib.find("acyclic_ipopt_interposers"), std::string::npos) << name << " resolves to '" << lib << "'";
  }
  // And MUMPS still solves through them: the chair's start stance from a perturbed guess.
  const Scenario& sc = chair();
  std::mt19937 rng(3);
  PostureRequest r;
  r.contacts = sc.start_stance;
  r.initial_guess = perturbed(sc.start, rng, 0.05, 0.02);
  PostureGeneratorOptions o;
  o.linear_solver = "mumps";
  PostureGenerator pg(sc.robot, sc.scene, o);
  EXPECT_TRUE(pg.solve(r).success());
  // With kkt_ldl and L-BFGS under Sherman-Morrison (the planner's), the
  // update's blocks of right-hand sides reach it whole, through the Backsolve
  // interposer (ipopt_backsolve.cpp); their solutions are bit for bit those
  // of one at a time (KktLdl.SolvesSeveralRightHandSidesAtOnceBitForBit).
  PostureGeneratorOptions sherman_morrison;
  sherman_morrison.lbfgs_in_kkt = false;
  PostureGenerator ldl(sc.robot, sc.scene, sherman_morrison);
  r.initial_guess = perturbed(sc.start, rng, 0.15, 0.1);  // far enough for L-BFGS to gather its pairs
  const long before = acyclic::kkt::rightHandSidesSolvedTogether();
  const PostureResult res = ldl.solve(r);
  EXPECT_TRUE(res.success());
  const long together = acyclic::kkt::rightHandSidesSolvedTogether() - before;
  EXPECT_GT(together, 0);
  // One by one instead: the same solve, to the bit, and no block.
  acyclic::kkt::solveBlocksAtOnce(false);
  const PostureResult singly = ldl.solve(r);
  acyclic::kkt::solveBlocksAtOnce(true);
  EXPECT_EQ(acyclic::kkt::rightHandSidesSolvedTogether() - before, together);
  EXPECT_EQ(singly.iterations, res.iterations);
  EXPECT_EQ(singly.configuration.base_position, res.configuration.base_position);
  EXPECT_EQ(singly.configuration.base_orientation.coeffs(), res.configuration.base_orientation.coeffs());
  EXPECT_EQ(singly.configuration.joints, res.configuration.joints);
}

// Postures along every third stance of the chair plan, walked in small steps
// toward the next witness (as the trajectory check walks samples), and with
// supports that cannot hold the robot mixed in (only the stance's first
// supporting contact kept), each passed to `check` in that order.
namespace {
void forEachChairPlanCheck(const Scenario& sc,
                           const std::function<void(const Configuration&, const std::vector<ContactSpec>&)>& check) {
  const Plan plan = readPlan(test::sourcePath("tests/data/chair.plan.json"), sc);
  for (std::size_t i = 0; i + 1 < plan.stances.size(); i += 3) {
    const auto stance = plan.stances[i].specs();
    const Configuration& q0 = plan.stances[i].configuration;
    const Configuration& q1 = plan.stances[i + 1].configuration;
    for (double t : {0.0, 0.02, 0.04}) {
      Configuration q = q0;
      q.base_position = (1 - t) * q0.base_position + t * q1.base_position;
      q.joints = (1 - t) * q0.joints + t * q1.joints;
      check(q, stance);
    }
    auto one = stance;
    bool first = true;
    for (auto& c : one)
      if (c.supporting) c.supporting = first, first = false;
    check(q0, one);
    check(q0, stance);
  }
}
}  // namespace

// Every program that runs posture generators allocates with jemalloc
// (planner/CMakeLists.txt): malloc resolves to it, not to glibc's.
TEST(PostureGenerator, JemallocIsTheAllocatorInUse) {
  for (const char* name : {"malloc", "free", "mallctl"}) {
    const std::string lib = libraryDefining(name);
    EXPECT_NE(lib.find("jemalloc"), std::string::npos) << name << " resolves to '" << lib << "'";
  }
}

// The independent check restarts each LP from the previous call's basis: one
// checker kept warm must give the same verdicts, margins and torque ratios as
// a fresh checker for each call.
TEST(QuasiStaticCheck, WarmStartedChecksAgreeWithColdOnes) {
  const Scenario& sc = chair();
  QuasiStaticChecker warm(sc.robot, sc.scene);
  warm.setWarmStart(true);
  Kinematics k(sc.robot);
  int checks = 0, infeasible = 0;
  forEachChairPlanCheck(sc, [&](const Configuration& q, const std::vector<ContactSpec>& stance) {
    k.setConfiguration(q);
    const QuasiStaticReport a = warm.check(k, stance);
    const QuasiStaticReport b = QuasiStaticChecker(sc.robot, sc.scene).check(k, stance);
    ++checks;
    infeasible += !b.feasible;
    ASSERT_EQ(a.feasible, b.feasible) << checks << ": " << a.reason << " | " << b.reason;
    if (std::isfinite(b.margin)) {
      EXPECT_NEAR(a.margin, b.margin, 1e-6 * (1 + std::abs(b.margin))) << checks;
    }
    if (b.feasible) {
      EXPECT_NEAR(a.worst_torque_ratio, b.worst_torque_ratio, 1e-5) << checks;  // Clp's tolerances
    }
  });
  EXPECT_GT(checks, 100);
  EXPECT_GT(infeasible, 5);  // the single supports
}

// Without the margin's LP (setMarginComputed(false), as the trajectory
// verifications run) the verdict, its reason and the torque ratio are those of
// the full check, feasible or not, and the margin is reported as not computed.
TEST(QuasiStaticCheck, VerdictsWithoutTheMarginLpAgreeWithFullChecks) {
  const Scenario& sc = chair();
  QuasiStaticChecker verdicts(sc.robot, sc.scene), full(sc.robot, sc.scene);
  verdicts.setMarginComputed(false);
  Kinematics k(sc.robot);
  int checks = 0, infeasible = 0, torque_bound = 0;
  forEachChairPlanCheck(sc, [&](const Configuration& q, const std::vector<ContactSpec>& stance) {
    k.setConfiguration(q);
    const QuasiStaticReport a = verdicts.check(k, stance);
    const QuasiStaticReport b = full.check(k, stance);
    ++checks;
    infeasible += !b.feasible;
    torque_bound += b.worst_torque_ratio > 0.5;
    ASSERT_EQ(a.feasible, b.feasible) << checks << ": " << a.reason << " | " << b.reason;
    EXPECT_EQ(a.reason, b.reason) << checks;
    EXPECT_TRUE(std::isnan(a.margin)) << checks;
    EXPECT_DOUBLE_EQ(a.worst_torque_ratio, b.worst_torque_ratio) << checks;  // the same LP 2, both cold
  });
  EXPECT_GT(checks, 100);
  EXPECT_GT(infeasible, 5);
  EXPECT_GT(torque_bound, 0);
}

namespace {
// Two checkers of verdicts in sequence (warm LPs, no margin LP) on the same
// robot, one reusing forces (setForcesReused): each check goes to both.
struct ReusingAndLp {
  QuasiStaticChecker reusing, lp;
  ReusingAndLp(std::shared_ptr<const RobotModel> robot, std::shared_ptr<const Scene> scene)
      : reusing(robot, scene), lp(robot, scene) {
    for (QuasiStaticChecker* c : {&reusing, &lp}) c->setWarmStart(true), c->setMarginComputed(false);
    reusing.setForcesReused(true);
  }
  struct Reports {
    QuasiStaticReport reusing, lp;
    bool reused;  // the reusing checker decided without an LP
  };
  Reports check(const Kinematics& k, const std::vector<ContactSpec>& stance) {
    const long before = reusing.forcesReused();
    QuasiStaticReport a = reusing.check(k, stance);
    return {std::move(a), lp.check(k, stance), reusing.forcesReused() > before};
  }
};
}  // namespace

// With the forces reused (setForcesReused, as the interpolator checks its
// samples), the verdicts are those of LP 2 alone, along small moves between
// the chair plan's stances with single supports mixed in; most of those
// checks are decided without an LP, and each such decision's forces balance
// the robot, lie in their pyramids and bound LP 2's optimum from above.
TEST(QuasiStaticCheck, ReusedForcesGiveTheLpsVerdicts) {
  const Scenario& sc = chair();
  const RobotModel& m = *sc.robot;
  ReusingAndLp both(sc.robot, sc.scene);
  const Plan plan = readPlan(test::sourcePath("tests/data/chair.plan.json"), sc);
  Kinematics k(sc.robot);
  int checks = 0, infeasible = 0;
  auto check = [&](const Configuration& q, const std::vector<ContactSpec>& stance) {
    k.setConfiguration(q);
    const auto [a, b, reused] = both.check(k, stance);
    ++checks;
    infeasible += !b.feasible;
    ASSERT_EQ(a.feasible, b.feasible) << checks << ": " << a.reason << " | " << b.reason;
    EXPECT_EQ(a.reason, b.reason) << checks;
    if (!reused) return;
    // Decided by reused forces: a point LP 2 accepts, its ratio above LP 2's optimum.
    EXPECT_LE(a.residual, 1e-9) << checks;
    EXPECT_LE(a.worst_cone_ratio, 1 + 1e-9) << checks;
    EXPECT_LE(a.worst_torque_ratio, 1.0) << checks;
    EXPECT_GE(a.worst_torque_ratio, b.worst_torque_ratio - 1e-6) << checks;
    Eigen::VectorXd tau = k.gravityTorques();  // through Simbody's station Jacobians, not the checker's
    for (std::size_t c = 0; c < stance.size(); ++c) {
      const int link = m.spots()[stance[c].spot].link;
      for (std::size_t i = 0; i < a.points[c].size(); ++i)
        tau -= k.pointJacobian(link, k.linkPose(link).inverse() * a.points[c][i]).transpose() * a.forces[c][i];
    }
    EXPECT_LE(tau.head<6>().norm(), 1e-6 * m.totalMass() * 9.81) << checks;
    for (const auto& j : m.joints()) EXPECT_LE(std::abs(tau[6 + j.index]), j.effort) << checks << " " << j.name;
  };
  for (std::size_t i = 0; i + 1 < plan.stances.size(); i += 3) {
    const auto stance = plan.stances[i].specs();
    const Configuration& q0 = plan.stances[i].configuration;
    const Configuration& q1 = plan.stances[i + 1].configuration;
    for (int n = 0; n <= 10; ++n) {
      const double t = 0.01 * n;
      Configuration q = q0;
      q.base_position = (1 - t) * q0.base_position + t * q1.base_position;
      q.joints = (1 - t) * q0.joints + t * q1.joints;
      check(q, stance);
      if (n == 5) {  // a single support in between: the same posture on the stance's first supporting contact
        auto one = stance;
        bool first = true;
        for (auto& c : one)
          if (c.supporting) c.supporting = first, first = false;
        check(q, one);
      }
    }
  }
  EXPECT_GT(checks, 300);
  EXPECT_GT(infeasible, 5);
  EXPECT_GT(both.reusing.forcesReused(), checks / 2);
}

// Reused forces are tried against the torque limits, and a point beyond one
// decides nothing (LP 2 does): on a robot whose right knee holds 10 N m and
// right shoulder 5 N m, standing on both feet, the chest pitched and each
// leg's hip and ankle rolled a little at a time, LP 2 keeps the knee within
// its limit where the previous check's forces, rebalanced, would not (a
// verdict "infeasible" from those forces alone would be wrong 39 times in
// these 123 checks); and the right arm raised forward takes its shoulder
// beyond its limit whatever the forces, which both refuse.
TEST(QuasiStaticCheck, ReusedForcesRespectTorqueLimits) {
  const Scenario& sc = chair();
  test::TempDir dir;
  std::string urdf = test::readFile(test::sourcePath("models/hrp2/hrp2.urdf"));
  for (const auto& [joint, effort] : {std::pair{"RLEG_JOINT3", "10"}, std::pair{"RARM_JOINT0", "5"}}) {
    const std::regex limit(std::string("(<joint name=\"") + joint + "\"[\\s\\S]*?effort=\")[0-9.]+(\")");
    const std::string was = urdf;
    urdf = std::regex_replace(urdf, limit, std::string("$01") + effort + "$2", std::regex_constants::format_first_only);
    ASSERT_NE(urdf, was) << joint;
  }
  dir.write("hrp2.urdf", urdf);
  dir.write("hrp2.yaml", test::readFile(test::sourcePath("models/hrp2/hrp2.yaml")));
  auto weak = RobotModel::load(dir.path() + "/hrp2.yaml");
  ReusingAndLp both(weak, sc.scene);
  Configuration q = weak->posture("half_sitting");
  q.base_position.x() = -0.6;
  q.base_position.y() = -0.8;
  const std::vector<ContactSpec> feet = {contactOf(sc, "r_sole", "floor", true, q),
                                         contactOf(sc, "l_sole", "floor", true, q)};
  Kinematics k(weak);
  int checks = 0, refused = 0;
  auto check = [&](const Configuration& at) {
    k.setConfiguration(at);
    const auto [a, b, reused] = both.check(k, feet);
    ++checks;
    refused += !b.feasible;
    ASSERT_EQ(a.feasible, b.feasible) << checks << ": " << a.reason << " | " << b.reason;
    EXPECT_EQ(a.reason, b.reason) << checks;
  };
  auto joint = [&](const char* name) { return weak->jointIndex(name); };
  for (const auto& [moved, against] : {std::pair{"CHEST_JOINT1", ""}, std::pair{"RLEG_JOINT1", "RLEG_JOINT5"},
                                       std::pair{"LLEG_JOINT1", "LLEG_JOINT5"}})
    for (int i = -20; i <= 20; ++i) {  // 0.01 rad a check
      Configuration at = q;
      at.joints[joint(moved)] += 0.01 * i;
      if (*against) at.joints[joint(against)] -= 0.01 * i;
      check(at);
    }
  const long standing_reused = both.reusing.forcesReused();
  EXPECT_EQ(refused, 0);
  for (int n = 0; n <= 18; ++n) {  // the right arm from hanging to raised forward, 5 degrees a check
    Configuration at = q;
    at.joints[joint("RARM_JOINT0")] = -n * 5 * M_PI / 180;
    check(at);
  }
  EXPECT_GT(standing_reused, 80);  // of the 123 standing checks
  EXPECT_GT(refused, 3);           // the arm raised
}

// Checked for their verdicts in sequence (checkVerdictsInSequence: pairs
// whose bounding spheres are over 1 mm apart left unmeasured), postures find
// the same collisions, with the same depths, as when every pair is
// measured: the chair plan's stances with each arm swept down through the
// table and the thighs, and the chest bent onto the table.
TEST(ValidityCheck, VerdictsInSequenceFindEveryCollision) {
  const Scenario& sc = chair();
  const Plan plan = readPlan(test::sourcePath("tests/data/chair.plan.json"), sc);
  ValidityChecker sequence(sc.robot, sc.scene), full(sc.robot, sc.scene);
  sequence.checkVerdictsInSequence();
  auto collisions = [](const ValidityReport& r) {
    for (const auto& p : r.parts)
      if (p.name == "collisions") return p;
    ADD_FAILURE() << "no collisions part";
    return CheckPart{};
  };
  int checks = 0, colliding = 0;
  for (std::size_t i = 0; i < plan.stances.size(); i += 4) {
    const auto stance = plan.stances[i].specs();
    for (const char* joint : {"RARM_JOINT0", "LARM_JOINT0", "CHEST_JOINT1"})
      for (int n = 0; n <= 24; ++n) {
        Configuration q = plan.stances[i].configuration;
        q.joints[sc.robot->jointIndex(joint)] += (joint[0] == 'C' ? 0.03 : -0.08) * n;
        const CheckPart a = collisions(sequence.checkPosture(q, stance));
        const CheckPart b = collisions(full.checkPosture(q, stance));
        ++checks;
        colliding += !b.ok();
        ASSERT_EQ(a.violations, b.violations) << i << " " << joint << " " << n;
      }
  }
  EXPECT_GT(checks, 500);
  EXPECT_GT(colliding, checks / 10);
}

// A failed check names the robot links its violations are about
// (CheckPart::links, which the interpolator orders its repairs by): an arm
// swept down through the table names links of that arm and, for a self pair,
// the link it hits, each in a violation's text; a base moved 5 mm off every
// contact names each contact's spot's link, in the stance's order.
TEST(ValidityCheck, NamesTheLinksOfWhatFailed) {
  const Scenario& sc = chair();
  const RobotModel& m = *sc.robot;
  const Plan plan = readPlan(test::sourcePath("tests/data/chair.plan.json"), sc);
  ValidityChecker checker(sc.robot, sc.scene);
  auto part = [](const ValidityReport& r, const std::string& name) {
    for (const auto& p : r.parts)
      if (p.name == name) return p;
    ADD_FAILURE() << "no part " << name;
    return CheckPart{};
  };
  const int arm = m.jointIndex("RARM_JOINT0");
  int colliding = 0;
  for (std::size_t i = 0; i < plan.stances.size(); i += 8) {
    const auto stance = plan.stances[i].specs();
    for (int n = 0; n <= 24; ++n) {
      Configuration q = plan.stances[i].configuration;
      q.joints[arm] -= 0.08 * n;
      const CheckPart c = part(checker.checkPosture(q, stance), "collisions");
      EXPECT_EQ(c.ok(), c.links.empty()) << i << " " << n;
      if (c.ok()) continue;
      ++colliding;
      bool on_arm = false;
      for (int link : c.links) {
        on_arm = on_arm || m.jointMovesLink(arm, link);
        bool named = false;
        for (const auto& v : c.violations) named = named || v.find(m.links()[link].name) != std::string::npos;
        EXPECT_TRUE(named) << m.links()[link].name << " in none of the violations, stance " << i << " step " << n;
      }
      EXPECT_TRUE(on_arm) << i << " " << n;
    }
  }
  EXPECT_GT(colliding, 5);
  const PlanStance& st = plan.stances.front();
  Configuration q = st.configuration;
  q.base_position.x() += 0.005;
  const CheckPart c = part(checker.checkPosture(q, st.specs()), "contacts");
  std::vector<int> expected;
  for (const auto& spec : st.specs()) expected.push_back(m.spots()[spec.spot].link);
  EXPECT_EQ(c.links, expected);
  EXPECT_TRUE(part(checker.checkPosture(st.configuration, st.specs()), "contacts").links.empty());
}

// The checker takes each corner's Jacobian from one frame Jacobian of its
// contact (J_p = J_v - [p - o]x J_w): the forces it reports, mapped through
// Simbody's own station Jacobian at each reported corner, balance gravity on
// the base and stay within every joint's torque limit, with the torque ratio
// it reports. A wrong row, sign or lever arm gives forces that balance a
// different robot.
TEST(QuasiStaticCheck, ReportedForcesBalanceGravityThroughStationJacobians) {
  const Scenario& sc = chair();
  const RobotModel& m = *sc.robot;
  QuasiStaticChecker checker(sc.robot, sc.scene);
  Kinematics k(sc.robot);
  const double W = m.totalMass() * 9.81;
  int feasible = 0;
  forEachChairPlanCheck(sc, [&](const Configuration& q, const std::vector<ContactSpec>& stance) {
    k.setConfiguration(q);
    const QuasiStaticReport r = checker.check(k, stance);
    if (!r.feasible) return;
    ++feasible;
    Eigen::VectorXd tau = k.gravityTorques();
    double levers = 0;  // the corners' distance from their links' origins: the moments depend on them
    for (std::size_t c = 0; c < stance.size(); ++c) {
      const int link = m.spots()[stance[c].spot].link;
      for (std::size_t i = 0; i < r.points[c].size(); ++i) {
        const Eigen::Vector3d in_link = k.linkPose(link).inverse() * r.points[c][i];
        tau -= k.pointJacobian(link, in_link).transpose() * r.forces[c][i];
        levers = std::max(levers, in_link.norm());
      }
    }
    EXPECT_GT(levers, 0.01);
    EXPECT_LE(tau.head<6>().norm() / W, 1e-6) << feasible;
    double worst = 0;
    for (const auto& j : m.joints()) worst = std::max(worst, std::abs(tau[6 + j.index]) / j.effort);
    EXPECT_NEAR(worst, r.worst_torque_ratio, 1e-6) << feasible;
  });
  EXPECT_GT(feasible, 50);
}

// --- Friction: the pyramid inscribed in the Coulomb cone --------------------

namespace {

// A floor tilted by `tilt` about the world y axis, its surface frame turned by
// `turn` about its normal: standing on it, gravity's reaction pulls along the
// surface direction at 180 deg - turn in the surface frame, at tan(tilt) of
// the normal force.
std::shared_ptr<const Scene> tiltedFloor(const test::TempDir& dir, double tilt, double turn, double mu) {
  const Eigen::Quaterniond q(Eigen::AngleAxisd(tilt, Eigen::Vector3d::UnitY()) *
                             Eigen::AngleAxisd(turn, Eigen::Vector3d::UnitZ()));
  std::ostringstream os;
  os.precision(17);
  os << "format: acyclic.scene/1\nname: tilted\nobstacles:\n"
     << "  - {name: floor, shape: box, size: [6, 6, 0.1], position: [0, 0, -0.05]}\n"
     << "surfaces:\n  - {name: floor, obstacle: floor, position: [0, 0, 0], friction: " << mu << ",\n"
     << "     quaternion: [" << q.w() << ", " << q.x() << ", " << q.y() << ", " << q.z() << "],\n"
     << "     polygon: [[-3, -3], [3, -3], [3, 3], [-3, 3]]}\n";
  const std::string path = dir.write("tilted_" + std::to_string(turn) + ".yaml", os.str());
  return Scene::load(path);
}

}  // namespace

// Where the load pulls along a pyramid edge, friction up to mu holds it; half
// way between two edges (a facet's middle) only mu cos(pi / 8) does. A load
// at 0.96 mu tells the inscribed pyramid from the cone (both would hold it) and
// from the circumscribed square pyramid (which would hold it in both
// directions). The forces found are inside the true cone.
TEST(QuasiStatic, FrictionIsThePyramidInscribedInTheCone) {
  const Scenario& sc = chair();
  test::TempDir dir;
  const double mu = 0.5, tilt = std::atan(0.96 * mu);
  ASSERT_GT(0.96, std::cos(M_PI / kFrictionPyramidEdges));
  Configuration q = sc.robot->posture("half_sitting");
  q.base_position.x() = 0, q.base_position.y() = 0;
  Kinematics k(sc.robot);
  k.setConfiguration(q);
  for (const double turn : {0.0, M_PI / kFrictionPyramidEdges}) {
    auto scene = tiltedFloor(dir, tilt, turn, mu);
    std::vector<ContactSpec> stance;
    for (const char* spot : {"r_sole", "l_sole"}) {
      ContactSpec c;
      c.spot = sc.robot->spotIndex(spot);
      c.surface = 0;
      c.supporting = true;
      stance.push_back(c);
    }
    const QuasiStaticReport r = QuasiStaticChecker(sc.robot, scene).check(k, stance);
    if (turn == 0) {
      ASSERT_TRUE(r.feasible) << r.reason;
      EXPECT_LE(r.worst_cone_ratio, 1 + 1e-9);
      EXPECT_GT(r.worst_cone_ratio, 0.9);  // friction binds
      const Eigen::Vector3d n = scene->surfaces()[0].frame.linear().col(2);
      for (const auto& contact : r.forces)
        for (const auto& f : contact) EXPECT_LE(coneRatio(f, n, mu), 1 + 1e-9);
    } else {
      EXPECT_FALSE(r.feasible) << "held by friction beyond the inscribed pyramid's facet";
    }
  }
}

TEST(QuasiStatic, ConeRatio) {
  const Eigen::Vector3d n = Eigen::Vector3d::UnitZ();
  EXPECT_NEAR(coneRatio(Eigen::Vector3d(0.3, 0.4, 1), n, 0.5), 1.0, 1e-12);
  EXPECT_NEAR(coneRatio(Eigen::Vector3d(0.5, 0.5, 1), n, 0.5), std::sqrt(2.0), 1e-12);  // a square pyramid's corner
  EXPECT_EQ(coneRatio(Eigen::Vector3d(0, 0, 2), n, 0.5), 0.0);
  EXPECT_TRUE(std::isinf(coneRatio(Eigen::Vector3d(0.1, 0, -1), n, 0.5)));  // pulls
}

TEST(PostureProblem, PyramidEdgesMustBeTheContractsEdges) {
  const Scenario& sc = chair();
  PostureRequest r;
  r.contacts = sc.start_stance;
  r.initial_guess = sc.start;
  auto collision = std::make_shared<CollisionModel>(sc.robot, sc.scene);
  PostureOptions o;
  o.pyramid_sides = 4;  // every other edge of the contract's octagon: inside it
  EXPECT_NO_THROW(PostureProblem(sc.robot, sc.scene, collision, r, o));
  o.pyramid_sides = 6;  // edges the contract's pyramid does not have: could reach outside it
  EXPECT_THROW(PostureProblem(sc.robot, sc.scene, collision, r, o), std::invalid_argument);
}


// A request's retry_guess: Ipopt is local, and HRP-2 kneeling on its right
// knee (crawl_under_table's third key posture, the left sole flat) cannot put
// its right palm on the floor from arms that hang at its sides (the wrist
// must turn some 75 degrees); from the right arm as the next key posture
// holds it, leaning onto the palms, it can. The generator tries the second
// guess only when the first fails, and says so.
TEST(PostureGenerator, ARetryGuessIsSolvedWhenTheFirstGuessFails) {
  const Scenario sc = Scenario::load(test::sourcePath("models/scenarios/crawl_under_table.yaml"));
  ASSERT_GE(sc.key_postures.size(), 4u);
  const Configuration& kneeling = sc.key_postures[2];
  const Configuration& leaning = sc.key_postures[3];
  PostureRequest r;
  r.contacts = {contactOf(sc, "l_sole", "floor", true, kneeling), contactOf(sc, "r_knee", "floor", true, kneeling)};
  r.initial_guess = kneeling;
  FloatingContact f;
  f.spot = sc.robot->spotIndex("r_palm");
  f.surface = sc.scene->surfaceIndex("floor");
  f.volume.polygon = sc.scene->surfaces()[f.surface].polygon;
  r.floating = f;
  PostureGenerator pg(sc.robot, sc.scene);
  {
    ValidityChecker checker(sc.robot, sc.scene);
    ASSERT_TRUE(checker.checkPosture(kneeling, r.contacts).valid());  // the stance itself holds
  }
  const PostureResult once = pg.solve(r);
  EXPECT_FALSE(once.success()) << "the palm was put down from hanging arms: the retry is not tested";
  EXPECT_EQ(once.solves, 1);

  Configuration arm_forward = kneeling;
  for (int j : sc.robot->jointsMovedBy(sc.robot->spotLimbRootJoint(f.spot))) arm_forward.joints[j] = leaning.joints[j];
  r.retry_guess = arm_forward;
  const PostureResult twice = pg.solve(r);
  ASSERT_TRUE(twice.success()) << toString(twice.status) << ": " << twice.reason;
  EXPECT_EQ(twice.solves, 2);
  std::vector<ContactSpec> stance = r.contacts;
  stance.push_back(placedContact(r, twice));
  expectValid(sc, twice, stance);

  // A first guess that succeeds is the answer: the retry is not solved.
  PostureRequest easy = r;
  easy.initial_guess = twice.configuration;
  const PostureResult first = pg.solve(easy);
  ASSERT_TRUE(first.success()) << first.reason;
  EXPECT_EQ(first.solves, 1);
}

// The push margin (QuasiStaticChecker::pushMargin): gravity is the push
// straight down, so g(q) = J_com^T (0, 0, W) (the sign and the frames the LP
// relies on); standing on both soles (step_forward's start), a push at the
// centre of mass tips the robot over the soles' front or back edges, which
// rigid statics puts at W d / h (d from the centre of mass's projection to
// the edge, h its height); a stance out of equilibrium has none.
TEST(QuasiStaticCheck, PushMarginIsTheTippingForceOfTheSupport) {
  const Scenario sc = Scenario::load(test::sourcePath("models/scenarios/step_forward.yaml"));
  Kinematics k(sc.robot);
  k.setConfiguration(sc.start);
  const double W = sc.robot->totalMass() * 9.81;
  const Eigen::VectorXd g = k.gravityTorques();
  const Eigen::VectorXd jg = k.centerOfMassJacobian().transpose() * Eigen::Vector3d(0, 0, W);
  EXPECT_LT((g - jg).norm(), 1e-9 * W) << (g - jg).transpose();

  double front = -1e9, back = 1e9, floor_z = 0;
  for (const ContactSpec& c : sc.start_stance) {
    const Eigen::Isometry3d T = k.spotPose(c.spot);
    for (const auto& v : sc.robot->spots()[c.spot].polygon.vertices()) {
      const Eigen::Vector3d p = T * Eigen::Vector3d(v.x(), v.y(), 0);
      front = std::max(front, p.x()), back = std::min(back, p.x()), floor_z = p.z();
    }
  }
  const Eigen::Vector3d com = k.centerOfMass();
  const double h = com.z() - floor_z;
  const PushMargin pm = QuasiStaticChecker(sc.robot, sc.scene).pushMargin(k, sc.start_stance);
  ASSERT_TRUE(pm.computed);
  ASSERT_EQ(pm.per_direction.size(), 8u);
  EXPECT_NEAR(pm.per_direction[0], W * (front - com.x()) / h, 1e-6 * W);  // +x
  EXPECT_NEAR(pm.per_direction[4], W * (com.x() - back) / h, 1e-6 * W);   // -x
  // The heels are nearer the centre of mass than the toes, and nearer than
  // the soles' outer edges: backward is the weakest direction.
  EXPECT_EQ(pm.weakest_direction_deg, 180.0);
  EXPECT_EQ(pm.weakest, pm.per_direction[4]);
  for (double f : pm.per_direction) EXPECT_GT(f, 0.05 * W);

  // On the right sole alone the centre of mass (between the feet) is outside
  // the support: no forces balance, no margin (a push toward the right
  // would hold it there, which is no margin either).
  std::vector<ContactSpec> one = sc.start_stance;
  for (auto& c : one) c.supporting = sc.robot->spots()[c.spot].name == "r_sole";
  EXPECT_FALSE(QuasiStaticChecker(sc.robot, sc.scene).pushMargin(k, one).computed);
}
