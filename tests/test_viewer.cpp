// The viewer: the data acyclic-view computes, the SVG figures, and
// the page itself in headless Chromium (Debian's chromium; the test FAILS when
// it is missing: scripts/install-deps installs it).
//
// Everything runs on the step_forward scenario, planned and interpolated by the
// real processes once for the suite.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <memory>

#include <nlohmann/json.hpp>

#include "planner/check/validity.h"
#include "planner/model/kinematics.h"
#include "test_support.h"
#include "viewer/export/view_data.h"
#include "viewer/plot/figures.h"

namespace acyclic {
namespace {

using test::binaryPath;
using test::readFile;
using test::runProcess;
using test::sourcePath;
using test::TempDir;

const char* kScenario = "models/scenarios/step_forward.yaml";
constexpr double kG = 9.81;

// One plan and one trajectory of step_forward for the whole suite.
class Viewer : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new TempDir;
    plan_path_ = dir_->path() + "/plan.json";
    trajectory_path_ = dir_->path() + "/trajectory.json";
    const auto plan = runProcess(binaryPath("processes/acyclic-planner") + " --in " + sourcePath(kScenario) +
                                 " --out " + plan_path_);
    ASSERT_EQ(plan.status, 0) << plan.output;
    const auto traj = runProcess(binaryPath("processes/acyclic-interpolator") + " --scenario " + sourcePath(kScenario) +
                                 " --in " + plan_path_ + " --out " + trajectory_path_);
    ASSERT_EQ(traj.status, 0) << traj.output;
  }
  static void TearDownTestSuite() {
    delete dir_;
    dir_ = nullptr;
  }
  void SetUp() override {
    ASSERT_TRUE(std::filesystem::exists(trajectory_path_)) << "the suite's plan and trajectory were not made";
    sc_ = Scenario::load(sourcePath(kScenario));
    plan_ = readPlan(plan_path_, sc_);
    tr_ = readTrajectory(trajectory_path_, sc_);
  }
  static TempDir* dir_;
  static std::string plan_path_, trajectory_path_;
  Scenario sc_;
  Plan plan_;
  Trajectory tr_;
};
TempDir* Viewer::dir_ = nullptr;
std::string Viewer::plan_path_, Viewer::trajectory_path_;

Eigen::Vector3d sum(const std::vector<Eigen::Vector3d>& v) {
  Eigen::Vector3d s = Eigen::Vector3d::Zero();
  for (const auto& x : v) s += x;
  return s;
}

TEST_F(Viewer, StancesShowThePlansPosturesContactsAndForces) {
  const auto stances = stancePostures(sc_, plan_);
  ASSERT_EQ(stances.size(), plan_.stances.size());
  const auto shapes = viewShapes(*sc_.robot);
  int n_shapes = 0;
  for (const auto& l : sc_.robot->links()) n_shapes += static_cast<int>(l.shapes.size());
  EXPECT_EQ(static_cast<int>(shapes.size()), n_shapes);
  EXPECT_GT(n_shapes, 10);
  Kinematics kin(sc_.robot);
  const double weight = sc_.robot->totalMass() * kG;
  for (std::size_t i = 0; i < stances.size(); ++i) {
    const ViewPosture& v = stances[i];
    const PlanStance& s = plan_.stances[i];
    SCOPED_TRACE("stance " + std::to_string(i));
    // The plan's posture, not a changed one.
    EXPECT_TRUE(v.q.joints.isApprox(s.configuration.joints, 0.0));
    kin.setConfiguration(s.configuration);
    EXPECT_LT((v.com - kin.centerOfMass()).norm(), 1e-12);
    ASSERT_EQ(v.shape_poses.size(), shapes.size());
    for (std::size_t k = 0; k < shapes.size(); ++k) {
      const Eigen::Isometry3d want =
          kin.linkPose(shapes[k].link) * sc_.robot->links()[shapes[k].link].shapes[shapes[k].index].pose;
      EXPECT_LT((v.shape_poses[k].matrix() - want.matrix()).norm(), 1e-12);
    }
    ASSERT_EQ(v.contacts.size(), s.contacts.size());
    Eigen::Vector3d total = Eigen::Vector3d::Zero();
    for (std::size_t c = 0; c < v.contacts.size(); ++c) {
      EXPECT_EQ(v.contacts[c].supporting, s.contacts[c].spec.supporting);
      // Every sole outline lies on the floor (the contract: within 1 mm).
      for (const auto& p : v.contacts[c].outline) EXPECT_NEAR(p.z(), 0.0, 1e-3);
      EXPECT_EQ(v.contacts[c].outline.size(), sc_.robot->spots()[v.contacts[c].spot].polygon.size());
      EXPECT_EQ(v.contacts[c].forces.size(), s.contacts[c].spec.supporting ? v.contacts[c].points.size() : 0u);
      total += sum(v.contacts[c].forces);
    }
    // The forces drawn (the plan's) hold the robot up: they add up to its weight.
    EXPECT_FALSE(v.forces_from_check);
    EXPECT_NEAR(total.z(), weight, 1e-3 * weight);
    EXPECT_TRUE(v.feasible);
    EXPECT_GE(v.margin, 0.0);
  }
}

