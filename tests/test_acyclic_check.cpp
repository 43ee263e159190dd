// acyclic-check as a user runs it: exit status and what it prints.
#include <gtest/gtest.h>

#include "planner/plan/plan.h"
#include "test_support.h"

namespace {

acyclic::test::ProcessRun run(const std::string& args) {
  return acyclic::test::runProcess(acyclic::test::binaryPath("processes/acyclic-check") + " " + args);
}

}  // namespace

TEST(AcyclicCheck, ChairStartStanceIsValid) {
  const acyclic::test::ProcessRun r = run(acyclic::test::sourcePath("models/scenarios/chair_table.yaml"));
  EXPECT_EQ(r.status, 0) << r.output;
  for (const char* part : {"joint limits", "contacts", "collisions", "equilibrium", "[ ok ] equilibrium"})
    EXPECT_NE(r.output.find(part), std::string::npos) << part << "\n" << r.output;
  EXPECT_NE(r.output.find("start stance: valid"), std::string::npos) << r.output;
}

TEST(AcyclicCheck, ThePlannersChairPlanIsValid) {
  // tests/data/chair.plan.json: the planner's plan for the chair scenario
  // (84 stances, acyclic-planner --in models/scenarios/chair_table.yaml),
  // kept as written: every stance and the sequence pass the contract.
  const acyclic::test::ProcessRun r = run(acyclic::test::sourcePath("models/scenarios/chair_table.yaml") + " --plan " +
                                          acyclic::test::sourcePath("tests/data/chair.plan.json"));
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("84 of 84 stances valid"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("plan: valid"), std::string::npos) << r.output;
}

