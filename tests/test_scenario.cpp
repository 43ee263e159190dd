// Scene and scenario files: the chair scenario as the paper describes it, and
// bad files rejected with an error naming the file, the field and the expectation.
#include <gtest/gtest.h>

#include <algorithm>

#include "planner/common/format_error.h"
#include "planner/model/kinematics.h"
#include "planner/scene/scenario.h"
#include "test_support.h"

using namespace acyclic;

namespace {

const std::string kRobot = test::sourcePath("models/hrp2/hrp2.yaml");
const std::string kScene = test::sourcePath("models/scenes/chair_table.yaml");

std::string scenarioText(const std::string& extra_start = "", const std::string& goal = "{link: WAIST, axis: y, min: 0.8}") {
  return "format: acyclic.scenario/1\n"
         "robot: " + kRobot + "\n"
         "scene: " + kScene + "\n"
         "start:\n"
         "  configuration: {posture: sitting}\n"
         "  contacts:\n"
         "    - {spot: r_sole, surface: floor}\n" + extra_start +
         "goal: " + goal + "\n";
}

// Loading `text` fails with an error about `file_part` and exactly `field`.
void expectFormatError(const std::string& text, const std::string& field, const std::string& needle = "") {
  test::TempDir dir;
  const std::string path = dir.write("bad.yaml", text);
  try {
    Scenario::load(path);
    FAIL() << "loaded a bad scenario; expected an error at " << field;
  } catch (const FormatError& e) {
    EXPECT_EQ(e.field(), field) << e.what();
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
  }
}

}  // namespace

TEST(ChairScenario, MatchesThePaper) {
  const Scenario sc = Scenario::load(test::sourcePath("models/scenarios/chair_table.yaml"));
  EXPECT_EQ(sc.name, "chair_table");
  // Sitting: both feet on the floor, both thighs on the seat, all supporting.
  ASSERT_EQ(sc.start_stance.size(), 4u);
  int on_seat = 0, on_floor = 0;
  for (const auto& c : sc.start_stance) {
    EXPECT_TRUE(c.supporting);
    const std::string surf = sc.scene->surfaces()[c.surface].name;
    on_seat += surf == "chair_seat";
    on_floor += surf == "floor";
  }
  EXPECT_EQ(on_seat, 2);
  EXPECT_EQ(on_floor, 2);
  EXPECT_EQ(sc.key_postures.size(), 4u);  // four hand-written key postures (paper, 3.1)
  EXPECT_EQ(sc.allowed_spots.size(), 12u);
  EXPECT_EQ(sc.allowed_surfaces.size(), 3u);
  // The goal lies beyond the side of the table and the start does not meet it.
  Kinematics k(sc.robot);
  k.setConfiguration(sc.start);
  EXPECT_FALSE(sc.goal.linkWithinBounds(k));
  k.setConfiguration(sc.key_postures.back());
  EXPECT_TRUE(sc.goal.linkWithinBounds(k));
  const auto& table = sc.scene->surfaces()[sc.scene->surfaceIndex("table_top")];
  double table_y_max = -1e9;
  for (const auto& v : table.polygon.vertices()) table_y_max = std::max(table_y_max, (table.frame * Eigen::Vector3d(v.x(), v.y(), 0)).y());
  EXPECT_GT(sc.goal.min, table_y_max);
}

TEST(ChairScenario, TooNarrowToStandStraightUp) {
  // Standing up in place (half-sitting above the seated feet) puts the robot
  // into the table: the scene forces the use of other contacts.
  const Scenario sc = Scenario::load(test::sourcePath("models/scenarios/chair_table.yaml"));
  Kinematics k(sc.robot);
  k.setConfiguration(sc.start);
  const double feet_x = k.spotPose(sc.robot->spotIndex("r_sole")).translation().x();
  Configuration standing = sc.robot->posture("half_sitting");
  standing.base_position.x() = feet_x;  // feet where they are when seated
  k.setConfiguration(standing);
  const auto& table = sc.scene->obstacles()[sc.scene->obstacleIndex("table_top")].shape;
  const Eigen::Vector3d chest = k.linkPose(sc.robot->linkIndex("CHEST_LINK1")).translation();
  const Eigen::Vector3d table_min = table.pose.translation() - table.size / 2;
  EXPECT_GT(chest.x() + 0.1, table_min.x()) << "the chest would not reach over the table edge";
  EXPECT_GT(chest.z() + 0.275, table_min.z());
}

