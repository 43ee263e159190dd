// acyclic-guide --scenario-keys: a scenario's hand-written key postures
// written as a guide file bit for bit, and the guide shipped that way for
// chair_paper with the right palm on the chair's seat (docs/design.md
// section 6). The planner's search is chaotic in the last bits of its
// guide, so "the same key postures" has to mean the same doubles (but for
// the base quaternion, which the file's reader normalizes: its last bit may
// move; chair_paper's plan on this guide is the same as on its scenario).
#include <gtest/gtest.h>

#include "planner/model/kinematics.h"
#include "planner/plan/guide.h"
#include "planner/scene/scenario.h"
#include "test_support.h"

using namespace acyclic;

namespace {
void expectSameBits(const Configuration& a, const Configuration& b, const std::string& what) {
  EXPECT_EQ(a.base_position, b.base_position) << what;
  EXPECT_LE((a.base_orientation.coeffs() - b.base_orientation.coeffs()).cwiseAbs().maxCoeff(), 1e-15) << what;
  EXPECT_EQ(a.joints, b.joints) << what;
}
const std::string kChairPaper = "models/scenarios/chair_paper.yaml";
}  // namespace

TEST(AcyclicGuide, ScenarioKeysAreWrittenBitForBitWithTheirSource) {
  test::TempDir dir;
  const auto r = test::runProcess(test::binaryPath("processes/acyclic-guide") + " --in " +
                                  test::sourcePath(kChairPaper) + " --scenario-keys --source 'hand: test' --out " +
                                  dir.path() + "/g.json");
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("its 12 key postures written"), std::string::npos) << r.output;
  const Scenario sc = Scenario::load(test::sourcePath(kChairPaper));
  const Guide g = readGuide(dir.path() + "/g.json", sc);
  EXPECT_EQ(g.source, "hand: test");
  ASSERT_EQ(g.key_postures.size(), sc.key_postures.size());
  for (std::size_t i = 0; i < g.key_postures.size(); ++i)
    expectSameBits(g.key_postures[i], sc.key_postures[i], "key posture " + std::to_string(i + 1));
  // Without --source the text is "hand"; an empty one is refused.
  const auto d = test::runProcess(test::binaryPath("processes/acyclic-guide") + " --in " +
                                  test::sourcePath(kChairPaper) + " --scenario-keys --out " + dir.path() + "/d.json");
  ASSERT_EQ(d.status, 0) << d.output;
  EXPECT_EQ(readGuide(dir.path() + "/d.json", sc).source, "hand");
  const auto e = test::runProcess(test::binaryPath("processes/acyclic-guide") + " --in " +
                                  test::sourcePath(kChairPaper) + " --scenario-keys --source '' --out " + dir.path() +
                                  "/e.json");
  EXPECT_NE(e.status, 0) << e.output;
  EXPECT_NE(e.output.find("non-empty"), std::string::npos) << e.output;
}

TEST(AcyclicGuide, ScenarioKeysOfAScenarioWithoutThemIsBadInputNamingTheField) {
  test::TempDir dir;
  const auto r = test::runProcess(test::binaryPath("processes/acyclic-guide") + " --in " +
                                  test::sourcePath("models/scenarios/step_up.yaml") + " --scenario-keys --out " +
                                  dir.path() + "/g.json");
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("step_up.yaml: key_postures"), std::string::npos) << r.output;
  const auto s = test::runProcess(test::binaryPath("processes/acyclic-guide") + " --in " +
                                  test::sourcePath(kChairPaper) + " --source x --out " + dir.path() + "/h.json");
  EXPECT_NE(s.status, 0) << s.output;  // --source means nothing for an OMPL guide
  EXPECT_NE(s.output.find("--scenario-keys"), std::string::npos) << s.output;
}

// The shipped guide is chair_paper's twelve key postures with a thirteenth
// after the sixth in which the right palm rests on the seat, as the paper's
// robot's right hand did (docs/design.md section 6 says so and plans it).
TEST(AcyclicGuide, TheHandOnChairGuideIsChairPapersKeysAndTheRightPalmOnTheSeat) {
  const Scenario sc = Scenario::load(test::sourcePath(kChairPaper));
  const Guide g = readGuide(test::sourcePath("models/guides/chair_paper_hand_on_chair.guide.json"), sc);
  ASSERT_EQ(g.key_postures.size(), 13u);
  for (std::size_t i = 0; i < 6; ++i)
    expectSameBits(g.key_postures[i], sc.key_postures[i], "key posture " + std::to_string(i + 1));
  for (std::size_t i = 6; i < 12; ++i)
    expectSameBits(g.key_postures[i + 1], sc.key_postures[i], "key posture " + std::to_string(i + 1));
  Kinematics kin(sc.robot);
  const Surface& seat = sc.scene->surfaces()[sc.scene->surfaceIndex("chair_seat")];
  const int palm = sc.robot->spotIndex("r_palm");
  kin.setConfiguration(g.key_postures[6]);
  EXPECT_TRUE(spotNearSurface(seat, kin.spotPose(palm), 0.002, 0.01))
      << "the right palm at " << kin.spotPose(palm).translation().transpose();
  for (std::size_t i : {5u, 7u}) {  // its neighbours have the hand elsewhere
    kin.setConfiguration(g.key_postures[i]);
    EXPECT_FALSE(spotNearSurface(seat, kin.spotPose(palm), 0.05, 0.5)) << "key posture " << i + 1;
  }
}