// A plan written without forces (the chair fixture) shows the
// independent check's, which hold the robot up too.
TEST(ViewerChair, AStanceWithoutPlanForcesShowsTheChecksForces) {
  const Scenario sc = Scenario::load(sourcePath("models/scenarios/chair_table.yaml"));
  const Plan plan = readPlan(sourcePath("tests/data/viewer_chair.plan.json"), sc);
  const auto stances = stancePostures(sc, plan);
  ASSERT_EQ(stances.size(), plan.stances.size());
  const double weight = sc.robot->totalMass() * kG;
  for (const auto& v : stances) {
    EXPECT_TRUE(v.forces_from_check);
    ASSERT_TRUE(v.feasible);
    Eigen::Vector3d total = Eigen::Vector3d::Zero();
    for (const auto& c : v.contacts) {
      EXPECT_EQ(c.forces.empty(), !c.supporting);
      total += sum(c.forces);
    }
    EXPECT_NEAR(total.z(), weight, 1e-3 * weight);
  }
}

TEST_F(Viewer, FramesAreTheTrajectorysOwnSamplesAtTheDisplayRate) {
  const double fps = 25;
  const auto frames = trajectoryFrames(sc_, tr_, fps);
  const std::size_t expected = static_cast<std::size_t>(std::floor(tr_.duration() * fps + 1e-9)) + 1;
  ASSERT_GE(frames.size(), expected);
  ASSERT_LE(frames.size(), expected + 1);  // the last sample, when the rate does not land on it
  EXPECT_EQ(frames.back().sample, static_cast<int>(tr_.samples.size()) - 1);
  ValidityChecker checker(sc_.robot, sc_.scene);
  const double weight = sc_.robot->totalMass() * kG;
  for (std::size_t k = 0; k < frames.size(); ++k) {
    const ViewPosture& f = frames[k];
    SCOPED_TRACE("frame " + std::to_string(k));
    ASSERT_GE(f.sample, 0);
    const TrajectorySample& s = tr_.samples[f.sample];
    if (k < expected) {
      EXPECT_LE(std::abs(s.t - k / fps), tr_.dt / 2 + 1e-9);  // the nearest sample
    }
    EXPECT_EQ(f.t, s.t);
    EXPECT_TRUE(f.q.joints.isApprox(s.q.joints, 0.0));
    EXPECT_EQ(f.phase, s.phase);
    EXPECT_EQ(f.stance, tr_.phases[s.phase].stance);
    EXPECT_EQ(f.contacts.size(), tr_.phases[s.phase].contacts.size());
    // The forces shown are the independent check's: they balance the weight.
    ASSERT_TRUE(f.feasible);
    Eigen::Vector3d total = Eigen::Vector3d::Zero();
    for (const auto& c : f.contacts) total += sum(c.forces);
    EXPECT_NEAR(total.z(), weight, 1e-3 * weight);
  }
  // Every fifth frame passes the whole validity contract (the viewer shows
  // postures of the pipeline; it must not show an invalid one as if fine).
  for (std::size_t k = 0; k < frames.size(); k += 5)
    EXPECT_TRUE(checker.checkPosture(frames[k].q, tr_.phases[frames[k].phase].contacts).valid()) << "frame " << k;
  EXPECT_THROW(trajectoryFrames(sc_, tr_, 0.0), std::invalid_argument);
}

