// acyclic-simulate: executes a trajectory in a dynamics simulation (Simbody
// multibody dynamics, free base, PD-servoed joints, compliant contact;
// hrp2_bridge/sim/dynamics_simulation.h) and reports per phase base drift
// and tilt, each contact's slip, lift-off and force against the plan's,
// tracking error, and the verdict.
// Exit status: 0 executed, 1 fell or slipped, 2 bad input.
#include <CLI/CLI.hpp>

#include <cmath>
#include <cstdio>
#include <memory>
#include <unistd.h>

#include "hrp2_bridge/sim/dynamics_simulation.h"
#include "hrp2_bridge/sim/held_start.h"
#include "hrp2_bridge/stabilizer_schedule.h"
#include "hrp2_bridge/trajectory_file.h"
#include "processes/command_line.h"

int main(int argc, char** argv) {
  using namespace acyclic;
  CLI::App app{
      "Executes a trajectory in a dynamics simulation (Simbody multibody dynamics, not kinematics): the\n"
      "base is free, each joint a PD servo toward the trajectory's q with its dq as feed-forward (gains from\n"
      "the effort limits, torque clamped to them), contacts compliant Hunt-Crossley spheres at the contact\n"
      "spots' polygon corners against the scene's surfaces with their friction, and the links' collision\n"
      "shapes against the surfaces they come near (a contact the plan does not make, reported). Prints per\n"
      "phase the base\n"
      "drift and tilt against the plan, each contact's slip, lift-off and force against the quasi-static\n"
      "plan's, the worst joint tracking error, and the verdict (executed / fell / slipped, time, reason).\n"
      "Where HRP-2's bridge runs its stabilizer (only coplanar feet touch), a model of it corrects the legs'\n"
      "references from the measured foot forces and centre of mass (--no-stabilizer: open-loop throughout).\n"
      "Progress on stderr when it is a terminal.\n"
      "Exit status: 0 executed, 1 fell or slipped, 2 bad input."};
  std::string scenario_path, trajectory_path, report_path;
  hrp2::DynamicsOptions o;
  bool quiet = false;
  app.add_option("scenario", scenario_path, "scenario file (format acyclic.scenario/1)")->required();
  double hold_start = 0;
  auto* trajectory_opt = app.add_option("--trajectory", trajectory_path, "trajectory file (format acyclic.trajectory/1)");
  auto* hold_opt = app.add_option("--hold-start", hold_start,
                                  "instead of a trajectory, hold the scenario's start posture and stance this long, s: "
                                  "does the start itself stand (or sit) on compliant contacts before a plan moves it?")
                       ->check(CLI::PositiveNumber);
  trajectory_opt->excludes(hold_opt);  // CLI11: both ways

  app.add_option("--report", report_path, "write the report as JSON (format acyclic.simulation/1) to this file")
      ->check(acyclic::proc::InWritableDirectory());
  app.add_option("--slip-bound", o.slip_bound, "a supporting contact slipping more over its phase: slipped, m (default 0.01)");
  app.add_option("--base-bound", o.base_bound, "acceptance: base within this of the plan, m (default 0.02)");
  app.add_option("--settle", o.settle, "hold the last reference this long after the end, s (default 0.5)");
  app.add_option("--accuracy", o.accuracy, "integrator accuracy, relative local error (default 1e-3)");
  app.add_option("--integrator", o.integrator, "cpodes (default; implicit BDF), semi-explicit-euler2, rk-merson or rk3");
  app.add_option("--full-torque-error", o.full_torque_error,
                 "servo stiffness: a joint's whole effort limit at this error, rad (default 0.01)");
  app.add_option("--transition-velocity", o.transition_velocity,
                 "friction's stiction regularization velocity, m/s (default 0.001)");
  std::string trace_path;
  app.add_option("--trace", trace_path,
                 "write one CSV row per controller period: time, phase, stabilizer flag, centre of mass and base "
                 "(simulated and planned, world, m), tilt (rad) and as a world rotation vector (its x, y the lean, its z the yaw), "
                 "each spot's vertical force (world z, N), the contact wrenches' ZMP and the stabilizer's wanted one "
                 "(world x-y, m; nan without load or stabilizer), each sole's turn by the stabilizer (rad)")
      ->check(acyclic::proc::InWritableDirectory());
  bool open_loop = false;
  app.add_flag("--no-stabilizer", open_loop,
               "play every phase open-loop: no model of HRP-2's stabilizer, even where the bridge runs it (only coplanar feet touch)");
  app.add_option("--stabilizer-cop-gain", o.stabilizer_options.cop_gain,
                 "stabilizer: a foot's turn rate per metre of centre-of-pressure error, rad/s/m (default 5)");
  app.add_option("--stabilizer-force-damping", o.stabilizer_options.force_damping,
                 "stabilizer: a foot rises at (measured - wanted normal force) / this, N s/m (default 2e4)");
  app.add_option("--stabilizer-off-time", o.stabilizer_options.off_time,
                 "stabilizer: switched off, its offsets fade out with this time constant, s (default 0.3)");
  bool no_body = false;
  app.add_flag("--no-body-contacts", no_body,
               "only the contact spots touch the scene: no collision shape of a link meets a surface (as before "
               "2026-12-07; a seated robot that tips back does not land on its waist)");
  app.add_option("--body-contact-range", o.body_contact_range,
                 "a link's collision shapes meet a surface they come within this of somewhere along the trajectory, "
                 "m (default 0.02)");
  app.add_flag("-q,--quiet", quiet, "print only the verdict");
  ACYCLIC_PARSE_COMMAND_LINE(app, argc, argv)

  o.stabilizer = !open_loop;
  o.body_contacts = !no_body;
  hrp2::LoadedTrajectory loaded;
  try {
    o.validate();
    if (!*hold_opt && !*trajectory_opt) throw std::invalid_argument("give --trajectory FILE or --hold-start SECONDS");
    if (*hold_opt) {
      loaded.scenario = Scenario::load(scenario_path);
      loaded.trajectory = hrp2::heldStart(loaded.scenario, hold_start);
      char label[64];
      std::snprintf(label, sizeof label, "the start held %g s", hold_start);
      trajectory_path = label;
    } else {
      loaded = hrp2::loadTrajectoryFile(trajectory_path, scenario_path);
    }
    if (loaded.trajectory.samples.size() < 2) throw std::invalid_argument(trajectory_path + ": field 'samples': at least two samples");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "acyclic-simulate: %s\n", e.what());
    return 2;
  }
  const Scenario& sc = loaded.scenario;
  const Trajectory& tr = loaded.trajectory;
  const bool tty = isatty(fileno(stderr));
  hrp2::SimulationProgress progress;
  if (tty)
    progress = [](double t, double total) {
      std::fprintf(stderr, "\r  simulated %6.2f / %.2f s", t, total);
      if (t >= total - 1e-9) std::fprintf(stderr, "\n");
      std::fflush(stderr);
    };
  hrp2::SimulationReport r;
  try {
    std::unique_ptr<std::FILE, int (*)(std::FILE*)> trace_file(nullptr, &std::fclose);
    hrp2::SimulationTrace trace;
    if (!trace_path.empty()) {
      trace_file.reset(std::fopen(trace_path.c_str(), "w"));
      if (!trace_file) {
        std::fprintf(stderr, "acyclic-simulate: cannot write the trace %s\n", trace_path.c_str());
        return 2;
      }
      std::fprintf(trace_file.get(), "t,phase,stabilizer,com_x,com_y,com_z,plan_com_x,plan_com_y,plan_com_z,"
                                     "base_x,base_y,base_z,plan_base_x,plan_base_y,plan_base_z,tilt,tilt_x,tilt_y,tilt_z");
      for (const auto& s : sc.robot->spots()) std::fprintf(trace_file.get(), ",%s_fz", s.name.c_str());
      std::fprintf(trace_file.get(), ",zmp_x,zmp_y,wanted_zmp_x,wanted_zmp_y");
      for (int s = 0; s < static_cast<int>(sc.robot->spots().size()); ++s)
        if (hrp2::isFootSpot(*sc.robot, s))
          std::fprintf(trace_file.get(), ",%s_turn_x,%s_turn_y", sc.robot->spots()[s].name.c_str(),
                       sc.robot->spots()[s].name.c_str());
      std::fprintf(trace_file.get(), "\n");
      trace = [f = trace_file.get()](const hrp2::SimulationSample& s) {
        std::fprintf(f, "%.3f,%d,%d", s.t, s.phase, s.stabilizer_on ? 1 : 0);
        for (const Eigen::Vector3d* v : {&s.com, &s.plan_com, &s.base, &s.plan_base})
          std::fprintf(f, ",%.5f,%.5f,%.5f", v->x(), v->y(), v->z());
        std::fprintf(f, ",%.5f,%.5f,%.5f,%.5f", s.tilt, s.tilt_vector.x(), s.tilt_vector.y(), s.tilt_vector.z());
        for (const auto& fs : s.spot_forces) std::fprintf(f, ",%.1f", fs.z());
        std::fprintf(f, ",%.5f,%.5f,%.5f,%.5f", s.zmp.x(), s.zmp.y(), s.wanted_zmp.x(), s.wanted_zmp.y());
        for (const Eigen::Vector2d& a : s.foot_tilts) std::fprintf(f, ",%.5f,%.5f", a.x(), a.y());
        std::fprintf(f, "\n");
      };
    }
    r = hrp2::simulate(sc, tr, o, progress, trace);
  } catch (const std::exception& e) {
    if (tty) std::fprintf(stderr, "\n");
    std::fprintf(stderr, "acyclic-simulate: the simulation failed: %s\n", e.what());
    return 2;
  }
  if (tty) std::fprintf(stderr, "\n");
  if (!quiet) {
    std::printf("acyclic-simulate: %s, %zu samples (%.2f s), %zu phases\n", trajectory_path.c_str(), tr.samples.size(),
                tr.duration(), tr.phases.size());
    for (const auto& p : r.phases) {
      std::printf("phase %d [%.2f, %.2f] s: base drift %.1f mm (end %.1f), tilt %.2f deg, tracking %.2f deg (%s)\n",
                  p.phase, p.t_start, p.t_end, 1e3 * p.base_drift, 1e3 * p.base_drift_end, p.tilt * 180 / M_PI,
                  p.tracking * 180 / M_PI, p.tracking_joint.c_str());
      for (const auto& c : p.contacts) {
        std::printf("  %-10s @ %-12s %-10s slip %5.1f mm, lift %5.1f mm, unloaded %.2f s%s, force (%.0f %.0f %.0f) N",
                    c.spot.c_str(), c.surface.c_str(), c.supporting ? "supporting" : "touching", 1e3 * c.slip,
                    1e3 * c.lift, c.unloaded_time, c.never_loaded ? ", NEVER LOADED" : c.left_surface ? ", LEFT THE SURFACE" : "", c.force.x(),
                    c.force.y(), c.force.z());
        if (c.plan_force_known)
          std::printf(", plan (%.0f %.0f %.0f) N\n", c.plan_force.x(), c.plan_force.y(), c.plan_force.z());
        else
          std::printf(", plan: none\n");
      }
    }
    std::printf("worst: slip %.1f mm (%s), base drift %.1f mm, tracking %.2f deg (%s)\n", 1e3 * r.worst_slip,
                r.worst_slip_contact.c_str(), 1e3 * r.worst_base_drift, r.worst_tracking * 180 / M_PI,
                r.worst_tracking_joint.c_str());
    std::printf("integrator: %s, accuracy %g, %ld steps (mean %.3g ms)\n", o.integrator.c_str(), o.accuracy,
                r.integrator_steps, 1e3 * r.mean_step);
    if (o.stabilizer)
      std::printf("stabilizer: on %.2f s of %.2f, a foot's turn up to %.2f deg, its rise up to %.1f mm\n",
                  r.stabilizer_on_time, tr.duration(), r.stabilizer_max_tilt * 180 / M_PI, 1e3 * r.stabilizer_max_lift);
    else
      std::printf("stabilizer: none (--no-stabilizer), every phase open-loop\n");
    if (r.body_contacts.empty())
      std::printf("unplanned contacts: none%s\n", o.body_contacts ? "" : " modelled (--no-body-contacts)");
    for (const auto& b : r.body_contacts)
      std::printf("unplanned contact: %s on %s, from %.3f s, %.2f s in all, up to %.0f N\n", b.link.c_str(),
                  b.surface.c_str(), b.first_time, b.loaded_time, b.max_force);
    std::printf("time: %.2f s simulated in %.2f s wall (%.2fx real time)\n", r.motion_time, r.wall_time,
                r.wall_time > 0 ? r.motion_time / r.wall_time : 0.0);
    std::printf("acceptance: %s (no fall, supporting slip < %.0f mm, base within %.0f mm of the plan)\n",
                r.executed() && r.base_within_bound ? "yes" : "no", 1e3 * o.slip_bound, 1e3 * o.base_bound);
  }
  std::printf("verdict: %s at %.3f s%s%s\n", hrp2::toString(r.verdict), r.verdict_time, r.reason.empty() ? "" : ": ",
              r.reason.c_str());
  if (!report_path.empty()) {
    try {
      hrp2::writeReport(r, report_path);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "acyclic-simulate: %s\n", e.what());
      return 2;
    }
  }
  return r.executed() ? 0 : 1;
}
