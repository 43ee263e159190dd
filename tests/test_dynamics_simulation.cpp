// The dynamics simulation of executing a trajectory (Simbody dynamics, PD
// servos, compliant contact, a model of HRP-2's stabilizer where the bridge
// runs it): a robot whose CoM is pushed beyond its feet falls; standing,
// leaning within the feet, step_forward and sit_down (planned and
// interpolated here) and the chair on the feet (its plan stored) execute
// without falling and with little slip; step_forward falls without the
// stabilizer; a seated robot that tips back lands on its waist's collision
// shape; the acyclic-simulate
// executable's exit statuses, report and trace.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "hrp2_bridge/sim/dynamics_simulation.h"
#include "hrp2_bridge/sim/held_start.h"
#include "interpolator/interpolator.h"
#include "planner/model/kinematics.h"
#include "planner/plan/plan.h"
#include "planner/search/planner_parameters.h"
#include "test_support.h"

using namespace acyclic;

namespace {

// Slip allowed to a supporting contact over a phase in these tests: a
// tenth of the acceptance bound (1 cm), so that a regression in the contact
// model shows before the chair's acceptance fails.
constexpr double kSlipBound = 0.002;
constexpr double kBaseBound = 0.02;

const Scenario& floorScenario() {
  static Scenario sc = Scenario::load(test::sourcePath("models/scenarios/step_forward.yaml"));
  return sc;
}

// Standing on both feet, the whole body leaning forward about the ankles by
// `lean` rad (reached linearly over 1 s, then held for 1 s): the base turns
// about the ankles' midpoint and the ankle pitch joints turn back, so the
// feet stay flat on the floor in the plan.
Trajectory leaningTrajectory(const Scenario& sc, double lean) {
  const RobotModel& m = *sc.robot;
  Kinematics kin(sc.robot);
  kin.setConfiguration(sc.start);
  const int r_ankle = m.jointIndex("RLEG_JOINT4"), l_ankle = m.jointIndex("LLEG_JOINT4");
  const Eigen::Vector3d pivot = 0.5 * (kin.jointOrigin(r_ankle) + kin.jointOrigin(l_ankle));
  Trajectory tr = hrp2::heldStart(sc, 2.0);
  for (int k = 0; k < static_cast<int>(tr.samples.size()); ++k) {
    const double s = std::min(1.0, k / 200.0), a = lean * s;
    const double rate = k < 200 ? lean / 1.0 : 0.0;
    const Eigen::AngleAxisd R(a, Eigen::Vector3d::UnitY());
    TrajectorySample& x = tr.samples[k];
    x.q.base_position = pivot + R * (sc.start.base_position - pivot);
    x.q.base_orientation = Eigen::Quaterniond(R) * sc.start.base_orientation;
    x.q.joints[r_ankle] -= a;
    x.q.joints[l_ankle] -= a;
    x.dq[r_ankle] = x.dq[l_ankle] = -rate;
  }
  return tr;
}

Trajectory plannedTrajectory(const Scenario& sc, const InterpolatorOptions& options = {}) {
  const PlanningResult p = ContactPlanner(sc, plannerParameters(sc)).plan();
  EXPECT_TRUE(p.solved()) << p.reason;
  const InterpolationResult t = interpolate(p.plan, sc, options);
  EXPECT_TRUE(t.success()) << t.reason;
  return t.trajectory;
}

void expectExecuted(const hrp2::SimulationReport& r, double slip_bound = kSlipBound) {
  EXPECT_EQ(r.verdict, hrp2::SimulationReport::Verdict::Executed) << r.reason;
  EXPECT_LT(r.worst_slip, slip_bound) << r.worst_slip_contact;
  EXPECT_LT(r.worst_base_drift, kBaseBound);
  for (const auto& p : r.phases)
    for (const auto& c : p.contacts)
      if (c.supporting) {
        EXPECT_FALSE(c.left_surface) << c.spot << " phase " << p.phase;
        // A supporting contact carries load: the simulated force is not nil.
        EXPECT_GT(c.force.z(), 1.0) << c.spot << " phase " << p.phase;
      }
}

}  // namespace