TEST_F(Viewer, DataFileHoldsEveryStanceFrameShapeAndObstacle) {
  const auto stances = stancePostures(sc_, plan_);
  const auto frames = trajectoryFrames(sc_, tr_, 10);
  const auto j = nlohmann::json::parse(viewDataJson(sc_, plan_, stances, frames, 10, {"s", "p", "t"}));
  EXPECT_EQ(j.at("format"), "acyclic.view/1");
  EXPECT_EQ(j.at("scenario").at("name"), "step_forward");
  const std::size_t n_shapes = viewShapes(*sc_.robot).size();
  EXPECT_EQ(j.at("robot").at("shapes").size(), n_shapes);
  EXPECT_EQ(j.at("obstacles").size(), sc_.scene->obstacles().size());
  ASSERT_EQ(j.at("stances").size(), plan_.stances.size());
  ASSERT_EQ(j.at("frames").size(), frames.size());
  for (std::size_t i = 0; i < plan_.stances.size(); ++i) {
    const auto& s = j.at("stances")[i];
    EXPECT_EQ(s.at("poses").size(), 7 * n_shapes);
    EXPECT_TRUE(s.at("valid").get<bool>()) << "stance " << i;  // the contract, as acyclic-check --plan
    for (std::size_t c = 0; c < plan_.stances[i].contacts.size(); ++c)
      EXPECT_EQ(s.at("contacts")[c].at("supporting").get<bool>(), plan_.stances[i].contacts[c].spec.supporting);
    // Quaternions are unit (x, y, z, w order, as three.js reads them).
    for (std::size_t k = 0; k < n_shapes; ++k) {
      double n2 = 0;
      for (int q = 3; q < 7; ++q) n2 += std::pow(s.at("poses")[7 * k + q].get<double>(), 2);
      EXPECT_NEAR(n2, 1.0, 1e-4);
    }
  }
}

TEST(ViewerPlots, TicksCoverTheRangeAtOneTwoFiveSteps) {
  const auto t = niceTicks(-0.13, 2.71);
  ASSERT_GE(t.size(), 3u);
  EXPECT_LE(t.front(), -0.13);
  EXPECT_GE(t.back(), 2.71);
  EXPECT_NEAR(t[1] - t[0], 1.0, 1e-12);  // 2.84 / 5 rounds up to a step of 1
  EXPECT_NEAR(niceTicks(0, 1.2)[1], 0.5, 1e-12);
  EXPECT_EQ(niceTicks(0, 100, 5)[1], 20);
}

