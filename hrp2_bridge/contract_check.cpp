#include "hrp2_bridge/contract_check.h"

#include "planner/check/trajectory_check.h"

namespace acyclic::hrp2 {

CheckResult checkContract(const Trajectory& tr, const Scenario& sc, const std::function<void(int, int)>& progress) {
  ValidityChecker checker(sc.robot, sc.scene);
  checker.checkVerdictsInSequence();  // verdicts only, sample after sample (planner/check/validity.h)
  checker.setForcesReused(true);      // and most of their equilibrium LPs skipped (the same verdicts)
  TrajectoryCheckOptions opt;
  opt.max_violations = 1;
  const TrajectoryReport rep = acyclic::checkTrajectory(tr, sc, checker, opt, progress);
  if (rep.valid()) return {};
  for (const TrajectoryCheckPart& p : rep.parts)
    if (!p.ok())
      return CheckResult::failure("validity contract: " + p.name + ": " + std::to_string(p.violation_count) +
                                  " violation(s), first: " + (p.violations.empty() ? p.summary : p.violations.front()));
  return CheckResult::failure("validity contract violated");
}

PrepareResult prepareChecked(const Trajectory& tr, const Scenario& sc, const BridgeConfig& config,
                             const PrepareOptions& options, const std::function<void(int, int)>& progress) {
  PrepareResult r = prepareTrajectory(tr, sc.robot, sc.scene, config, options);
  if (r.check.ok && config.check_contract) {
    CheckResult c = checkContract(tr, sc, progress);
    if (!c.ok) r = PrepareResult{std::move(c), {}};
  }
  return r;
}

}  // namespace acyclic::hrp2
