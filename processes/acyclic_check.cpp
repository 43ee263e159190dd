// acyclic-check: checks a scenario's start stance, a plan, or a trajectory
// against the validity contract (docs/design.md section 9) and prints every check
// with its figures. Exit status: 0 valid, 1 a violation, 2 bad input.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cstdio>
#include <unistd.h>

#include "processes/command_line.h"
#include "planner/check/plan_check.h"
#ifdef ACYCLIC_HAVE_HRP2_BRIDGE
#include "hrp2_bridge/stabilizer_schedule.h"
#endif
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

// "12.3 N (2.2% of the weight) toward 180 deg"
std::string describePush(const acyclic::Scenario& sc, const acyclic::PushMargin& p) {
  char buf[128];
  std::snprintf(buf, sizeof buf, "%.1f N (%.1f%% of the weight) toward %.0f deg", p.weakest,
                100 * p.weakest / (sc.robot->totalMass() * 9.81), p.weakest_direction_deg);
  return buf;
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
  bool push = false;
  app.add_flag("--push-margin", push,
               "also print how marginal the start stance or each plan stance is (not part of the contract): the "
               "largest horizontal push at the centre of mass its contacts still hold quasi-statically, in its "
               "weakest of 8 directions (world, degrees from +x toward +y); for a plan the weakest stances")
      ->excludes("--trajectory");
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
      if (push) {
        acyclic::Kinematics kin(sc.robot);
        kin.setConfiguration(sc.start);
        const acyclic::PushMargin pm = acyclic::QuasiStaticChecker(sc.robot, sc.scene).pushMargin(kin, sc.start_stance);
        if (pm.computed) {
          std::printf("  [info] push margin   %s; per direction (0, 45, ... 315 deg):", describePush(sc, pm).c_str());
          for (double f : pm.per_direction) std::printf(" %.0f", f);
          std::printf(" N\n");
        } else {
          std::printf("  [skip] push margin   not in equilibrium\n");
        }
      }
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
    if (push) {
      acyclic::Kinematics kin(sc.robot);
      const acyclic::QuasiStaticChecker statics(sc.robot, sc.scene);
      std::vector<std::pair<std::size_t, acyclic::PushMargin>> margins;  // (stance, its margin)
      std::size_t skipped = 0;  // stances that fail the contract, or out of equilibrium
      for (std::size_t i = 0; i < plan.stances.size(); ++i) {
        kin.setConfiguration(plan.stances[i].configuration);
        const acyclic::PushMargin pm = statics.pushMargin(kin, plan.stances[i].specs());
        if (!pm.computed || !rep.stances[i].valid()) {
          ++skipped;
          continue;
        }
        margins.push_back({i, pm});
        if (verbose) std::printf("  stance %zu: push margin %s\n", i, describePush(sc, pm).c_str());
      }
      std::stable_sort(margins.begin(), margins.end(),
                       [](const auto& a, const auto& b) { return a.second.weakest < b.second.weakest; });
      // Where HRP-2's bridge runs its stabilizer (only coplanar feet touch)
      // feedback holds a small margin; elsewhere the robot plays its
      // references open-loop, and the margin is all there is. Per stance:
      // the bridge also switches the stabilizer off a little before a
      // contact that is not a coplanar sole is made, and on a little after.
      std::vector<std::pair<std::string, std::vector<const std::pair<std::size_t, acyclic::PushMargin>*>>> groups;
#ifdef ACYCLIC_HAVE_HRP2_BRIDGE
      const double tol = acyclic::hrp2::BridgeConfig{}.coplanar_tolerance;
      for (const bool open_loop : {true, false}) {
        groups.push_back({open_loop ? "played open-loop (a contact other than coplanar soles)"
                                    : "on coplanar soles alone (where HRP-2's bridge runs its stabilizer)",
                          {}});
        for (const auto& m : margins)
          if (acyclic::hrp2::onlyCoplanarFeet(plan.stances[m.first].specs(), *sc.robot, *sc.scene, tol) != open_loop)
            groups.back().second.push_back(&m);
      }
#else
      groups.push_back({"valid", {}});
      for (const auto& m : margins) groups.back().second.push_back(&m);
#endif
      for (const auto& [label, group] : groups) {
        std::printf("  [info] push margin   %zu stances %s", group.size(), label.c_str());
        for (std::size_t k = 0; k < std::min<std::size_t>(3, group.size()); ++k)
          std::printf("%s stance %zu %s", k ? ";" : "; the weakest:", group[k]->first,
                      describePush(sc, group[k]->second).c_str());
        if (!group.empty()) std::printf("; median %.1f N", group[group.size() / 2]->second.weakest);
        std::printf("\n");
      }
      if (skipped) std::printf("  [info] push margin   %zu stances left out (invalid, or out of equilibrium)\n", skipped);
    }
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
