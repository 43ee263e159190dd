// Plans: acyclic.plan/1 round trip, the plan check, and acyclic-check --plan.
#include <gtest/gtest.h>

#include "planner/check/plan_check.h"
#include "planner/common/format_error.h"
#include "planner/posture/posture_generator.h"
#include "test_support.h"

using namespace acyclic;

namespace {

const Scenario& chair() {
  static Scenario sc = Scenario::load(test::sourcePath("models/scenarios/chair_table.yaml"));
  return sc;
}

PlanStance stanceFrom(const PostureResult& r, const std::vector<ContactSpec>& specs, const Scenario& sc) {
  PlanStance s;
  s.configuration = r.configuration;
  for (std::size_t i = 0; i < specs.size(); ++i) {
    PlanContact c;
    c.spec = specs[i];
    c.frame = contactFrame(sc.scene->surfaces()[specs[i].surface], specs[i].placement);
    for (const auto& f : r.forces)
      if (f.contact == static_cast<int>(i)) c.points = f.points, c.forces = f.forces;
    s.contacts.push_back(c);
  }
  return s;
}

// Seated; then the left wrist added on the table (geometric only); then it supports.
const Plan& threeStancePlan() {
  static Plan plan = [] {
    const Scenario& sc = chair();
    PostureGenerator pg(sc.robot, sc.scene);
    Plan p;
    p.scenario = "models/scenarios/chair_table.yaml";
    p.robot = "models/hrp2/hrp2.yaml";
    PostureRequest r;
    r.contacts = sc.start_stance;
    r.initial_guess = sc.start;
    const PostureResult s0 = pg.solve(r);
    EXPECT_TRUE(s0.success()) << s0.reason;
    p.stances.push_back(stanceFrom(s0, sc.start_stance, sc));

    FloatingContact f;
    f.spot = sc.robot->spotIndex("l_wrist");
    f.surface = sc.scene->surfaceIndex("table_top");
    f.volume.polygon = sc.scene->surfaces()[f.surface].polygon;
    r.floating = f;
    r.initial_guess = s0.configuration;
    const PostureResult s1 = pg.solve(r);
    EXPECT_TRUE(s1.success()) << s1.reason;
    std::vector<ContactSpec> with_wrist = sc.start_stance;
    ContactSpec wrist;
    wrist.spot = f.spot;
    wrist.surface = f.surface;
    wrist.supporting = false;
    wrist.placement = s1.floating;
    with_wrist.push_back(wrist);
    p.stances.push_back(stanceFrom(s1, with_wrist, sc));

    with_wrist.back().supporting = true;
    PostureRequest r2;
    r2.contacts = with_wrist;
    r2.initial_guess = s1.configuration;
    const PostureResult s2 = pg.solve(r2);
    EXPECT_TRUE(s2.success()) << s2.reason;
    p.stances.push_back(stanceFrom(s2, with_wrist, sc));
    p.stats.posture_calls = 3;
    return p;
  }();
  return plan;
}

test::ProcessRun runCheck(const std::string& args) {
  return test::runProcess(test::binaryPath("processes/acyclic-check") + " " + args);
}

}  // namespace

TEST(PlanFile, RoundTripIsExact) {
  const Scenario& sc = chair();
  const Plan& plan = threeStancePlan();
  test::TempDir dir;
  const std::string path = dir.path() + "/plan.json";
  writePlan(plan, sc, path);
  const Plan back = readPlan(path, sc);
  ASSERT_EQ(back.stances.size(), plan.stances.size());
  EXPECT_EQ(back.scenario, plan.scenario);
  EXPECT_EQ(back.stats.posture_calls, 3);
  for (std::size_t i = 0; i < plan.stances.size(); ++i) {
    const auto& a = plan.stances[i];
    const auto& b = back.stances[i];
    EXPECT_EQ(a.configuration.joints, b.configuration.joints);
    EXPECT_EQ(a.configuration.base_position, b.configuration.base_position);
    ASSERT_EQ(a.contacts.size(), b.contacts.size());
    for (std::size_t k = 0; k < a.contacts.size(); ++k) {
      EXPECT_EQ(a.contacts[k].spec.spot, b.contacts[k].spec.spot);
      EXPECT_EQ(a.contacts[k].spec.supporting, b.contacts[k].spec.supporting);
      EXPECT_EQ(a.contacts[k].spec.placement.x, b.contacts[k].spec.placement.x);
      EXPECT_EQ(a.contacts[k].forces, b.contacts[k].forces);
    }
  }
  // Forces are written for supporting contacts only.
  EXPECT_TRUE(back.stances[1].contacts.back().forces.empty());
  EXPECT_EQ(back.stances[2].contacts.back().forces.size(), 4u);
  // No planner settings: no field (the files of plans planned without --set
  // are as before); with them, read back in order.
  EXPECT_TRUE(back.planner_settings.empty());
  EXPECT_EQ(planToJson(plan, sc).find("planner_settings"), std::string::npos);
  Plan set = plan;
  set.planner_settings = {"posture_mu_oracle=probing", "portfolio=null"};
  EXPECT_EQ(planFromJson(planToJson(set, sc), "set.json", sc).planner_settings, set.planner_settings);
}

