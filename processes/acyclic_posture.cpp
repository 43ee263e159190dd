// acyclic-posture: one posture-generator call on a scenario's start stance,
// the way the planner makes one son (paper 2.3): contacts removed from the
// stance stay touching but stop supporting; an added contact floats over its
// whole surface, touching, geometric only. Prints the result, the witness's
// centre of mass and the independent check; writes the witness as a one-stance
// plan when asked. For scenario authors: is this stance feasible at all?
// With --from PLAN --stance K, a plan's stance as the plan holds it: does it
// still exist with stability margins?
// Exit: 0 found and valid, 1 not found or not valid, 2 bad input.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <limits>
#include <string>

#include "processes/command_line.h"
#include "planner/check/validity.h"
#include "planner/common/format_error.h"
#include "planner/posture/heap_tuning.h"
#include "planner/plan/plan.h"
#include "planner/posture/posture_generator.h"
#include "planner/search/search_volume.h"

using namespace acyclic;

int main(int argc, char** argv) {
  CLI::App app{
      "One posture-generator call on a scenario's start stance (or a plan's last stance, --from, or any\n"
      "of its stances as the plan holds it, --stance), as the planner makes one son:\n"
      "  --remove SPOT: that start contact stays touching but stops supporting (repeatable);\n"
      "  --add SPOT@SURFACE: a contact floating over the whole surface, touching, not supporting.\n"
      "Cost: distance to the start configuration. Prints the status, the witness's centre of mass and\n"
      "the independent check of the validity contract. Exit: 0 found and valid, 1 not, 2 bad input."};
  std::string scenario_path, add, out, from;
  std::vector<std::string> remove;
  int iterations = 300;
  double seconds = 5;
  int print_level = 0;
  std::vector<std::string> ipopt;
  app.add_option("scenario", scenario_path, "scenario file (acyclic.scenario/1)")->required();
  app.add_option("--from", from,
                 "start from the last stance of this plan instead (its contacts all supporting, as the planner's "
                 "node after the change settles)");
  int stance_index = -1;
  app.add_option("--stance", stance_index,
                 "with --from: re-pose this stance of the plan (0 the start) as the plan holds it, its touching but "
                 "not supporting contacts as they are (the call that made it, e.g. to probe it with margins)")
      ->check(CLI::Range(0, std::numeric_limits<int>::max()))
      ->needs("--from");
  app.add_option("--remove", remove, "a start contact's spot that stops supporting (repeatable)");
  app.add_option("--add", add, "SPOT@SURFACE: a contact to add, floating over the surface");
  app.add_option("--iterations", iterations, "Ipopt iterations at most")->capture_default_str();
  app.add_option("--max-seconds", seconds, "CPU seconds at most")->capture_default_str();
  app.add_option("--print-level", print_level, "Ipopt's print level (0-12), to see why a solve fails")
      ->check(CLI::Range(0, 12));
  std::string engine = "convex";
  app.add_option("--distance-engine", engine,
                 "collision distances: convex (the posture generator's default) or fcl (the planner's)")
      ->check([](const std::string& v) { return distanceEngineNamed(v) ? std::string() : "expected convex or fcl"; })
      ->capture_default_str();
  int pyramid_edges = 4;
  app.add_option("--pyramid-edges", pyramid_edges,
                 "friction pyramid edges per corner: 4 (every other edge of the contract's) or 8 (all of them)")
      ->check(CLI::IsMember({4, 8}))
      ->capture_default_str();
  double support_inset = 0, support_inset_y = -1, friction_share = 1;
  app.add_option("--support-inset-y", support_inset_y,
                 "the same along each spot's y axis (across a sole) instead, m (negative: --support-inset)")
      ->capture_default_str();
  app.add_option("--support-inset", support_inset,
                 "stability margin: each supporting contact's forces applied this far (m) inside its spot's edges")
      ->check(CLI::Range(0.0, 0.1))
      ->capture_default_str();
  app.add_option("--friction-share", friction_share,
                 "stability margin: the share of each surface's friction coefficient used, in (0, 1]")
      ->check(CLI::Range(1e-6, 1.0))
      ->capture_default_str();
  app.add_option("--ipopt", ipopt, "a further Ipopt option NAME=VALUE (repeatable)");
  app.add_option("--out", out,
                 "write the witness as a one-stance plan (acyclic.plan/1) with the stance once the change settles "
                 "(removed contacts gone, the added one supporting): the input of a next --from")
      ->check(acyclic::proc::InWritableDirectory());
  ACYCLIC_PARSE_COMMAND_LINE(app, argc, argv)
  keepSolverWorkspaceInHeap();  // planner/posture/heap_tuning.h
  try {
    const Scenario sc = Scenario::load(scenario_path);
    PostureRequest r;
    r.contacts = sc.start_stance;
    r.initial_guess = sc.start;
    if (!from.empty()) {
      const Plan p = readPlan(from, sc);
      if (p.stances.empty()) throw FormatError(from, "stances", "at least one stance");
      const int n = static_cast<int>(p.stances.size());
      if (stance_index >= n)
        throw FormatError("--stance", std::to_string(stance_index),
                          "a stance of " + from + ", 0 to " + std::to_string(n - 1));
      const PlanStance& st = p.stances[static_cast<std::size_t>(stance_index < 0 ? n - 1 : stance_index)];
      r.contacts = st.specs();
      // The last stance as the planner's node once its change settles (all
      // supporting); a stance named by --stance exactly as the plan holds it.
      if (stance_index < 0)
        for (auto& c : r.contacts) c.supporting = true;
      r.initial_guess = st.configuration;
    }
    for (const auto& name : remove) {
      bool found = false;
      for (auto& c : r.contacts)
        if (sc.robot->spots()[c.spot].name == name) c.supporting = false, found = true;
      if (!found) throw FormatError("--remove", name, "a spot of the stance");
    }
    if (!add.empty()) {
      const auto at = add.find('@');
      if (at == std::string::npos) throw FormatError("--add", add, "SPOT@SURFACE");
      FloatingContact f;
      f.spot = sc.robot->spotIndex(add.substr(0, at));
      f.surface = sc.scene->surfaceIndex(add.substr(at + 1));
      if (f.spot < 0) throw FormatError("--add", add.substr(0, at), "a contact spot of the robot");
      if (f.surface < 0) throw FormatError("--add", add.substr(at + 1), "a surface of the scene");
      f.volume = fullVolume(sc.scene->surfaces()[f.surface].polygon);
      r.floating = f;
    }
    PostureGeneratorOptions o;
    o.max_iterations = iterations;
    o.max_seconds = seconds;
    o.print_level = print_level;
    o.ipopt_options = ipopt;
    o.distance_engine = *distanceEngineNamed(engine);
    o.problem.pyramid_sides = pyramid_edges;
    o.problem.support_inset = support_inset;
    o.problem.support_inset_y = support_inset_y;
    o.problem.friction_share = friction_share;
    PostureGenerator pg(sc.robot, sc.scene, o);
    const PostureResult res = pg.solve(r);
    std::printf("acyclic-posture: %s in %d iterations, %.1f ms%s%s%s\n", toString(res.status), res.iterations,
                res.seconds * 1e3,
                res.footprint_turned ? ", solved again with the added spot's footprint turned half a turn" : "",
                res.reason.empty() ? "" : ": ", res.reason.c_str());
    Kinematics kin(sc.robot);
    kin.setConfiguration(res.configuration);
    const Eigen::Vector3d com = kin.centerOfMass();
    std::printf("  witness: base (%.3f, %.3f, %.3f), centre of mass (%.3f, %.3f, %.3f)\n",
                res.configuration.base_position.x(), res.configuration.base_position.y(),
                res.configuration.base_position.z(), com.x(), com.y(), com.z());
    std::vector<ContactSpec> stance = r.contacts;
    if (r.floating) {
      ContactSpec c;
      c.spot = r.floating->spot;
      c.surface = r.floating->surface;
      c.supporting = false;
      c.placement = res.floating;
      // The contact rows fix the angle only modulo pi: the placement takes
      // the witness's own angle, as the planner's nodes do, so that the
      // contact frame written is the spot's.
      c.placement.theta = projectOnSurface(sc.scene->surfaces()[c.surface], kin.spotPose(c.spot)).theta;
      stance.push_back(c);
      std::printf("  added %s at (%.3f, %.3f, %.3f)\n", sc.describe(c).c_str(), c.placement.x, c.placement.y,
                  c.placement.theta);
    }
    if (!res.success()) return 1;
    ValidityChecker checker(sc.robot, sc.scene);
    const ValidityReport rep = checker.checkPosture(res.configuration, stance);
    for (const auto& part : rep.parts)
      std::printf("  [%s] %-13s %s\n", part.ok() ? " ok " : "FAIL", part.name.c_str(), part.summary.c_str());
    if (!out.empty()) {
      Plan plan;
      plan.scenario = scenario_path;
      // The stance once the change settles (the planner's node): removed
      // contacts gone, the added one supporting; the witness as its posture.
      PlanStance s;
      s.configuration = res.configuration;
      for (ContactSpec c : stance) {
        if (!c.supporting && !(r.floating && c.spot == r.floating->spot)) continue;
        c.supporting = true;
        PlanContact pc;
        pc.spec = c;
        pc.frame = contactFrame(sc.scene->surfaces()[c.surface], c.placement);
        s.contacts.push_back(pc);
      }
      plan.stances.push_back(s);
      writePlan(plan, sc, out);
    }
    return rep.valid() ? 0 : 1;
  } catch (const FormatError& e) {
    std::fprintf(stderr, "acyclic-posture: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "acyclic-posture: error: %s\n", e.what());
    return 2;
  }
}
