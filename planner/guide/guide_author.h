#pragma once
// The rough-trajectory author: the paper's guide was written by
// hand; here OMPL writes it. From the scenario's start configuration to a
// posture in the goal region made by the posture generator (standing there;
// or the start stance carried there; for a goal on the height of a link, the
// robot resting on the goal's supported_by spots, as when it sits down), it
// plans in a reduced space - the base's position and heading, and a blend
// parameter alpha that carries every other coordinate from the start
// posture to the goal posture - with FCL checking the scene against robot
// geometry that may penetrate it by a few centimetres (a rough trajectory
// may graze obstacles, paper 2.7). The path is shortcut and its vertices
// lifted to whole-body key postures. Seeded: same scenario and seed, same
// guide. Failures return a status with a reason.
#include <atomic>
#include <string>

#include "planner/plan/guide.h"

namespace acyclic {

struct GuideOptions {
  double penetration = 0.03;    // m: robot-environment penetration allowed along the rough trajectory
  double max_seconds = 10;      // wall time for OMPL's searches, all of them
  // State checks at most for a search whose failure leads to another (to the
  // approach posture, standing where a crouch may follow): those decisions
  // are the same under any load.
  long fallback_checks = 50000;
  double range = 0.2;           // RRTConnect's range, in the reduced space's metric
  int shortcut_steps = 300;     // PathSimplifier attempts (counts, not time: deterministic)
  double goal_margin = 0.05;    // m: how far past the goal's bound the goal posture stands
  double goal_search = 0.6;     // m: the goal posture's free coordinate tried within +- this of the start's
  int support_attempts = 40;    // start stances carried toward a surface, for a goal posture on supported_by spots
  std::string standing_posture = "half_sitting";  // the robot's named posture the goal posture starts from
  // For a goal resting on supported_by spots that the start stance carried
  // toward their surface cannot reach (a seat at a table): the robot's named
  // seated posture put over that surface (goalPosture).
  std::string seated_posture = "sitting";
  // m: the path's base at most this much higher over the ground under it
  // than the standing posture's base over its soles (authorGuide).
  double ceiling_slack = 0.03;
  // Where no path of standing postures reaches the goal within half of
  // max_seconds, try again with a crouch coordinate (authorGuide).
  bool crouch = true;
  // Where no posture stands in the goal region and the start stance cannot
  // be carried there (under a low table): the robot's named crawling
  // posture there, and getting down onto its contacts where the robot
  // starts (authorGuide).
  bool crawl = true;
  std::string crawling_posture = "crawling";
  double crawl_step = 0.1;      // m: the crawling posture this far ahead of where the robot got down
  // Paths through the statically stable subspace (Bouyarmane 2009;
  // planner/guide/stable_path.h): every leg's shortcut path sampled along its
  // edges, each sample projected by the posture generator onto a posture in
  // static equilibrium on the contacts it makes, accepted by the check; the
  // key postures are the projections. Where a sample does not project, the
  // leg is planned again with a ball around it left out of the reduced
  // space, at most stable_replans times.
  bool stable = false;
  // The key postures samples along the edges as with `stable`, not
  // projected (a control for what the projection itself changes).
  bool sample_edges = false;
  double stable_step = 0.1;     // m of base travel (and 0.1 of blend, 0.2 rad of heading) between samples
  double stable_reach = 0.05;   // m: a spot this close to an allowed surface rests on it (StableOptions::reach)
  double stable_tolerance = 0.1;  // m: a projection's base this near the sample's, horizontally
  int stable_replans = 4;
  double stable_forbid = 0.1;   // the left-out ball's radius in the reduced space's metric
  // Each leg's path: the shortest (in the reduced space's metric, once
  // shortcut) of this many RRTConnect tries, the first with `seed`, the
  // others with seeds derived from it. One try leaves the guide to one
  // random tree's luck: on chair_paper some seeds find no path within
  // fallback_checks or go round the chair the long way (docs/design.md
  // section 7).
  int path_tries = 1;
  // Where none of those tries finds a path within its bound, up to this many
  // more, each seeded anew as they are and bounded by state checks
  // (fallback_checks where the leg has no such bound), before the leg is
  // given up (and a crouch, an approach posture or a crawl is tried). A
  // guide whose first try finds its path is the same as without them; a
  // leg that no try can make (under duck_under_beam's beam) costs that many
  // more bounded tries before its fallback. On chair_paper, seed 2's
  // standing path was not found within 50,000 checks, the one of seeds 1-60
  // without a guide; with one retry all 60 have one (docs/design.md
  // section 7).
  int path_retries = 1;
  unsigned seed = 1;
};

struct GuideResult {
  enum class Status { Success, InvalidStart, NoGoalPosture, NoPath, Cancelled };
  Status status = Status::InvalidStart;
  std::string reason;
  Guide guide;                  // on success
  int path_vertices = 0;        // before shortcutting (every leg's)
  bool approach = false;        // an approach posture before the goal posture (approachPosture)
  int approach_index = -1;      // its index in guide.key_postures
  bool crouch = false;          // the path needed the crouch coordinate (crouchOffsets)
  bool crawl = false;           // the goal is crawling: the guide gets down first (gettingDown)
  int crawl_index = -1;         // the key posture at which the robot is down on its crawl contacts
  int stable_projections = 0;   // posture generator calls projecting samples (GuideOptions::stable)
  int stable_replans = 0;       // legs planned again around a sample that did not project
  double stable_seconds = 0;    // spent projecting
  double goal_seconds = 0, path_seconds = 0;
  bool success() const { return status == Status::Success; }
};

const char* toString(GuideResult::Status s);

GuideResult authorGuide(const Scenario& sc, const GuideOptions& options, const std::atomic<bool>* cancel = nullptr);

}  // namespace acyclic
