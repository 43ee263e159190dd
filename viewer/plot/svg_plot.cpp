#include "viewer/plot/svg_plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace acyclic {
namespace {

std::string esc(const std::string& s) {
  std::string o;
  for (char c : s) {
    if (c == '<') o += "&lt;";
    else if (c == '>') o += "&gt;";
    else if (c == '&') o += "&amp;";
    else if (c == '"') o += "&quot;";
    else o += c;
  }
  return o;
}

std::string num(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.1f", v);
  return b;
}

std::string tickLabel(double v, double step) {
  char b[32];
  const int decimals = std::max(0, static_cast<int>(std::ceil(-std::log10(step) - 1e-9)));
  std::snprintf(b, sizeof b, "%.*f", std::min(decimals, 6), std::abs(v) < step * 1e-6 ? 0.0 : v);
  return b;
}

struct Range {
  double lo = std::numeric_limits<double>::infinity(), hi = -std::numeric_limits<double>::infinity();
  void add(double v) {
    if (std::isfinite(v)) lo = std::min(lo, v), hi = std::max(hi, v);
  }
  void finish() {
    if (!(lo <= hi)) lo = 0, hi = 1;
    if (hi - lo < 1e-12) {
      const double pad = std::max(std::abs(lo) * 0.1, 1e-3);
      lo -= pad, hi += pad;
    }
  }
};

void panelSvg(std::ostringstream& o, const PlotPanel& p, double ox, double oy, double w, double h) {
  // Plot area inside the panel, leaving room for labels.
  const double left = ox + 56, right = ox + w - 10, top = oy + 22, bottom = oy + h - 34;
  Range xr, yr;
  for (const auto& s : p.series) {
    for (double v : s.x) xr.add(v);
    for (double v : s.y) yr.add(v);
  }
  for (const auto& l : p.lines) yr.add(l.y);
  xr.finish();
  yr.finish();
  // x spans the data exactly (time axes); y is widened to its outer ticks.
  std::vector<double> xt;
  for (double v : niceTicks(xr.lo, xr.hi))
    if (v >= xr.lo - 1e-9 * (xr.hi - xr.lo) && v <= xr.hi + 1e-9 * (xr.hi - xr.lo)) xt.push_back(v);
  const auto yt = niceTicks(yr.lo, yr.hi);
  const double x0 = xr.lo, x1 = xr.hi;
  const double y0 = std::min(yr.lo, yt.front()), y1 = std::max(yr.hi, yt.back());
  auto X = [&](double v) { return left + (v - x0) / (x1 - x0) * (right - left); };
  auto Y = [&](double v) { return bottom - (v - y0) / (y1 - y0) * (bottom - top); };
  o << "<text x='" << num(ox + w / 2) << "' y='" << num(oy + 14) << "' text-anchor='middle' font-size='12' font-weight='bold'>"
    << esc(p.title) << "</text>\n";
  o << "<rect x='" << num(left) << "' y='" << num(top) << "' width='" << num(right - left) << "' height='" << num(bottom - top)
    << "' fill='white' stroke='#888'/>\n";
  const double xstep = xt.size() > 1 ? xt[1] - xt[0] : (x1 - x0), ystep = yt.size() > 1 ? yt[1] - yt[0] : 1;
  for (double v : xt) {
    o << "<line x1='" << num(X(v)) << "' x2='" << num(X(v)) << "' y1='" << num(top) << "' y2='" << num(bottom)
      << "' stroke='#eee'/><text x='" << num(X(v)) << "' y='" << num(bottom + 12)
      << "' text-anchor='middle' font-size='9'>" << tickLabel(v, xstep) << "</text>\n";
  }
  for (double v : yt) {
    o << "<line x1='" << num(left) << "' x2='" << num(right) << "' y1='" << num(Y(v)) << "' y2='" << num(Y(v))
      << "' stroke='#eee'/><text x='" << num(left - 4) << "' y='" << num(Y(v) + 3)
      << "' text-anchor='end' font-size='9'>" << tickLabel(v, ystep) << "</text>\n";
  }
  o << "<text x='" << num((left + right) / 2) << "' y='" << num(bottom + 26) << "' text-anchor='middle' font-size='10'>"
    << esc(p.xlabel) << "</text>\n";
  o << "<text transform='translate(" << num(ox + 12) << "," << num((top + bottom) / 2)
    << ") rotate(-90)' text-anchor='middle' font-size='10'>" << esc(p.ylabel) << "</text>\n";
  for (const auto& l : p.lines) {
    o << "<line x1='" << num(left) << "' x2='" << num(right) << "' y1='" << num(Y(l.y)) << "' y2='" << num(Y(l.y))
      << "' stroke='" << l.color << "' stroke-dasharray='4 3'/>";
    if (!l.label.empty())
      o << "<text x='" << num(right - 2) << "' y='" << num(Y(l.y) - 2) << "' text-anchor='end' font-size='8' fill='"
        << l.color << "'>" << esc(l.label) << "</text>";
    o << "\n";
  }
  double legend_y = top + 10;
  for (const auto& s : p.series) {
    o << "<polyline fill='none' stroke='" << s.color << "' stroke-width='1.3'"
      << (s.dashed ? " stroke-dasharray='5 3'" : "") << " points='";
    for (std::size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
      if (!std::isfinite(s.y[i])) continue;
      if (s.steps && i > 0) o << num(X(s.x[i])) << "," << num(Y(s.y[i - 1])) << " ";
      o << num(X(s.x[i])) << "," << num(Y(s.y[i])) << " ";
    }
    o << "'/>\n";
    if (p.series.size() > 1 && !s.name.empty()) {
      o << "<text x='" << num(left + 6) << "' y='" << num(legend_y) << "' font-size='9' fill='" << s.color << "'>"
        << esc(s.name) << "</text>\n";
      legend_y += 11;
    }
  }
}

}  // namespace

