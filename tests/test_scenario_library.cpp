// The scenarios shipped in models/scenarios: each loads, starts in a stance the
// independent check accepts, and does not meet its goal at the start. And the
// scenarios that need non-foot contacts do need them.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "planner/check/quasi_static.h"
#include "planner/check/validity.h"
#include "planner/model/kinematics.h"
#include "planner/scene/scenario.h"
#include "test_support.h"

using namespace acyclic;
namespace fs = std::filesystem;

namespace {

std::vector<std::string> shippedScenarios() {
  std::vector<std::string> out;
  for (const auto& e : fs::directory_iterator(test::sourcePath("models/scenarios")))
    if (e.path().extension() == ".yaml") out.push_back(e.path().string());
  std::sort(out.begin(), out.end());
  return out;
}

std::vector<ContactSpec> without(std::vector<ContactSpec> stance, const Scenario& sc,
                                 const std::vector<std::string>& spots) {
  stance.erase(std::remove_if(stance.begin(), stance.end(),
                              [&](const ContactSpec& c) {
                                return std::find(spots.begin(), spots.end(), sc.robot->spots()[c.spot].name) !=
                                       spots.end();
                              }),
               stance.end());
  return stance;
}

}  // namespace

TEST(ScenarioLibrary, EveryScenarioStartsValidAndAwayFromItsGoal) {
  const auto files = shippedScenarios();
  ASSERT_GE(files.size(), 3u);
  for (const auto& f : files) {
    SCOPED_TRACE(f);
    const Scenario sc = Scenario::load(f);
    ValidityChecker checker(sc.robot, sc.scene);
    const ValidityReport rep = checker.checkPosture(sc.start, sc.start_stance);
    for (const auto& part : rep.parts)
      EXPECT_TRUE(part.ok()) << part.name << ": " << (part.violations.empty() ? "" : part.violations[0]);
    Kinematics k(sc.robot);
    k.setConfiguration(sc.start);
    EXPECT_FALSE(sc.goal.satisfied(k, sc.start_stance));
    if (!sc.key_postures.empty()) {
      ASSERT_GE(sc.key_postures.size(), 2u);
      k.setConfiguration(sc.key_postures.back());
      EXPECT_TRUE(sc.goal.linkWithinBounds(k)) << "the rough trajectory ends short of the goal";
    }
  }
}

// The wet ramp cannot be climbed on the feet: the ramp's friction cone does
// not contain the vertical, so feet alone can never balance gravity, in any
// posture; the start posture holds with either palm alone, not with none.
TEST(ScenarioLibrary, WetRampHoldsOnlyWithAHandOnABar) {
  const Scenario sc = Scenario::load(test::sourcePath("models/scenarios/wet_ramp.yaml"));
  const Surface& ramp = sc.scene->surfaces()[sc.scene->surfaceIndex("ramp")];
  const double tilt = std::acos(ramp.frame.linear().col(2).dot(Eigen::Vector3d::UnitZ()));
  EXPECT_LT(std::atan(ramp.friction), tilt - 0.05);  // a margin beyond the cone's linearization
  Kinematics k(sc.robot);
  k.setConfiguration(sc.start);
  const QuasiStaticChecker statics(sc.robot, sc.scene);
  EXPECT_TRUE(statics.check(k, sc.start_stance).feasible);
  EXPECT_TRUE(statics.check(k, without(sc.start_stance, sc, {"r_palm"})).feasible);
  EXPECT_TRUE(statics.check(k, without(sc.start_stance, sc, {"l_palm"})).feasible);
  const QuasiStaticReport feet = statics.check(k, without(sc.start_stance, sc, {"r_palm", "l_palm"}));
  EXPECT_FALSE(feet.feasible);
  EXPECT_FALSE(feet.reason.empty());
}