TEST_F(Viewer, FiguresHaveAPanelPerJointWithItsLimitsAndTheMarginAlongTheTrajectory) {
  const PlotFigure angles = jointAnglesFigure(sc_, tr_);
  ASSERT_EQ(static_cast<int>(angles.panels.size()), sc_.robot->numJoints());
  for (int j = 0; j < sc_.robot->numJoints(); ++j) {
    const auto& p = angles.panels[j];
    EXPECT_EQ(p.title, sc_.robot->joints()[j].name);
    ASSERT_EQ(p.lines.size(), 2u);
    EXPECT_NEAR(p.lines[0].y, sc_.robot->joints()[j].upper * 180 / M_PI, 1e-9);
    EXPECT_NEAR(p.lines[1].y, sc_.robot->joints()[j].lower * 180 / M_PI, 1e-9);
    // The curve stays within the limits it is drawn against.
    for (double y : p.series[0].y) EXPECT_TRUE(y >= p.lines[1].y - 1e-6 && y <= p.lines[0].y + 1e-6) << p.title;
    EXPECT_EQ(p.series[0].x.back(), tr_.samples.back().t);
  }
  const PlotFigure vel = jointVelocitiesFigure(sc_, tr_);
  for (const auto& p : vel.panels)
    for (double y : p.series[0].y) EXPECT_LE(std::abs(y), p.lines[0].y + 1e-6) << p.title;
  const auto frames = trajectoryFrames(sc_, tr_, 25);
  const PlotFigure stab = stabilityFigure(sc_, frames);
  ASSERT_EQ(stab.panels.size(), 3u);
  EXPECT_EQ(stab.panels[0].series[0].y.size(), frames.size());
  // The check's forces are inside the Coulomb cone at every frame, and friction is used.
  double worst_cone = 0;
  for (double y : stab.panels[1].series[0].y) {
    EXPECT_LE(y, 1.0 + 1e-9);
    if (std::isfinite(y)) worst_cone = std::max(worst_cone, y);
  }
  EXPECT_GT(worst_cone, 0.0);
  const std::string svg = renderSvg(angles);
  EXPECT_EQ(svg.rfind("<?xml", 0), 0u);
  std::size_t polylines = 0;
  for (std::size_t at = svg.find("<polyline"); at != std::string::npos; at = svg.find("<polyline", at + 1)) ++polylines;
  EXPECT_EQ(static_cast<int>(polylines), sc_.robot->numJoints());
}

TEST_F(Viewer, AcyclicViewRefusesBadInputNamingTheFile) {
  TempDir out;
  const std::string view = binaryPath("processes/acyclic-view");
  const std::string bad = out.write("bad.json", R"({"format": "acyclic.plan/2"})");
  auto r = runProcess(view + " --scenario " + sourcePath(kScenario) + " --plan " + bad + " --out " + out.path() + "/v");
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("bad.json"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("format"), std::string::npos) << r.output;
  r = runProcess(view + " --scenario " + sourcePath(kScenario) + " --plan " + plan_path_ + " --out " + out.path() +
                 "/v --page " + out.path() + "/nowhere");
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_NE(r.output.find("build-viewer"), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(out.path() + "/v/index.html"));
}

// The page in a real browser: it loads the robot, every stance and every
// frame (checked through its own state, window.acyclicViewer) and asks
// nothing of the network.
// The browser tests need Debian's chromium ($CHROMIUM, else /usr/bin/chromium).
std::string chromiumPath() {
  const char* env = std::getenv("CHROMIUM");
  return env ? env : "/usr/bin/chromium";
}
bool haveChromium() { return std::filesystem::exists(chromiumPath()); }
std::string chromiumMissing() {
  return chromiumPath() + " not found: the browser test needs Debian's chromium (scripts/install-deps installs it)";
}

// Opens the page in headless Chromium at `query`, visits every stance, and
// returns snap.mjs's state file (null, with a failure recorded, if it fails).
nlohmann::json browserVisit(const std::string& page, const std::string& query, const std::string& dir) {
  const std::string state_path = dir + "/state.json";
  const auto r = runProcess("node " + sourcePath("viewer/tools/snap.mjs") + " " + page + " --query '" + query +
                            "' --width 480 --height 320 --visit-stances --state " + state_path);
  if (r.status != 0) {
    ADD_FAILURE() << r.output;
    return nullptr;
  }
  return nlohmann::json::parse(readFile(state_path));
}

