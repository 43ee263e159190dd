#pragma once
// A rough trajectory (the guide of the contact planner, paper 2.7) and its
// file format, acyclic.guide/1 (JSON): a few key postures from the start
// posture to the goal region, hand-written or authored by OMPL.
#include <string>
#include <vector>

#include "planner/scene/scenario.h"

namespace acyclic {

struct Guide {
  std::string scenario;                  // the scenario file it was made for (as given)
  std::string source;                    // "ompl" or "hand"
  std::vector<Configuration> key_postures;
  double seconds = 0;                    // wall time spent making it
};

void writeGuide(const Guide& g, const Scenario& sc, const std::string& path);  // atomic (beside, then rename)
std::string guideToJson(const Guide& g, const Scenario& sc);
// FormatError naming the file and field on bad input (fewer than two key postures included).
Guide readGuide(const std::string& path, const Scenario& sc);
Guide guideFromJson(const std::string& text, const std::string& origin, const Scenario& sc);

}  // namespace acyclic