// The simulator builds its own Simbody system from the model: the same
// masses and joint placements as the planner's (its centre of mass at a
// posture with every joint bent).
TEST(DynamicsSimulation, ModelMatchesThePlannersModel) {
  const Scenario& sc = floorScenario();
  Configuration q = sc.robot->posture("sitting");
  for (int j = 0; j < q.joints.size(); ++j) q.joints[j] += 0.1 * std::sin(j + 1.0);
  q.base_position = Eigen::Vector3d(0.3, -0.2, 1.0);
  q.base_orientation = Eigen::Quaterniond(Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 2, 3).normalized()));
  const hrp2::DynamicsSimulator sim(sc, q, {});
  Kinematics kin(sc.robot);
  kin.setConfiguration(q);
  EXPECT_LT((sim.centerOfMass() - kin.centerOfMass()).norm(), 1e-9);
  const Configuration back = sim.configuration();
  EXPECT_LT((back.joints - q.joints).norm(), 1e-12);
  EXPECT_LT((back.base_position - q.base_position).norm(), 1e-12);
}

TEST(DynamicsSimulation, StandingStillHoldsItsPostureAndCarriesItsWeight) {
  const Scenario& sc = floorScenario();
  const Trajectory tr = leaningTrajectory(sc, 0.0);
  hrp2::DynamicsOptions o;
  o.settle = 0;
  const hrp2::SimulationReport r = hrp2::simulate(sc, tr, o);
  expectExecuted(r);
  ASSERT_EQ(r.phases.size(), 1u);
  // The two soles carry the weight, as the quasi-static plan says.
  const double weight = sc.robot->totalMass() * 9.81;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero(), plan = Eigen::Vector3d::Zero();
  for (const auto& c : r.phases[0].contacts) {
    sum += c.force;
    ASSERT_TRUE(c.plan_force_known);
    plan += c.plan_force;
  }
  EXPECT_NEAR(sum.z(), weight, 0.02 * weight);
  EXPECT_NEAR(plan.z(), weight, 1e-3 * weight);
  EXPECT_LT(r.phases[0].tilt, 0.02);
}

TEST(DynamicsSimulation, LeaningWithinTheFeetStaysUp) {
  // 3 degrees: the CoM about 4 cm ahead of the ankles, inside the soles (14 cm).
  const Scenario& sc = floorScenario();
  const hrp2::SimulationReport r = hrp2::simulate(sc, leaningTrajectory(sc, 3 * M_PI / 180));
  expectExecuted(r);
}

// A contact the plan says supports but that never touches (here a palm on
// the floor while the robot stands and leans 3 degrees) is reported as never
// loaded, and the verdict says it never reached its surface rather than
// that it slipped.
TEST(DynamicsSimulation, ASupportingContactThatNeverTouchesIsReportedAsSuch) {
  const Scenario& sc = floorScenario();
  Trajectory tr = leaningTrajectory(sc, 3 * M_PI / 180);
  ContactSpec palm = tr.phases[0].contacts[0];
  palm.spot = sc.robot->spotIndex("l_palm");
  palm.supporting = true;
  tr.phases[0].contacts.push_back(palm);
  const hrp2::SimulationReport r = hrp2::simulate(sc, tr);
  ASSERT_EQ(r.phases.size(), 1u);
  const auto& contacts = r.phases[0].contacts;
  ASSERT_EQ(contacts.size(), 3u);
  EXPECT_TRUE(contacts[2].never_loaded);
  EXPECT_FALSE(contacts[0].never_loaded);
  EXPECT_FALSE(contacts[1].never_loaded);
  EXPECT_EQ(r.verdict, hrp2::SimulationReport::Verdict::Slipped) << r.reason;
  EXPECT_NE(r.reason.find("l_palm on floor carried no load"), std::string::npos) << r.reason;
  EXPECT_NE(hrp2::reportToJson(r).find("\"never_loaded\": true"), std::string::npos);
}

