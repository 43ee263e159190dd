#pragma once
// Whether the limbs that hang from a contact can swing from one witness to
// the next (docs/design.md section 7). A limb below a link held on its
// contact in both stances (a foot and shank below a thigh resting on a seat)
// moves only by its own joints: between the two witnesses it swings on their
// interpolation, on an arc about the held link, and nothing else can take it
// around an obstacle on the way. A foot behind the knee in one witness and in
// front of it in the next, the knee 0.40 m over the floor, passes 5 mm
// through the floor whatever the interpolator does. The limb's end joints
// (an ankle), which turn its end body alone, are free: where the
// interpolation dips, the swing is refused only if no setting of them clears. The contact planner
// checks every son with its parent so, as the paper's method does not.
#include <string>
#include <vector>

#include "planner/collision/collision_model.h"
#include "planner/model/configuration.h"
#include "planner/model/kinematics.h"
#include "planner/scene/scenario.h"

namespace acyclic {

struct SwingOptions {
  int samples = 16;             // points of the interpolation checked, ends excluded
  double tolerance = 2e-4;      // m: penetration allowed (a body just leaving its surface)
};

// `held`: the contacts both stances hold (their links where both witnesses
// have them). Returns an empty string, or why a hanging limb cannot swing
// (the link and the obstacle or link it passes through, how deep).
std::string checkHangingSwings(const Scenario& sc, const CollisionModel& collisions, Kinematics& kin,
                               const std::vector<ContactSpec>& held, const Configuration& a, const Configuration& b,
                               const SwingOptions& options = {});

}  // namespace acyclic