TEST(ScenarioFiles, StartPlacementComesFromTheConfiguration) {
  test::TempDir dir;
  const Scenario sc = Scenario::load(dir.write("s.yaml", scenarioText("    - {spot: l_sole, surface: floor, x: 0.01, theta_deg: 90}\n")));
  ASSERT_EQ(sc.start_stance.size(), 2u);
  Kinematics k(sc.robot);
  k.setConfiguration(sc.start);
  const auto& floor = sc.scene->surfaces()[sc.start_stance[0].surface];
  const Eigen::Vector3d expected = floor.frame.inverse() * k.spotPose(sc.start_stance[0].spot).translation();
  EXPECT_NEAR(sc.start_stance[0].placement.x, expected.x(), 1e-12);
  EXPECT_NEAR(sc.start_stance[0].placement.y, expected.y(), 1e-12);
  EXPECT_NEAR(sc.start_stance[1].placement.x, 0.01, 1e-12);  // given values win
  EXPECT_NEAR(sc.start_stance[1].placement.theta, M_PI / 2, 1e-12);
}

// A goal with supported_by holds only for a stance in which each listed spot
// touches and supports: the link bound alone does not meet it.
TEST(ScenarioFiles, GoalSupportedByNeedsEachSpotSupporting) {
  test::TempDir dir;
  const Scenario sc = Scenario::load(
      dir.write("goal.yaml", scenarioText("", "{link: WAIST, axis: z, max: 5, supported_by: [r_sole, l_sole]}")));
  ASSERT_EQ(sc.goal.supporting_spots.size(), 2u);
  Kinematics k(sc.robot);
  k.setConfiguration(sc.start);
  ASSERT_TRUE(sc.goal.linkWithinBounds(k));
  const ContactSpec r = sc.start_stance[0];
  ContactSpec l = r;
  l.spot = sc.robot->spotIndex("l_sole");
  EXPECT_FALSE(sc.goal.satisfied(k, {r}));  // l_sole not in the stance
  l.supporting = false;
  EXPECT_FALSE(sc.goal.satisfied(k, {r, l}));  // in it, geometric only
  l.supporting = true;
  EXPECT_TRUE(sc.goal.satisfied(k, {r, l}));
  EXPECT_NE(sc.goal.describe(*sc.robot).find("supported by r_sole and l_sole"), std::string::npos)
      << sc.goal.describe(*sc.robot);
  // Without supported_by the link bound is the whole goal.
  const Scenario plain = Scenario::load(dir.write("plain.yaml", scenarioText("", "{link: WAIST, axis: z, max: 5}")));
  EXPECT_TRUE(plain.goal.satisfied(k, {}));
}