TEST_F(Viewer, PageInHeadlessChromiumLoadsTheRobotEveryStanceAndFrameOffline) {
  ASSERT_TRUE(haveChromium()) << chromiumMissing();
  TempDir out;
  const std::string page = out.path() + "/page";
  auto r = runProcess(binaryPath("processes/acyclic-view") + " --scenario " + sourcePath(kScenario) + " --plan " +
                      plan_path_ + " --trajectory " + trajectory_path_ + " --out " + page);
  ASSERT_EQ(r.status, 0) << r.output;
  const auto j = browserVisit(page, "t=2.0", out.path());
  ASSERT_FALSE(j.is_null());
  const auto& st = j.at("state");
  EXPECT_TRUE(st.at("loaded").get<bool>());
  EXPECT_TRUE(st.at("error").is_null()) << st.at("error");
  EXPECT_EQ(st.at("scenario"), "step_forward");
  EXPECT_EQ(st.at("stances").get<std::size_t>(), plan_.stances.size());
  EXPECT_EQ(st.at("frames").get<std::size_t>(), trajectoryFrames(sc_, tr_, 25).size());
  EXPECT_EQ(st.at("robotMeshes").get<std::size_t>(), viewShapes(*sc_.robot).size());
  EXPECT_EQ(st.at("current").at("mode"), "frame");
  EXPECT_NEAR(st.at("current").at("t").get<double>(), 2.0, 1e-9);
  EXPECT_TRUE(j.at("remote_requests").empty()) << j.at("remote_requests");
  // Every stance, shown one by one: its contacts (supporting and not) and forces drawn.
  const auto& visits = j.at("visits").at("stances");
  ASSERT_EQ(visits.size(), plan_.stances.size());
  for (std::size_t i = 0; i < visits.size(); ++i) {
    const auto& v = visits[i];
    int supporting = 0;
    for (const auto& c : plan_.stances[i].contacts) supporting += c.spec.supporting;
    EXPECT_EQ(v.at("current").at("stance").get<std::size_t>(), i);
    EXPECT_EQ(v.at("drawn").at("contacts").get<std::size_t>(), plan_.stances[i].contacts.size()) << "stance " << i;
    EXPECT_EQ(v.at("drawn").at("supporting").get<int>(), supporting) << "stance " << i;
    EXPECT_GT(v.at("drawn").at("arrows").get<int>(), 0) << "stance " << i;
    EXPECT_EQ(v.at("drawn").at("com").get<int>(), 1);
  }
  // Play moves the timeline (by wall time; a slow machine moves it less, never not at all).
  const auto& play = j.at("visits").at("play");
  EXPECT_TRUE(play.at("playing").get<bool>());
  EXPECT_EQ(play.at("mode"), "frame");
  EXPECT_GT(play.at("t").get<double>(), 0.0);
  const auto frames = trajectoryFrames(sc_, tr_, 25);
  const auto& fv = j.at("visits").at("frames");
  ASSERT_EQ(fv.size(), frames.size());
  for (std::size_t k = 0; k < fv.size(); ++k) {
    EXPECT_EQ(fv[k].at("current").at("index").get<std::size_t>(), k);
    EXPECT_EQ(fv[k].at("current").at("stance").get<int>(), frames[k].stance);
    EXPECT_EQ(fv[k].at("drawn").at("contacts").get<std::size_t>(), frames[k].contacts.size()) << "frame " << k;
  }
}

