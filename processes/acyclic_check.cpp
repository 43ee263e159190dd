// acyclic-check: checks a scenario's start stance, a plan, or a trajectory
// against the validity contract (docs/design.md section 9) and prints every check
// with its figures. Exit status: 0 valid, 1 a violation, 2 bad input.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <unistd.h>

#include "processes/command_line.h"
#include "planner/check/plan_check.h"
#include "planner/check/trajectory_check.h"
#include "planner/common/format_error.h"
#include "planner/scene/scenario.h"
#include "planner/search/planner_parameters.h"

namespace {

void printParts(const acyclic::ValidityReport& r, const char* indent) {
  for (const auto& p : r.parts) {
    const char* tag = !p.checked ? "skip" : p.ok() ? " ok " : "FAIL";
    std::printf("%s[%s] %-13s %s\n", indent, tag, p.name.c_str(), p.summary.c_str());
    for (const auto& v : p.violations) std::printf("%s       violation: %s\n", indent, v.c_str());
  }
}

std::string describeStance(const acyclic::Scenario& sc, const std::vector<acyclic::ContactSpec>& s) {
  std::string out;
  for (const auto& c : s) out += (out.empty() ? "" : ", ") + sc.describe(c);
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "Checks a scenario's start stance, or a plan, against Acyclic's validity contract (docs/design.md\n"
      "section 9): joint limits, contacts, collisions and quasi-static equilibrium for every posture;\n"
      "for a plan also the sequence (start stance first, goal met last, one contact change per step);\n"
      "for a plan also the forces it reports (on the contacts' corners, inside the Coulomb cone,\n"
      "balancing gravity); for a trajectory every sample with its phase's contacts (held within 1 mm),\n"
      "the joint velocity limits (stored and finite-difference), stored velocities against positions,\n"
      "joint accelerations from positions within the robot's limits, rest where a contact is made or\n"
      "broken (stored velocity and positions). Friction is the worst ||f_t|| / (mu f_n) per stance and sample.\n"
      "Exit status: 0 valid, 1 a violation, 2 bad input."};
  std::string scenario_path, plan_path, trajectory_path;
  bool verbose = false;
  app.add_option("scenario", scenario_path, "scenario file (format acyclic.scenario/1)")->required();
  app.add_option("--plan", plan_path, "plan file (format acyclic.plan/1) to check against the scenario");
  app.add_option("--trajectory", trajectory_path,
                 "trajectory file (format acyclic.trajectory/1) to check against the scenario, sample by sample")
      ->excludes("--plan");
  app.add_flag("-v,--verbose", verbose, "print every check of every stance, not only the failing ones");
  ACYCLIC_PARSE_COMMAND_LINE(app, argc, argv)

  try {
    const acyclic::Scenario sc = acyclic::Scenario::load(scenario_path);
    acyclic::plannerParameters(sc);  // its planner section, read as the planner reads it (bad input: exit 2)
    std::printf("acyclic-check: scenario %s (%s)\n", sc.name.c_str(), scenario_path.c_str());
    std::printf("  robot %s: %d joints, %d links, %zu contact spots, %.2f kg\n", sc.robot->name().c_str(),
                sc.robot->numJoints(), sc.robot->numLinks(), sc.robot->spots().size(), sc.robot->totalMass());
    std::printf("  scene %s: %zu obstacles, %zu contact surfaces\n", sc.scene->path().c_str(),
                sc.scene->obstacles().size(), sc.scene->surfaces().size());
    std::printf("  goal: %s\n", sc.goal.describe(*sc.robot).c_str());
    acyclic::ValidityChecker checker(sc.robot, sc.scene);

    if (!trajectory_path.empty()) {
      const acyclic::Trajectory tr = acyclic::readTrajectory(trajectory_path, sc);
      // Samples are checked for their verdicts, in sequence: the same
      // verdicts, faster (planner/check/validity.h).
      checker.checkVerdictsInSequence();
      std::printf("trajectory %s: %zu samples, %zu phases, %.3f s\n", trajectory_path.c_str(), tr.samples.size(),
                  tr.phases.size(), tr.duration());
      const bool tty = isatty(STDERR_FILENO);
      auto progress = [&](int done, int total) {
        if (tty) std::fprintf(stderr, "\r  checking sample %d of %d ", done, total);
      };
      const acyclic::TrajectoryReport rep = acyclic::checkTrajectory(tr, sc, checker, {}, progress);
      if (tty) std::fprintf(stderr, "\n");
      for (const auto& p : rep.parts) {
        std::printf("  [%s] %-23s %s\n", p.ok() ? " ok " : "FAIL", p.name.c_str(), p.summary.c_str());
        for (const auto& v : p.violations) std::printf("         violation: %s\n", v.c_str());
        if (p.violation_count > static_cast<long>(p.violations.size()))
          std::printf("         ... %ld violations in all\n", p.violation_count);
      }
      std::printf("%s\n", rep.valid() ? "trajectory: valid" : "trajectory: INVALID");
      return rep.valid() ? 0 : 1;
    }

    if (plan_path.empty()) {
      std::printf("start stance: %s\n", describeStance(sc, sc.start_stance).c_str());
      const acyclic::ValidityReport r = checker.checkPosture(sc.start, sc.start_stance);
      printParts(r, "  ");
      std::printf("%s\n", r.valid() ? "start stance: valid" : "start stance: INVALID");
      return r.valid() ? 0 : 1;
    }

    const acyclic::Plan plan = acyclic::readPlan(plan_path, sc);
    std::printf("plan %s: %zu stances\n", plan_path.c_str(), plan.stances.size());
    const acyclic::PlanReport rep = acyclic::checkPlan(plan, sc, checker);
    int bad = 0;
    for (std::size_t i = 0; i < rep.stances.size(); ++i) {
      const bool ok = rep.stances[i].valid();
      bad += !ok;
      if (ok && !verbose) continue;
      std::printf("  stance %zu: %s: %s\n", i, ok ? "valid" : "INVALID",
                  describeStance(sc, plan.stances[i].specs()).c_str());
      printParts(rep.stances[i], "    ");
    }
    std::printf("  [%s] postures      %zu of %zu stances valid (joint limits, contacts, collisions, equilibrium, reported forces)\n",
                bad ? "FAIL" : " ok ", rep.stances.size() - bad, rep.stances.size());
    bool forces_ok = true;
    for (const auto& st : rep.stances)
      for (const auto& p : st.parts) forces_ok = forces_ok && (p.name != "reported forces" || p.ok());
    if (rep.worst_cone_stance >= 0)
      std::printf("  [%s] friction      reported forces: worst ||f_t|| / (mu f_n) %.3f (stance %d; at most 1 in the cone)\n",
                  forces_ok ? " ok " : "FAIL", rep.worst_cone_ratio, rep.worst_cone_stance);
    else
      std::printf("  [skip] friction      the plan reports no contact force\n");
    std::printf("  [%s] sequence      start stance first, goal met last, one contact change per step\n",
                rep.sequence_violations.empty() ? " ok " : "FAIL");
    for (const auto& v : rep.sequence_violations) std::printf("         violation: %s\n", v.c_str());
    std::printf("%s\n", rep.valid() ? "plan: valid" : "plan: INVALID");
    return rep.valid() ? 0 : 1;
  } catch (const acyclic::FormatError& e) {
    std::fprintf(stderr, "acyclic-check: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "acyclic-check: error: %s\n", e.what());
    return 2;
  }
}
