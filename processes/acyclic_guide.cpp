// acyclic-guide: authors a scenario's rough trajectory (its key postures)
// with OMPL and writes it as acyclic.guide/1, for acyclic-planner --guide.
// Exit: 0 written, 1 no guide (reason printed), 2 bad input.
#include <CLI/CLI.hpp>

#include <cstdio>

#include "processes/command_line.h"
#include "planner/common/format_error.h"
#include "planner/posture/heap_tuning.h"
#include "planner/guide/guide_author.h"
#include "processes/guide_service.h"
#include "processes/lcm_process.h"

using namespace acyclic;

int main(int argc, char** argv) {
  CLI::App app{
      "Authors a scenario's rough trajectory with OMPL (the paper wrote it by hand): a posture in the goal\n"
      "region from the posture generator (standing, on the floor or a level surface above it; else the\n"
      "start stance carried there; for a goal on a link's height, resting on the goal's supported_by\n"
      "spots: the start stance lowered onto them, else the robot's seated posture put over their surface),\n"
      "then RRTConnect in (base position, heading, blend from the start posture to the goal posture) with\n"
      "FCL against the scene, the robot allowed to graze obstacles by --penetration and its base kept\n"
      "within its standing height (+3 cm) of the ground within a step of it; the path shortcut and lifted\n"
      "to whole-body key postures. For a goal resting on spots the start lacks (sitting down) from a start\n"
      "not in line with it, through an approach posture standing in front of it first. Where standing\n"
      "postures find no path within half the budget (a low beam), again with a crouch coordinate (the\n"
      "start stance lowered on its feet) in the space. Where nothing stands in the goal region (under a\n"
      "low table), the robot's crawling posture there, reached by getting down where it starts (a squat,\n"
      "a knee, the palms, the other knee: each a posture-generator witness) and then crawling.\n"
      "With --stable, paths through the statically stable subspace: every key posture in static\n"
      "equilibrium on the contacts it makes (section 7 of docs/design.md).\n"
      "Writes acyclic.guide/1 (give it to acyclic-planner --guide). Same scenario and seed, same guide.\n"
      "With --scenario-keys, writes the scenario's own (hand-written) key postures instead, as parsed: a\n"
      "guide to edit and plan with beside the scenario's (models/guides/chair_paper_hand_on_chair.guide.json).\n"
      "File mode: --in SCENARIO --out GUIDE; exit status 0 written, 1 no guide (reason printed), 2 bad input.\n"
      "LCM mode: --lcm answers every ACYCLIC_REQUEST whose scenario has no key postures with ACYCLIC_GUIDE\n"
      "(same request id; the planner waits for it); ACYCLIC_STATUS at 1 Hz and on errors; ACYCLIC_CANCEL.\n"
      "One request at a time: another is refused (ACYCLIC_GUIDE with status ERROR). Exits 0 on SIGINT/SIGTERM."};
  std::string in, out;
  GuideOptions o;
  long seed = -1;
  bool lcm_mode = false;
  std::string url = proc::defaultLcmUrl();
  app.add_option("--in", in, "scenario file (acyclic.scenario/1), file mode");
  app.add_option("--out", out, "guide file to write (acyclic.guide/1), file mode")
      ->check(acyclic::proc::InWritableDirectory());
  app.add_flag("--lcm", lcm_mode, "serve ACYCLIC_REQUEST on LCM instead of the file mode");
  app.add_option("--lcm-url", url, "LCM URL (default: $LCM_DEFAULT_URL, else LCM's default)");
  app.add_option("--seed", seed, "seed (default: the scenario's)");
  app.add_option("--max-seconds", o.max_seconds, "OMPL search budget, s")->capture_default_str();
  app.add_option("--penetration", o.penetration, "robot-scene penetration allowed along the guide, m")
      ->capture_default_str();
  app.add_option("--range", o.range, "RRTConnect range in the reduced space")->capture_default_str();
  app.add_option("--path-tries", o.path_tries,
                 "each leg's path the shortest of this many RRTConnect tries (the first with the seed, the others\n"
                 "with seeds derived from it, each bounded by state checks): less of one random tree's luck")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  app.add_option("--path-retries", o.path_retries,
                 "where none of those tries finds a leg's path within its state checks, this many more (seeded\n"
                 "the same way) before the leg is given up; a guide whose first try succeeds is unchanged")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  bool no_crouch = false;
  app.add_flag("--no-crouch", no_crouch, "standing postures only: no second try with a crouch");
  bool no_crawl = false;
  app.add_flag("--no-crawl", no_crawl, "no crawling goal posture where nothing stands in the goal region");
  app.add_flag("--stable", o.stable,
               "paths through the statically stable subspace (Bouyarmane 2009): samples along the path, each\n"
               "projected by the posture generator onto a posture in static equilibrium on the contacts it\n"
               "makes (checked); the leg replanned around a sample that does not project");
  app.add_option("--stable-step", o.stable_step, "m of base travel between samples with --stable")->capture_default_str();
  app.add_option("--stable-reach", o.stable_reach, "m: a spot this close to a surface rests on it, with --stable")
      ->capture_default_str();
  bool scenario_keys = false;
  app.add_flag("--scenario-keys", scenario_keys,
               "write the scenario's own key postures (bit for bit as parsed) instead of authoring a guide");
  std::string source = "hand";
  app.add_option("--source", source, "the guide's source text: where its key postures come from")
      ->capture_default_str()
      ->check(CLI::Validator([](std::string& s) { return s.empty() ? std::string("give a non-empty text") : ""; },
                             "TEXT"))
      ->needs("--scenario-keys");
  ACYCLIC_PARSE_COMMAND_LINE(app, argc, argv)
  o.crouch = !no_crouch;
  o.crawl = !no_crawl;
  keepSolverWorkspaceInHeap();  // planner/posture/heap_tuning.h
  proc::installSignalHandlers();
  if (lcm_mode) return serveGuide(url, o);
  if (in.empty() || out.empty()) {
    std::fprintf(stderr, "acyclic-guide: give --in SCENARIO --out GUIDE (file mode) or --lcm; see --help\n");
    return 2;
  }
  try {
    const Scenario sc = Scenario::load(in);
    if (scenario_keys) {
      if (sc.key_postures.size() < 2) {
        std::fprintf(stderr, "acyclic-guide: %s: key_postures: the scenario has fewer than two key postures to write\n",
                     in.c_str());
        return 2;
      }
      writeGuide(Guide{in, source, sc.key_postures, 0.0}, sc, out);
      std::printf("acyclic-guide: %s: its %zu key postures written to %s\n", sc.name.c_str(), sc.key_postures.size(),
                  out.c_str());
      return 0;
    }
    o.seed = static_cast<unsigned>(seed >= 0 ? seed : static_cast<long>(sc.seed));
    const GuideResult r = authorGuide(sc, o, &proc::stopFlag());
    if (!r.success()) {
      std::printf("acyclic-guide: %s: %s: %s\n", sc.name.c_str(), toString(r.status), r.reason.c_str());
      return 1;
    }
    Guide g = r.guide;
    g.scenario = in;
    writeGuide(g, sc, out);
    std::printf("acyclic-guide: %s: %zu key postures (path of %d vertices shortcut) in %.2f s "
                "(goal posture %.2f s, OMPL %.2f s), written to %s\n",
                sc.name.c_str(), g.key_postures.size(), r.path_vertices, g.seconds, r.goal_seconds, r.path_seconds,
                out.c_str());
    if (r.approach) std::printf("acyclic-guide: through an approach posture standing in front of the goal\n");
    if (o.stable)
      std::printf("acyclic-guide: through the statically stable subspace: %d posture calls projecting samples in "
                  "%.2f s, %d replans around samples that did not project\n",
                  r.stable_projections, r.stable_seconds, r.stable_replans);
    if (r.crouch) std::printf("acyclic-guide: crouched: no path of standing postures\n");
    if (r.crawl)
      std::printf("acyclic-guide: crawling: nothing stands in the goal region; down on the '%s' posture's contacts "
                  "at key posture %d\n", o.crawling_posture.c_str(), r.crawl_index + 1);
    return 0;
  } catch (const FormatError& e) {
    std::fprintf(stderr, "acyclic-guide: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "acyclic-guide: error: %s\n", e.what());
    return 2;
  }
}