TEST(AcyclicCheck, ViolationsArePrintedWithFiguresAndFail) {
  acyclic::test::TempDir dir;
  std::string text = acyclic::test::scenarioText("models/scenarios/chair_table.yaml");
  // Knee beyond its limit, and the robot sunk 5 cm into the seat.
  const std::string start = "    base_position: [0, 0, 0.37]";
  ASSERT_NE(text.find(start), std::string::npos);
  text.replace(text.find(start), start.size(), "    base_position: [0, 0, 0.32]");
  const std::string knee = "RLEG_JOINT3: 117.953";
  ASSERT_NE(text.find(knee), std::string::npos);
  text.replace(text.find(knee), knee.size(), "RLEG_JOINT3: 155");
  const acyclic::test::ProcessRun r = run(dir.write("bad.yaml", text));
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_NE(r.output.find("RLEG_JOINT3"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("penetration"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("INVALID"), std::string::npos) << r.output;
}

// The forces a plan reports are what a controller would apply: forces on the
// corners of the square pyramid (|f_x| = |f_y| = mu f_n), outside the Coulomb
// cone, fail; the plan's own forces pass, with their worst ratio printed.
TEST(AcyclicCheck, ReportedForcesOutsideTheConeFail) {
  const std::string scenario = acyclic::test::sourcePath("models/scenarios/chair_table.yaml");
  const acyclic::Scenario sc = acyclic::Scenario::load(scenario);
  acyclic::Plan plan = acyclic::readPlan(acyclic::test::sourcePath("tests/data/chair.plan.json"), sc);
  plan.stances.resize(1);  // the start stance alone: a plan that ends short of the goal, forces checked all the same
  acyclic::test::TempDir dir;
  const acyclic::test::ProcessRun good = run(scenario + " --plan " + [&] {
    const std::string path = dir.path() + "/start.plan.json";
    acyclic::writePlan(plan, sc, path);
    return path;
  }());
  EXPECT_NE(good.output.find("[ ok ] friction      reported forces: worst ||f_t|| / (mu f_n)"), std::string::npos)
      << good.output;
  bool changed = false;
  for (auto& c : plan.stances[0].contacts) {
    if (!c.spec.supporting || sc.robot->spots()[c.spec.spot].name != "r_sole") continue;
    const double mu = sc.scene->surfaces()[c.spec.surface].friction;
    for (auto& f : c.forces) f = Eigen::Vector3d(mu * f.z(), mu * f.z(), f.z()), changed = true;  // the floor's normal is z
  }
  ASSERT_TRUE(changed);
  const std::string path = dir.path() + "/corners.plan.json";
  acyclic::writePlan(plan, sc, path);
  const acyclic::test::ProcessRun bad = run(scenario + " --plan " + path + " -v");
  EXPECT_EQ(bad.status, 1) << bad.output;
  EXPECT_NE(bad.output.find("outside the friction cone, ||f_t|| = 1.4 mu f_n"), std::string::npos) << bad.output;
  EXPECT_NE(bad.output.find("[FAIL] friction      reported forces: worst ||f_t|| / (mu f_n) 1.414"), std::string::npos)
      << bad.output;
}

TEST(AcyclicCheck, BadInputNamesTheFileAndExitsTwo) {
  const acyclic::test::ProcessRun missing = run("/nonexistent/scenario.yaml");
  EXPECT_EQ(missing.status, 2);
  EXPECT_NE(missing.output.find("/nonexistent/scenario.yaml"), std::string::npos) << missing.output;
  const acyclic::test::ProcessRun help = run("--help");
  EXPECT_EQ(help.status, 0);
  EXPECT_NE(help.output.find("validity contract"), std::string::npos) << help.output;
}

TEST(AcyclicCheck, ScenarioInputErrorsAreBadInputNotViolations) {
  acyclic::test::TempDir dir;
  const std::string chair = acyclic::test::scenarioText("models/scenarios/chair_table.yaml");
  auto with = [&](const std::string& from, const std::string& to) {
    std::string t = chair;
    EXPECT_NE(t.find(from), std::string::npos) << from;
    t.replace(t.find(from), from.size(), to);
    return dir.write("bad.yaml", t);
  };
  // A key given twice: both lines named.
  const acyclic::test::ProcessRun twice = run(with("seed: 1\n", "seed: 1\nseed: 2\n"));
  EXPECT_EQ(twice.status, 2) << twice.output;
  EXPECT_NE(twice.output.find("bad.yaml"), std::string::npos) << twice.output;
  EXPECT_NE(twice.output.find("given twice in one map (lines 10 and 11)"), std::string::npos) << twice.output;
  // The planner section, read as the planner reads it.
  const acyclic::test::ProcessRun planner =
      run(with("  posture_iterations: 40\n", "  posture_iterations: 40\n  max_nodez: 3\n"));
  EXPECT_EQ(planner.status, 2) << planner.output;
  EXPECT_NE(planner.output.find("max_nodez"), std::string::npos) << planner.output;
  // 1e300 degrees is not a joint beyond its limit: it is not an angle.
  const acyclic::test::ProcessRun absurd = run(with("RLEG_JOINT3: 117.953", "RLEG_JOINT3: 1e300"));
  EXPECT_EQ(absurd.status, 2) << absurd.output;
  EXPECT_NE(absurd.output.find("RLEG_JOINT3"), std::string::npos) << absurd.output;
  const acyclic::test::ProcessRun nan = run(with("RLEG_JOINT3: 117.953", "RLEG_JOINT3: .nan"));
  EXPECT_EQ(nan.status, 2) << nan.output;
}

TEST(AcyclicCheck, PushMarginIsPrintedForTheStartAndAPlansWeakestStances) {
  const std::string chair = acyclic::test::sourcePath("models/scenarios/chair_table.yaml");
  const acyclic::test::ProcessRun start = run(chair + " --push-margin");
  EXPECT_EQ(start.status, 0) << start.output;
  EXPECT_NE(start.output.find("[info] push margin"), std::string::npos) << start.output;
  EXPECT_NE(start.output.find("per direction (0, 45, ... 315 deg):"), std::string::npos) << start.output;
  // Not a verdict: the stored plan is valid. Its stances on the thighs are
  // played open-loop, the side steps on the soles alone under the stabilizer.
  const acyclic::test::ProcessRun plan =
      run(chair + " --push-margin --plan " + acyclic::test::sourcePath("tests/data/chair.plan.json"));
  EXPECT_EQ(plan.status, 0) << plan.output;
  const std::size_t open_loop = plan.output.find(" stances played open-loop (a contact other than coplanar soles); the weakest: stance ");
  const std::size_t feet = plan.output.find(" stances on coplanar soles alone (where HRP-2's bridge runs its stabilizer); the weakest: stance ");
  ASSERT_NE(open_loop, std::string::npos) << plan.output;
  ASSERT_NE(feet, std::string::npos) << plan.output;
  // The two groups count the 84 stances between them.
  const auto count = [&](std::size_t at) {
    const std::size_t begin = plan.output.rfind("push margin", at) + std::string("push margin").size();
    return std::stoi(plan.output.substr(begin, at - begin));
  };
  EXPECT_EQ(count(open_loop) + count(feet), 84) << plan.output;
  EXPECT_GT(count(open_loop), 0);
  EXPECT_GT(count(feet), 0);
  EXPECT_NE(plan.output.find("plan: valid"), std::string::npos) << plan.output;
  const acyclic::test::ProcessRun traj = run(chair + " --push-margin --trajectory x.json");
  EXPECT_EQ(traj.status, 2) << traj.output;
  EXPECT_NE(traj.output.find("excludes"), std::string::npos) << "refused by the options, before any file\n" << traj.output;
}