std::vector<double> niceTicks(double lo, double hi, int target) {
  if (!(hi > lo)) return {lo};
  const double raw = (hi - lo) / std::max(1, target);
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  double step = mag;
  for (double m : {1.0, 2.0, 5.0, 10.0})
    if (m * mag >= raw) {
      step = m * mag;
      break;
    }
  std::vector<double> t;
  for (double v = std::floor(lo / step) * step; v <= std::ceil(hi / step) * step + step * 1e-9; v += step)
    t.push_back(std::abs(v) < step * 1e-9 ? 0.0 : v);
  return t;
}

std::string renderSvg(const PlotFigure& fig) {
  const int cols = std::max(1, fig.columns);
  const int rows = static_cast<int>((fig.panels.size() + cols - 1) / cols);
  const double head = fig.title.empty() ? 0 : 28;
  const double W = cols * fig.panel_width, H = head + rows * fig.panel_height;
  std::ostringstream o;
  o << "<?xml version='1.0' encoding='UTF-8'?>\n<svg xmlns='http://www.w3.org/2000/svg' width='" << num(W)
    << "' height='" << num(H) << "' viewBox='0 0 " << num(W) << " " << num(H)
    << "' font-family='DejaVu Sans, Arial, sans-serif'>\n<rect width='100%' height='100%' fill='#fafafa'/>\n";
  if (!fig.title.empty())
    o << "<text x='" << num(W / 2) << "' y='19' text-anchor='middle' font-size='15' font-weight='bold'>" << esc(fig.title)
      << "</text>\n";
  for (std::size_t i = 0; i < fig.panels.size(); ++i)
    panelSvg(o, fig.panels[i], (i % cols) * fig.panel_width, head + (i / cols) * fig.panel_height, fig.panel_width,
             fig.panel_height);
  o << "</svg>\n";
  return o.str();
}

void writeSvg(const PlotFigure& fig, const std::string& path) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream f(tmp);
    if (!f) throw std::runtime_error(path + ": cannot write");
    f << renderSvg(fig);
    if (!f.flush()) throw std::runtime_error(path + ": cannot write");
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) throw std::runtime_error(path + ": cannot rename " + tmp + " onto it");
}

}  // namespace acyclic
