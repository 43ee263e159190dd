#pragma once
// The scenario a plan, guide or trajectory file names (its "scenario" field):
// one rule for every tool that loads such a file without --scenario
// (acyclic-interpolator, acyclic-hrp2-bridge, acyclic-hrp2-sim,
// acyclic-hrp2-export, acyclic-simulate, bench_interpolator), so that a file
// opens the same scenario whichever tool reads it.
//
// The rule, in order:
//   1. an absolute path: as it is;
//   2. a relative path beside the file (in the file's folder): the tools
//      write the field relative to where they ran, and a file moved together
//      with its scenario still finds it;
//   3. else the relative path from the current directory (a file written in
//      the source tree and read from there, e.g. "models/scenarios/x.yaml").
// Neither found: FormatError naming the file and the field.
#include <string>

namespace acyclic {

// `named` as written in `file_path`'s scenario field, resolved by the rule above.
std::string resolveScenarioReference(const std::string& file_path, const std::string& named);

// Reads `file_path`'s "scenario" field (FormatError: unreadable, not JSON, no
// such string field) and resolves it by the rule above.
std::string scenarioNamedBy(const std::string& file_path);

}  // namespace acyclic
