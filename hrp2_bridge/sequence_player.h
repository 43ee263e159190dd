#pragma once
// Export to OpenHRP / hrpsys SequencePlayer files (hrp2-public-facts.md):
// BASENAME.pos (joint angles, controller order, rad), BASENAME.waist (base
// x y z, roll pitch yaw, world), BASENAME.zmp (ZMP x y z in the waist frame),
// whitespace-separated rows `t v1 ... vN` at the controller period, t in
// seconds from the start. The same numbers the bridge streams.
#include <string>
#include <vector>

#include "hrp2_bridge/prepared_trajectory.h"

namespace acyclic::hrp2 {

// Writes the three files (each beside, then renamed: a crash never leaves
// half a file); returns their paths. std::runtime_error naming the file when
// one cannot be written.
std::vector<std::string> writeSequencePlayer(const PreparedTrajectory& p, const std::string& basename);

}  // namespace acyclic::hrp2