// forbidden_contacts takes pairs out of allowed_spots x allowed_surfaces;
// the start may hold one (the planner only never makes it).
TEST(ScenarioFiles, ForbiddenContactsTakePairsOutOfTheAllowedOnes) {
  test::TempDir dir;
  const Scenario sc = Scenario::load(dir.write(
      "s.yaml", scenarioText() + "allowed_spots: [r_sole, l_sole, r_palm]\n"
                                 "forbidden_contacts:\n  - {spot: r_sole, surface: floor}\n"
                                 "  - {spot: l_sole, surface: chair_seat}\n"));
  const int r_sole = sc.robot->spotIndex("r_sole"), l_sole = sc.robot->spotIndex("l_sole");
  const int r_palm = sc.robot->spotIndex("r_palm"), l_palm = sc.robot->spotIndex("l_palm");
  const int floor = sc.scene->surfaceIndex("floor"), seat = sc.scene->surfaceIndex("chair_seat");
  ASSERT_EQ(sc.forbidden_contacts.size(), 2u);
  EXPECT_FALSE(sc.allows(r_sole, floor));  // forbidden, although the start stands on it
  EXPECT_FALSE(sc.allows(l_sole, seat));
  EXPECT_TRUE(sc.allows(l_sole, floor));
  EXPECT_TRUE(sc.allows(r_sole, seat));
  EXPECT_TRUE(sc.allows(r_palm, seat));
  EXPECT_FALSE(sc.allows(l_palm, floor));  // not in allowed_spots
  // A forbidden pair outside the allowed spots is accepted (a scenario
  // narrowed to fewer spots keeps its list) and stays disallowed.
  const Scenario narrowed = Scenario::load(dir.write(
      "narrowed.yaml", scenarioText() + "allowed_spots: [r_sole]\nforbidden_contacts:\n  - {spot: l_sole, surface: floor}\n"));
  EXPECT_FALSE(narrowed.allows(l_sole, floor));
  EXPECT_TRUE(narrowed.allows(r_sole, floor));
  EXPECT_EQ(sc.start_stance.at(0).spot, r_sole);
  // Without the key every allowed pair is allowed.
  const Scenario plain = Scenario::load(dir.write("plain.yaml", scenarioText()));
  EXPECT_TRUE(plain.forbidden_contacts.empty());
  EXPECT_TRUE(plain.allows(r_sole, floor));
  EXPECT_TRUE(plain.allows(l_palm, seat));
}

TEST(ScenarioFiles, BadFieldsAreNamed) {
  expectFormatError(scenarioText() + "seed: -3\n", "seed", "non-negative");
  expectFormatError(scenarioText("    - {spot: r_foot, surface: floor}\n"), "start.contacts[1].spot", "r_sole");
  expectFormatError(scenarioText("    - {spot: l_sole, surface: roof}\n"), "start.contacts[1].surface", "table_top");
  expectFormatError(scenarioText("    - {spot: r_sole, surface: floor}\n"), "start.contacts[1].spot", "not already");
  expectFormatError(scenarioText("", "{link: WAIST, axis: w, min: 1}"), "goal.axis", "x, y, z");
  expectFormatError(scenarioText("", "{link: WAIST, axis: y}"), "goal", "min, max");
  expectFormatError(scenarioText("", "{link: NECK, axis: y, min: 1}"), "goal.link", "link");
  expectFormatError(scenarioText("", "{link: WAIST, axis: y, min: 1, supported_by: [r_foot]}"), "goal.supported_by[0]",
                    "r_sole");
  expectFormatError(scenarioText("", "{link: WAIST, axis: y, min: 1, supported_by: [r_sole, r_sole]}"),
                    "goal.supported_by[1]", "not already listed");
  expectFormatError(scenarioText("", "{link: WAIST, axis: y, min: 1, supported_by: [r_sole]}") +
                        "allowed_spots: [l_sole]\n",
                    "goal.supported_by[0]", "allowed_spots");
  expectFormatError(scenarioText() + "unexpected: 1\n", "unexpected", "unknown field");
  expectFormatError(scenarioText() + "forbidden_contacts:\n  - {spot: r_foot, surface: floor}\n",
                    "forbidden_contacts[0].spot", "r_sole");
  expectFormatError(scenarioText() + "forbidden_contacts:\n  - {spot: r_sole, surface: roof}\n",
                    "forbidden_contacts[0].surface", "table_top");
  expectFormatError(scenarioText() + "forbidden_contacts:\n  - {spot: r_sole, surface: floor}\n"
                                     "  - {spot: r_sole, surface: floor}\n",
                    "forbidden_contacts[1]", "not already listed");
  expectFormatError(scenarioText() + "forbidden_contacts:\n  - {spot: r_sole, surface: floor, x: 1}\n",
                    "forbidden_contacts[0].x", "unknown field");
  std::string wrong_format = scenarioText();
  wrong_format.replace(wrong_format.find("/1"), 2, "/9");
  expectFormatError(wrong_format, "format", "acyclic.scenario/1");
  std::string bad_joint = scenarioText();
  bad_joint.replace(bad_joint.find("{posture: sitting}"), 18, "{posture: sitting, joints_deg: {KNEE: 3}}");
  expectFormatError(bad_joint, "start.configuration.joints_deg.KNEE", "joint name");
  std::string bad_posture = scenarioText();
  bad_posture.replace(bad_posture.find("sitting}"), 8, "lying}");
  expectFormatError(bad_posture, "start.configuration.posture", "half_sitting");
}

