// acyclic-check: checks a scenario's start stance against the validity
// contract (DESIGN.md section 9) and prints every check with its figures.
// Exit status: 0 valid, 1 a violation, 2 bad input.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <iostream>

#include "planner/check/validity.h"
#include "planner/common/format_error.h"
#include "planner/scene/scenario.h"

namespace {

int printReport(const acyclic::ValidityReport& r) {
  for (const auto& p : r.parts) {
    const char* tag = !p.checked ? "skip" : p.ok() ? " ok " : "FAIL";
    std::printf("  [%s] %-13s %s\n", tag, p.name.c_str(), p.summary.c_str());
    for (const auto& v : p.violations) std::printf("         violation: %s\n", v.c_str());
  }
  return r.valid() ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "Checks a scenario's start stance against Acyclic's validity contract (DESIGN.md section 9):\n"
      "joint limits, contacts, collisions, quasi-static equilibrium.\n"
      "Exit status: 0 valid, 1 a violation, 2 bad input."};
  std::string scenario_path;
  app.add_option("scenario", scenario_path, "scenario file (format acyclic.scenario/1)")->required();
  CLI11_PARSE(app, argc, argv);

  try {
    const acyclic::Scenario sc = acyclic::Scenario::load(scenario_path);
    std::printf("acyclic-check: scenario %s (%s)\n", sc.name.c_str(), scenario_path.c_str());
    std::printf("  robot %s: %d joints, %d links, %zu contact spots, %.2f kg\n", sc.robot->name().c_str(),
                sc.robot->numJoints(), sc.robot->numLinks(), sc.robot->spots().size(), sc.robot->totalMass());
    std::printf("  scene %s: %zu obstacles, %zu contact surfaces\n", sc.scene->path().c_str(),
                sc.scene->obstacles().size(), sc.scene->surfaces().size());
    std::printf("start stance:");
    for (const auto& c : sc.start_stance) std::printf(" %s", sc.describe(c).c_str());
    std::printf("\n");
    acyclic::ValidityChecker checker(sc.robot, sc.scene);
    const int status = printReport(checker.checkPosture(sc.start, sc.start_stance));
    std::printf("%s\n", status == 0 ? "start stance: valid" : "start stance: INVALID");
    return status;
  } catch (const acyclic::FormatError& e) {
    std::fprintf(stderr, "acyclic-check: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "acyclic-check: error: %s\n", e.what());
    return 2;
  }
}