// chair_paper's seated start, held 3 s: its centre of mass 5 mm inside the
// back edge of the thighs' contact patches (which end 6 cm short of the
// hips), the feet lightly loaded. The robot tips back as the servos take the
// load. With only the contact spots modelled it goes on tipping and falls
// off the seat within 1.2 s; with the body's collision shapes its waist box,
// 1 cm above the seat in the plan, catches it 4 degrees back, and it rocks
// between the waist and the thighs, seated, as the robot itself would.
TEST(DynamicsSimulation, ASeatedRobotThatTipsBackSitsOnItsWaist) {
  static const Scenario sc = Scenario::load(test::sourcePath("models/scenarios/chair_paper.yaml"));
  const Trajectory tr = hrp2::heldStart(sc, 3.0);
  hrp2::DynamicsOptions o;
  o.settle = 0;
  // Near a surface in the plan: the waist above the seat. The thighs and the
  // feet, whose spots meet the seat and the floor, are left to their spots.
  const auto pairs = hrp2::bodyContactPairs(sc, tr, o);
  ASSERT_EQ(pairs.size(), 1u);
  EXPECT_EQ(sc.robot->links()[pairs[0].first].name, "WAIST");
  EXPECT_EQ(sc.scene->surfaces()[pairs[0].second].name, "chair_seat");

  o.body_contacts = false;
  const hrp2::SimulationReport spots_only = hrp2::simulate(sc, tr, o);
  EXPECT_EQ(spots_only.verdict, hrp2::SimulationReport::Verdict::Fell) << spots_only.reason;
  EXPECT_LT(spots_only.verdict_time, 1.5);

  o.body_contacts = true;
  const hrp2::SimulationReport body = hrp2::simulate(sc, tr, o);
  // Not a fall (its unloaded soles slide as it rocks, which is a slip).
  EXPECT_NE(body.verdict, hrp2::SimulationReport::Verdict::Fell) << body.reason;
  EXPECT_GE(body.motion_time, 3.0 - 1e-9);
  EXPECT_LT(body.phases.at(0).tilt, 0.1) << "rad: a few degrees back onto the waist, not off the seat";
  ASSERT_EQ(body.body_contacts.size(), 1u);
  EXPECT_EQ(body.body_contacts[0].link, "WAIST");
  EXPECT_EQ(body.body_contacts[0].surface, "chair_seat");
  EXPECT_LT(body.body_contacts[0].first_time, 1.0);
  EXPECT_GT(body.body_contacts[0].loaded_time, 0.1);
  EXPECT_GT(body.body_contacts[0].max_force, 50.0);
  EXPECT_NE(hrp2::reportToJson(body).find("\"link\": \"WAIST\""), std::string::npos);
}

TEST(DynamicsSimulation, CentreOfMassBeyondTheToesFalls) {
  // 20 degrees: the CoM about 28 cm ahead of the ankles, twice the toes' 14 cm.
  const Scenario& sc = floorScenario();
  hrp2::DynamicsOptions o;
  o.settle = 2.0;
  const hrp2::SimulationReport r = hrp2::simulate(sc, leaningTrajectory(sc, 20 * M_PI / 180), o);
  EXPECT_EQ(r.verdict, hrp2::SimulationReport::Verdict::Fell) << r.reason;
  EXPECT_GT(r.verdict_time, 0.5);  // the lean has to build up first
  EXPECT_LT(r.motion_time, 4.0);   // stopped at the fall
  EXPECT_NE(r.reason.find("tilted"), std::string::npos) << r.reason;
}

// Up to the first single support: both feet on the floor while the CoM moves
// over the left foot.
TEST(DynamicsSimulation, StepForwardsWeightShiftExecutes) {
  const Scenario& sc = floorScenario();
  Trajectory tr = plannedTrajectory(sc);
  ASSERT_GE(tr.phases.size(), 2u);
  ASSERT_EQ(tr.phases[0].contacts.size(), 2u);
  std::size_t k = 0;
  while (k < tr.samples.size() && tr.samples[k].phase == 0) ++k;
  tr.samples.resize(k);
  tr.phases.resize(1);
  const hrp2::SimulationReport r = hrp2::simulate(sc, tr);
  expectExecuted(r);
  ASSERT_EQ(r.phases.size(), 1u);
  // Halfway, the left foot already carries more of the weight than the right.
  double left = 0, right = 0;
  for (const auto& c : r.phases[0].contacts) (c.spot == "l_sole" ? left : right) = c.force.z();
  EXPECT_GT(left, right);
  EXPECT_NEAR(left + right, sc.robot->totalMass() * 9.81, 0.05 * sc.robot->totalMass() * 9.81);
}

// step_forward as shipped (no stability margins, the default time law):
// with the model of HRP-2's stabilizer, which the bridge runs throughout (only
// coplanar feet touch), it executes; played open-loop it falls in its first
// single support, the CoM 3-5 mm inside the left sole's inner edge while the
// right sole, which the position-servoed legs (not the plan) still load when
// it is released, lifts: the robot rolls over that edge.
TEST(DynamicsSimulation, StepForwardExecutesWithTheStabilizerAndFallsWithout) {
  const Scenario sc = Scenario::load(test::sourcePath("models/scenarios/step_forward.yaml"));
  const Trajectory tr = plannedTrajectory(sc);
  const hrp2::SimulationReport r = hrp2::simulate(sc, tr);
  expectExecuted(r);
  EXPECT_EQ(r.phases.size(), tr.phases.size());
  EXPECT_NEAR(r.stabilizer_on_time, tr.duration(), 0.01);
  // The released feet were unloaded by the stabilizer, not by the plan alone.
  EXPECT_GT(r.stabilizer_max_lift, 1e-4);
  hrp2::DynamicsOptions open_loop;
  open_loop.stabilizer = false;
  const hrp2::SimulationReport o = hrp2::simulate(sc, tr, open_loop);
  EXPECT_EQ(o.verdict, hrp2::SimulationReport::Verdict::Fell) << o.reason;
}