// The planner's whole chair plan (tests/data/chair.plan.json, 84 stances) in
// a real browser: the page loads the robot and every stance, each drawn with
// its contacts (supporting ones counted) and forces, offline.
TEST(ViewerChair, TheWholeChairPlanInHeadlessChromium) {
  ASSERT_TRUE(haveChromium()) << chromiumMissing();
  const Scenario sc = Scenario::load(sourcePath("models/scenarios/chair_table.yaml"));
  const Plan plan = readPlan(sourcePath("tests/data/chair.plan.json"), sc);
  TempDir out;
  const std::string page = out.path() + "/page";
  auto r = runProcess(binaryPath("processes/acyclic-view") + " --scenario " +
                      sourcePath("models/scenarios/chair_table.yaml") + " --plan " +
                      sourcePath("tests/data/chair.plan.json") + " --out " + page);
  ASSERT_EQ(r.status, 0) << r.output;
  const auto j = browserVisit(page, "stance=0", out.path());
  ASSERT_FALSE(j.is_null());
  const auto& st = j.at("state");
  EXPECT_TRUE(st.at("loaded").get<bool>());
  EXPECT_TRUE(st.at("error").is_null()) << st.at("error");
  EXPECT_EQ(st.at("scenario"), "chair_table");
  EXPECT_EQ(st.at("stances").get<std::size_t>(), plan.stances.size());
  EXPECT_EQ(st.at("robotMeshes").get<std::size_t>(), viewShapes(*sc.robot).size());
  EXPECT_TRUE(j.at("remote_requests").empty()) << j.at("remote_requests");
  const auto& visits = j.at("visits").at("stances");
  ASSERT_EQ(visits.size(), plan.stances.size());
  for (std::size_t i = 0; i < visits.size(); ++i) {
    int supporting = 0;
    for (const auto& c : plan.stances[i].contacts) supporting += c.spec.supporting;
    EXPECT_EQ(visits[i].at("current").at("stance").get<std::size_t>(), i);
    EXPECT_EQ(visits[i].at("drawn").at("contacts").get<std::size_t>(), plan.stances[i].contacts.size()) << i;
    EXPECT_EQ(visits[i].at("drawn").at("supporting").get<int>(), supporting) << i;
    EXPECT_GT(visits[i].at("drawn").at("arrows").get<int>(), 0) << i;
  }
}

// The picture: a strip of the chair plan (a fixed file, so the picture does
// not move when the planner changes), within a tolerance of the reference
// (software rendering; docs/design.md section 13 says how to remake the reference).
TEST(ViewerChair, StripInHeadlessChromiumMatchesTheReference) {
  ASSERT_TRUE(haveChromium()) << chromiumMissing();
  TempDir out;
  const std::string page = out.path() + "/page";
  auto r = runProcess(binaryPath("processes/acyclic-view") + " --scenario " +
                      sourcePath("models/scenarios/chair_table.yaml") + " --plan " +
                      sourcePath("tests/data/viewer_chair.plan.json") + " --out " + page);
  ASSERT_EQ(r.status, 0) << r.output;
  const std::string png = binaryPath("tests/viewer_chair.png");  // kept: look at it when the test fails
  const std::string state_path = out.path() + "/state.json";
  r = runProcess("node " + sourcePath("viewer/tools/snap.mjs") + " " + page +
                 " --query 'strip=0,1,2,3,4&hud=0' --width 1500 --height 500 --png " + png + " --state " + state_path);
  ASSERT_EQ(r.status, 0) << r.output;
  const auto j = nlohmann::json::parse(readFile(state_path));
  const auto& st = j.at("state");
  EXPECT_TRUE(st.at("loaded").get<bool>());
  EXPECT_EQ(st.at("scenario"), "chair_table");
  EXPECT_EQ(st.at("stances").get<int>(), 5);
  EXPECT_EQ(st.at("frames").get<int>(), 0);
  EXPECT_EQ(st.at("strip"), nlohmann::json::parse("[0, 1, 2, 3, 4]"));
  EXPECT_GT(st.at("robotMeshes").get<int>(), 10);
  EXPECT_EQ(st.at("obstacles").get<int>(), 12);
  r = runProcess("node " + sourcePath("viewer/tools/compare-png.mjs") + " " + png + " " +
                 sourcePath("tests/data/viewer_chair.png") + " --mean 1.5 --pixels 0.005 --diff " +
                 binaryPath("tests/viewer_chair.diff.png"));
  EXPECT_EQ(r.status, 0) << r.output << "(screenshot " << png << ", differences in tests/viewer_chair.diff.png)";
}

}  // namespace
}  // namespace acyclic