TEST(ScenarioFiles, APublishedRunIsReadWithItsFiguresAndBadOnesAreNamed) {
  // chair_paper carries the paper's own run, which bench_scenarios prints
  // beside the planner's (ISER 2008, section 3.2).
  const Scenario paper = Scenario::load(test::sourcePath("models/scenarios/chair_paper.yaml"));
  ASSERT_TRUE(paper.published.has_value());
  EXPECT_NE(paper.published->source.find("ISER 2008"), std::string::npos);
  EXPECT_EQ(paper.published->nodes, 2400);
  EXPECT_EQ(paper.published->stances, 81);
  EXPECT_DOUBLE_EQ(paper.published->seconds, 5 * 3600.0);
  EXPECT_FALSE(Scenario::load(test::sourcePath("models/scenarios/chair_table.yaml")).published.has_value());
  // Only the source is required.
  test::TempDir dir;
  const Scenario bare = Scenario::load(dir.write("ok.yaml", scenarioText() + "published: {source: a talk}\n"));
  ASSERT_TRUE(bare.published.has_value());
  EXPECT_EQ(bare.published->nodes, 0);
  EXPECT_EQ(bare.published->seconds, 0);
  expectFormatError(scenarioText() + "published: {nodes: 10}\n", "published.source", "missing");
  expectFormatError(scenarioText() + "published: {source: \"\"}\n", "published.source", "non-empty");
  expectFormatError(scenarioText() + "published: {source: x, nodes: -5}\n", "published.nodes", "positive integer");
  expectFormatError(scenarioText() + "published: {source: x, stances: 0}\n", "published.stances", "positive integer");
  expectFormatError(scenarioText() + "published: {source: x, seconds: 0}\n", "published.seconds", "positive");
  expectFormatError(scenarioText() + "published: {source: x, hours: 5}\n", "published.hours", "unknown field");
  expectFormatError(scenarioText() + "published: [x]\n", "published", "source");
}

TEST(SceneFiles, BadFieldsNameTheSceneFile) {
  test::TempDir dir;
  auto load = [&](const std::string& body) {
    const std::string path = dir.write("scene.yaml", "format: acyclic.scene/1\n" + body);
    try {
      Scene::load(path);
    } catch (const FormatError& e) {
      EXPECT_EQ(e.file(), path);
      return e.field();
    }
    return std::string("(loaded)");
  };
  const std::string floor = "  - {name: floor, shape: box, size: [1, 1, 0.1]}\n";
  EXPECT_EQ(load("obstacles:\n  - {name: b, shape: box, size: [1, -1, 1]}\nsurfaces: []\n"), "obstacles[0].size");
  EXPECT_EQ(load("obstacles:\n  - {name: b, shape: cone, radius: 1}\nsurfaces: []\n"), "obstacles[0].shape");
  EXPECT_EQ(load("obstacles:\n" + floor + floor + "surfaces: []\n"), "obstacles[1].name");
  EXPECT_EQ(load("obstacles:\n" + floor +
                 "surfaces:\n  - {name: s, obstacle: wall, friction: 1, polygon: [[0,0],[1,0],[0,1]]}\n"),
            "surfaces[0].obstacle");
  EXPECT_EQ(load("obstacles:\n" + floor +
                 "surfaces:\n  - {name: s, obstacle: floor, friction: 1, polygon: [[0,0],[2,0],[1,0.1],[2,2],[0,2]]}\n"),
            "surfaces[0].polygon");
  EXPECT_EQ(load("obstacles:\n" + floor +
                 "surfaces:\n  - {name: s, obstacle: floor, friction: -1, polygon: [[0,0],[1,0],[0,1]]}\n"),
            "surfaces[0].friction");
  EXPECT_EQ(load("obstacles:\n" + floor + "surfaces:\n  - {name: s, obstacle: floor, polygon: [[0,0],[1,0],[0,1]]}\n"),
            "surfaces[0].friction");
  EXPECT_EQ(load("obstacles:\n" + floor + "surfaces:\n  - {name: s, obstacle: floor, friction: 1, polygon: [[0,0],[1,0],[0,1]], rpy: [0,0,0], rpy_deg: [0,0,0]}\n"),
            "surfaces[0]");
}

