#include "viewer/plot/figures.h"

#include <algorithm>
#include <cmath>

namespace acyclic {
namespace {

constexpr double kDeg = 180.0 / M_PI;

// At most about 600 points per series: a screen-sized plot shows no more.
int stride(std::size_t n) { return std::max<int>(1, static_cast<int>(n / 600)); }

PlotFigure jointFigure(const Scenario& sc, const Trajectory& tr, bool velocity) {
  const RobotModel& m = *sc.robot;
  PlotFigure fig;
  fig.title = sc.name + (velocity ? ": joint velocities (deg/s) and their limits" : ": joint angles (deg) and their limits");
  fig.columns = 5;
  fig.panel_width = 300;
  fig.panel_height = 170;
  const int step = stride(tr.samples.size());
  for (int j = 0; j < m.numJoints(); ++j) {
    const JointInfo& J = m.joints()[j];
    PlotPanel p;
    p.title = J.name;
    p.xlabel = "t (s)";
    p.ylabel = velocity ? "deg/s" : "deg";
    PlotSeries s;
    s.name = J.name;
    for (std::size_t i = 0; i < tr.samples.size(); i += step) {
      const auto& smp = tr.samples[i];
      s.x.push_back(smp.t);
      s.y.push_back(kDeg * (velocity ? (smp.dq.size() > j ? smp.dq[j] : NAN) : smp.q.joints[j]));
    }
    if (!tr.samples.empty() && (tr.samples.size() - 1) % step != 0) {  // the last sample too
      const auto& smp = tr.samples.back();
      s.x.push_back(smp.t);
      s.y.push_back(kDeg * (velocity ? (smp.dq.size() > j ? smp.dq[j] : NAN) : smp.q.joints[j]));
    }
    p.series.push_back(std::move(s));
    if (velocity) {
      p.lines.push_back({kDeg * J.velocity, "limit"});
      p.lines.push_back({-kDeg * J.velocity, "-limit"});
    } else {
      p.lines.push_back({kDeg * J.upper, "upper"});
      p.lines.push_back({kDeg * J.lower, "lower"});
    }
    fig.panels.push_back(std::move(p));
  }
  return fig;
}

}  // namespace

PlotFigure jointAnglesFigure(const Scenario& sc, const Trajectory& tr) { return jointFigure(sc, tr, false); }
PlotFigure jointVelocitiesFigure(const Scenario& sc, const Trajectory& tr) { return jointFigure(sc, tr, true); }

PlotFigure stabilityFigure(const Scenario& sc, const std::vector<ViewPosture>& frames) {
  PlotFigure fig;
  fig.title = sc.name + ": stability along the trajectory (independent quasi-static check)";
  fig.panel_width = 760;
  fig.panel_height = 220;
  PlotPanel margin{"friction margin: least slack of a corner force to its friction pyramid's facets (LP 1)", "t (s)",
                   "N", {}, {}};
  PlotPanel cone{"worst ||f_t|| / (mu f_n) of the corner forces (LP 2): at most 1 inside the Coulomb cone", "t (s)",
                 "ratio", {}, {}};
  PlotPanel torque{"worst joint torque / its limit (LP 2)", "t (s)", "ratio", {}, {}};
  PlotSeries m{"margin", {}, {}, "#1f5fa8"}, c{"cone ratio", {}, {}, "#16a085"}, r{"torque ratio", {}, {}, "#8e44ad"};
  for (const auto& f : frames) {
    m.x.push_back(f.t);
    m.y.push_back(f.feasible ? f.margin : NAN);  // an infeasible frame leaves a gap
    c.x.push_back(f.t);
    c.y.push_back(f.feasible ? f.worst_cone_ratio : NAN);
    r.x.push_back(f.t);
    r.y.push_back(f.feasible ? f.worst_torque_ratio : NAN);
  }
  margin.series.push_back(std::move(m));
  margin.lines.push_back({0.0, "no margin", "#c0392b"});
  cone.series.push_back(std::move(c));
  cone.lines.push_back({1.0, "the cone", "#c0392b"});
  torque.series.push_back(std::move(r));
  torque.lines.push_back({1.0, "limit", "#c0392b"});
  fig.panels = {std::move(margin), std::move(cone), std::move(torque)};
  return fig;
}

PlotFigure plannerProgressFigure(const std::string& title, const std::vector<PlannerProgressPoint>& points) {
  PlotFigure fig;
  fig.title = title;
  fig.panel_width = 760;
  fig.panel_height = 220;
  PlotPanel pot{"best potential f_T", "elapsed (s)", "f_T", {}, {}};
  PlotPanel tree{"tree size", "elapsed (s)", "count", {}, {}};
  PlotSeries f{"best f_T", {}, {}, "#1f5fa8"};
  PlotSeries n{"nodes generated", {}, {}, "#27ae60"}, c{"posture calls", {}, {}, "#e67e22"};
  n.steps = c.steps = f.steps = true;
  for (const auto& p : points) {
    f.x.push_back(p.elapsed_s);
    f.y.push_back(std::isfinite(p.best_potential) ? p.best_potential : NAN);
    n.x.push_back(p.elapsed_s);
    n.y.push_back(static_cast<double>(p.nodes_generated));
    c.x.push_back(p.elapsed_s);
    c.y.push_back(static_cast<double>(p.posture_calls));
  }
  pot.series.push_back(std::move(f));
  tree.series.push_back(std::move(n));
  tree.series.push_back(std::move(c));
  fig.panels = {std::move(pot), std::move(tree)};
  return fig;
}

}  // namespace acyclic
