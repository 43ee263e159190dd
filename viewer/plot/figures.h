#pragma once
// The figures people look at: joint angles and velocities over a
// trajectory with their limits, the stability margin along it (the
// independent quasi-static check), and the planner's progress over time.
#include <vector>

#include "planner/plan/trajectory.h"
#include "viewer/export/view_data.h"
#include "viewer/plot/svg_plot.h"

namespace acyclic {

// One panel per joint: its angle (deg) over time, with its limits.
PlotFigure jointAnglesFigure(const Scenario& sc, const Trajectory& tr);
// One panel per joint: its velocity (deg/s) over time, with +-its limit.
PlotFigure jointVelocitiesFigure(const Scenario& sc, const Trajectory& tr);
// The friction margin (N, LP 1) and the worst torque ratio (LP 2) of the
// independent check at each frame; phase boundaries are visible as steps.
PlotFigure stabilityFigure(const Scenario& sc, const std::vector<ViewPosture>& frames);

struct PlannerProgressPoint {
  double elapsed_s = 0;
  long nodes_generated = 0;
  long posture_calls = 0;
  double best_potential = 0;
};
// Best potential f_T and tree size (nodes generated, posture calls) over time.
PlotFigure plannerProgressFigure(const std::string& title, const std::vector<PlannerProgressPoint>& points);

}  // namespace acyclic
