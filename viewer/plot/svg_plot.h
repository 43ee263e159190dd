#pragma once
// Line plots as SVG text, written directly (no dependency): a figure is a grid
// of panels, each with its series and horizontal reference lines (limits).
#include <string>
#include <vector>

namespace acyclic {

struct PlotSeries {
  std::string name;
  std::vector<double> x, y;     // same length
  std::string color = "#1f5fa8";
  bool dashed = false;
  bool steps = false;           // drawn as a staircase (a count over time)
};

struct PlotLine {               // horizontal reference line, e.g. a joint limit
  double y = 0;
  std::string label;
  std::string color = "#c0392b";
};

struct PlotPanel {
  std::string title, xlabel, ylabel;
  std::vector<PlotSeries> series;
  std::vector<PlotLine> lines;
};

struct PlotFigure {
  std::string title;
  int columns = 1;
  double panel_width = 360, panel_height = 200;  // px, each panel
  std::vector<PlotPanel> panels;
};

// Tick positions covering [lo, hi] at a 1-2-5 step, about `target` of them.
std::vector<double> niceTicks(double lo, double hi, int target = 5);

std::string renderSvg(const PlotFigure& fig);
// Writes beside and renames; std::runtime_error naming the file when it cannot.
void writeSvg(const PlotFigure& fig, const std::string& path);

}  // namespace acyclic