TEST(RobotFiles, BadFieldsNameTheRobotFile) {
  test::TempDir dir;
  const std::string urdf = test::sourcePath("models/hrp2/hrp2.urdf");
  std::string text = test::readFile(kRobot);
  text.replace(text.find("urdf: hrp2.urdf"), 15, "urdf: " + urdf);
  auto load = [&](const std::string& from, const std::string& to) {
    std::string t = text;
    const auto at = t.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    t.replace(at, from.size(), to);
    const std::string path = dir.write("robot.yaml", t);
    try {
      RobotModel::load(path);
    } catch (const FormatError& e) {
      EXPECT_EQ(e.file(), path) << e.what();
      return e.field();
    }
    return std::string("(loaded)");
  };
  EXPECT_EQ(load("body: RLEG_LINK5", "body: RLEG_FOOT"), "contact_spots.r_sole.body");
  EXPECT_EQ(load("[0.14, -0.069], [0.14, 0.069]", "[0.14, -0.069], [0.14, -0.069]"), "contact_spots.r_sole.polygon");
  EXPECT_EQ(load("RLEG_JOINT5,\n", "RLEG_JOINT5, RLEG_JOINT5,\n"), "controller_order[6]");
  EXPECT_EQ(load("{a: [RLEG_LINK5], b: [RLEG_LINK2]}", "{a: [RLEG_LINK5], b: [RLEG_LINK1]}"),
            "self_collision_pairs[7].b[0]");  // a link without collision shapes
  EXPECT_EQ(load("  LARM_JOINT0, LARM_JOINT1,", "  LARM_JOINT1,"), "controller_order[23]");
}

TEST(ScenarioFiles, AKeyGivenTwiceIsRefusedWithBothLines) {
  // The second seed is the file's last line.
  const std::string text = scenarioText() + "seed: 1\nseed: 2\n";
  const int last = static_cast<int>(std::count(text.begin(), text.end(), '\n'));
  expectFormatError(text, "seed", "given twice in one map (lines " + std::to_string(last - 1) + " and " +
                                      std::to_string(last) + ")");
  std::string nested = scenarioText();
  nested.replace(nested.find("{posture: sitting}"), 18,
                 "{posture: sitting, joints_deg: {RLEG_JOINT3: 3, RLEG_JOINT3: 4}}");
  expectFormatError(nested, "start.configuration.joints_deg.RLEG_JOINT3", "given twice");
}

TEST(ScenarioFiles, NonFiniteOrAbsurdNumbersAreBadInput) {
  std::string deg = scenarioText();
  deg.replace(deg.find("{posture: sitting}"), 18, "{posture: sitting, joints_deg: {RLEG_JOINT3: 1e300}}");
  expectFormatError(deg, "start.configuration.joints_deg.RLEG_JOINT3", "plausible magnitude");
  std::string turns = scenarioText();
  turns.replace(turns.find("{posture: sitting}"), 18, "{posture: sitting, joints_deg: {RLEG_JOINT3: 1000}}");
  expectFormatError(turns, "start.configuration.joints_deg.RLEG_JOINT3", "within +-720");
  std::string nan = scenarioText();
  nan.replace(nan.find("{posture: sitting}"), 18, "{posture: sitting, base_position: [0, .nan, 0]}");
  expectFormatError(nan, "start.configuration.base_position[1]", "finite");
  expectFormatError(scenarioText("", "{link: WAIST, axis: y, min: 1e300}"), "goal.min", "plausible magnitude");
  expectFormatError(scenarioText("    - {spot: l_sole, surface: floor, theta_deg: 1000}\n"),
                    "start.contacts[1].theta_deg", "within +-720");
}