TEST(PlanCheck, ValidStancesAndTheSequenceRules) {
  const Scenario& sc = chair();
  ValidityChecker checker(sc.robot, sc.scene);
  Plan plan = threeStancePlan();
  PlanReport rep = checkPlan(plan, sc, checker);
  for (const auto& s : rep.stances) EXPECT_TRUE(s.valid());
  // Each step changes one contact; the goal (left of the table) is not reached.
  ASSERT_EQ(rep.sequence_violations.size(), 1u);
  EXPECT_NE(rep.sequence_violations[0].find("goal"), std::string::npos);

  // Skipping the middle stance adds a supporting contact in one step: still one change.
  Plan skip = plan;
  skip.stances.erase(skip.stances.begin() + 1);
  EXPECT_EQ(checkPlan(skip, sc, checker).sequence_violations.size(), 1u);
  // Dropping the first stance: the plan no longer starts at the start stance.
  Plan late = plan;
  late.stances.erase(late.stances.begin());
  rep = checkPlan(late, sc, checker);
  ASSERT_EQ(rep.sequence_violations.size(), 2u);
  EXPECT_NE(rep.sequence_violations[0].find("start stance"), std::string::npos);
  // Two changes in one step.
  Plan two = plan;
  two.stances[2].contacts.erase(two.stances[2].contacts.begin());
  rep = checkPlan(two, sc, checker);
  bool found = false;
  for (const auto& v : rep.sequence_violations) found = found || v.find("stances 1 -> 2") != std::string::npos;
  EXPECT_TRUE(found);
}

TEST(PlanFile, BadFieldsAreNamed) {
  const Scenario& sc = chair();
  std::string text = planToJson(threeStancePlan(), sc);
  auto expectField = [&](const std::string& from, const std::string& to, const std::string& field) {
    test::expectBadField([&](const std::string& t) { planFromJson(t, "plan.json", sc); }, text, "plan.json", from, to,
                         field);
  };
  expectField("\"acyclic.plan/1\"", "\"acyclic.plan/2\"", "format");
  expectField("\"spot\": \"r_sole\"", "\"spot\": \"r_foot\"", "stances[0].contacts[0].spot");
  expectField("\"supporting\": true", "\"supporting\": 1", "stances[0].contacts[0].supporting");
  expectField("\"RLEG_JOINT0\"", "\"RLEG_JOINT9\"", "joint_names[0]");
  Plan set = threeStancePlan();
  set.planner_settings = {"max_nodes=3"};
  test::expectBadField([&](const std::string& t) { planFromJson(t, "plan.json", sc); }, planToJson(set, sc),
                       "plan.json", "\"max_nodes=3\"", "3", "planner_settings[0]");
  EXPECT_THROW(planFromJson("{\"format\": ", "plan.json", sc), FormatError);
}

TEST(AcyclicCheckPlan, ChecksEveryStanceAndTheSequence) {
  const Scenario& sc = chair();
  test::TempDir dir;
  const std::string plan = dir.path() + "/plan.json";
  writePlan(threeStancePlan(), sc, plan);
  const std::string scenario = test::sourcePath("models/scenarios/chair_table.yaml");
  const test::ProcessRun r = runCheck(scenario + " --plan " + plan);
  EXPECT_EQ(r.status, 1) << r.output;  // the goal is not reached
  EXPECT_NE(r.output.find("3 of 3 stances valid"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("does not meet the goal"), std::string::npos) << r.output;

  // The same plan against a scenario whose goal it meets: valid.
  std::string text = test::scenarioText("models/scenarios/chair_table.yaml");
  text.replace(text.find("goal: {link: WAIST, axis: y, min: 0.80}"), 39, "goal: {link: WAIST, axis: z, max: 1.0}");
  const test::ProcessRun ok = runCheck(dir.write("s.yaml", text) + " --plan " + plan + " -v");
  EXPECT_EQ(ok.status, 0) << ok.output;
  EXPECT_NE(ok.output.find("plan: valid"), std::string::npos) << ok.output;
  EXPECT_NE(ok.output.find("equilibrium"), std::string::npos) << ok.output;

  const test::ProcessRun bad = runCheck(scenario + " --plan " + dir.write("bad.json", "{\"format\": \"acyclic.plan/1\"}"));
  EXPECT_EQ(bad.status, 2) << bad.output;
  EXPECT_NE(bad.output.find("joint_names"), std::string::npos) << bad.output;
}