// sit_down as shipped (its planner section's margins: forces 2 cm inside the
// spots' edges, a fifth of the friction; the interpolator takes them from the
// scenario) executes: the stabilizer on while only the soles touch, then
// open-loop from just before a thigh touches the seat, as on HRP-2. Without
// the margins the CoM comes within 5 mm of a heel and the robot falls; with
// the full friction a stance on one sole and one thigh leans on an 84 N
// friction couple that position servos do not produce.
TEST(DynamicsSimulation, SitDownExecutes) {
  const Scenario sc = Scenario::load(test::sourcePath("models/scenarios/sit_down.yaml"));
  const Trajectory tr = plannedTrajectory(sc, withScenarioMargins(sc, {}));
  const hrp2::SimulationReport r = hrp2::simulate(sc, tr);
  // The acceptance's slip bound: on one sole and one thigh the legs squeeze
  // the seat (about 100 N: the servos' sag lets the thigh land early), and
  // the regularized friction creeps under it, 4.4 mm over the 8 s phase.
  expectExecuted(r, hrp2::DynamicsOptions{}.slip_bound);
  EXPECT_GT(r.stabilizer_on_time, 1.0);
  EXPECT_LT(r.stabilizer_on_time, tr.duration() - 1.0);
  // Seated at the end: the thighs on the seat carry load.
  double thighs = 0;
  for (const auto& c : r.phases.back().contacts)
    if (c.surface == "chair_seat") thighs += c.force.z();
  EXPECT_GT(thighs, 50.0);
}

// The chair, on the feet (models/scenarios/chair_feet.yaml; its plan stored,
// 70 stances: planning it takes about 50 s), interpolated with the
// scenario's margins and time law: the thighs released, the robot side-steps
// out from between the chair and the table without falling, each supporting
// sole slipping less than the acceptance's 1 cm. Its base stays within
// 19.4 mm of the plan on this machine (the acceptance asks 20 mm); the test
// allows 25 so that the last bits of another CPU's libm cannot turn it red.
TEST(DynamicsSimulation, TheChairOnTheFeetExecutes) {
  const Scenario sc = Scenario::load(test::sourcePath("models/scenarios/chair_feet.yaml"));
  const Plan plan = readPlan(test::sourcePath("tests/data/chair_feet.plan.json"), sc);
  const InterpolationResult t = interpolate(plan, sc, withScenarioMargins(sc, {}));
  ASSERT_TRUE(t.success()) << t.reason;
  const hrp2::SimulationReport r = hrp2::simulate(sc, t.trajectory);
  EXPECT_EQ(r.verdict, hrp2::SimulationReport::Verdict::Executed) << r.reason;
  EXPECT_LT(r.worst_slip, hrp2::DynamicsOptions{}.slip_bound) << r.worst_slip_contact;
  EXPECT_LT(r.worst_base_drift, 0.025);
  ASSERT_EQ(r.phases.size(), t.trajectory.phases.size());
  // Off the seat at the end, on both soles.
  double seat = 0, floor = 0;
  for (const auto& c : r.phases.back().contacts) (c.surface == "chair_seat" ? seat : floor) += c.force.z();
  EXPECT_EQ(seat, 0.0);
  EXPECT_GT(floor, 500.0);
}

TEST(DynamicsSimulation, ReportIsJson) {
  hrp2::SimulationReport r;
  r.verdict = hrp2::SimulationReport::Verdict::Slipped;
  r.reason = "r_sole on floor slipped";
  hrp2::PhaseOutcome p;
  p.contacts.push_back({});
  r.phases.push_back(p);
  const std::string j = hrp2::reportToJson(r);
  EXPECT_NE(j.find("\"verdict\": \"slipped\""), std::string::npos) << j;
  EXPECT_NE(j.find("\"plan_force\": null"), std::string::npos) << j;
  EXPECT_NE(j.find("acyclic.simulation/1"), std::string::npos) << j;
}

TEST(SimulateProcess, HelpBadInputAndAFall) {
  const std::string exe = test::binaryPath("processes/acyclic-simulate");
  const auto help = test::runProcess(exe + " --help");
  EXPECT_EQ(help.status, 0);
  EXPECT_NE(help.output.find("Exit status: 0 executed"), std::string::npos) << help.output;
  test::TempDir dir;
  const std::string scenario = test::sourcePath("models/scenarios/step_forward.yaml");
  // A trajectory file with a bad field: exit 2, the file and the field named.
  const std::string bad = dir.write("bad.json", R"({"format": "acyclic.trajectory/1", "dt": "fast"})");
  const auto b = test::runProcess(exe + " " + scenario + " --trajectory " + bad);
  EXPECT_EQ(b.status, 2) << b.output;
  EXPECT_NE(b.output.find("bad.json"), std::string::npos) << b.output;
  const auto missing = test::runProcess(exe + " " + scenario + " --trajectory " + dir.path() + "/none.json");
  EXPECT_EQ(missing.status, 2) << missing.output;
  // A fall: exit 1, the verdict printed and written.
  const Scenario& sc = floorScenario();
  Trajectory tr = leaningTrajectory(sc, 20 * M_PI / 180);
  tr.scenario = scenario;
  writeTrajectory(tr, sc, dir.path() + "/lean.json");
  const auto f = test::runProcess(exe + " " + scenario + " --trajectory " + dir.path() + "/lean.json --settle 2 --report " +
                                  dir.path() + "/r.json");
  EXPECT_EQ(f.status, 1) << f.output;
  EXPECT_NE(f.output.find("verdict: fell"), std::string::npos) << f.output;
  EXPECT_NE(test::readFile(dir.path() + "/r.json").find("\"verdict\": \"fell\""), std::string::npos);
  // A trace: a header naming every spot's force, then one row per period up
  // to the fall.
  const auto traced = test::runProcess(exe + " " + scenario + " --trajectory " + dir.path() +
                                       "/lean.json --settle 2 -q --no-stabilizer --trace " + dir.path() + "/t.csv");
  EXPECT_EQ(traced.status, 1) << traced.output;
  const std::string csv = test::readFile(dir.path() + "/t.csv");
  EXPECT_EQ(csv.rfind("t,phase,stabilizer,com_x", 0), 0u) << csv.substr(0, 200);
  EXPECT_NE(csv.find(",l_palm_fz,zmp_x,zmp_y,wanted_zmp_x,wanted_zmp_y,r_sole_turn_x"), std::string::npos);
  EXPECT_NE(csv.find(",l_sole_turn_y\n"), std::string::npos);
  const long rows = std::count(csv.begin(), csv.end(), '\n') - 1;
  EXPECT_GT(rows, 100);
  EXPECT_LT(rows, 800);  // 4 s at most: stopped at the fall
}

// --hold-start: the scenario's start held, no trajectory file. The chair's
// seated start tips back off its thighs' patches on the spots alone (the
// test above); the floor's standing start holds.
TEST(SimulateProcess, HoldsAScenariosStartWithoutATrajectory) {
  const std::string exe = test::binaryPath("processes/acyclic-simulate");
  const std::string floor = test::sourcePath("models/scenarios/step_forward.yaml");
  const std::string chair = test::sourcePath("models/scenarios/chair_paper.yaml");
  const auto neither = test::runProcess(exe + " " + floor);
  EXPECT_EQ(neither.status, 2) << neither.output;
  EXPECT_NE(neither.output.find("--trajectory FILE or --hold-start SECONDS"), std::string::npos) << neither.output;
  const auto both = test::runProcess(exe + " " + floor + " --hold-start 1 --trajectory x.json");
  EXPECT_EQ(both.status, 2) << both.output;
  const auto negative = test::runProcess(exe + " " + floor + " --hold-start -1");
  EXPECT_EQ(negative.status, 2) << negative.output;

  const auto stands = test::runProcess(exe + " " + floor + " --hold-start 1");
  EXPECT_EQ(stands.status, 0) << stands.output;
  EXPECT_NE(stands.output.find("the start held 1 s, 201 samples"), std::string::npos) << stands.output;
  EXPECT_NE(stands.output.find("verdict: executed at 1.500 s"), std::string::npos) << stands.output;
  const auto tips = test::runProcess(exe + " " + chair + " --hold-start 3 --no-body-contacts");
  EXPECT_EQ(tips.status, 1) << tips.output;
  EXPECT_NE(tips.output.find("verdict: fell"), std::string::npos) << tips.output;
}
