#pragma once
// Conversions between the libraries' plans and trajectories and their LCM
// messages (plan_t, trajectory_t). Names (joints, spots, surfaces) come from a
// scenario; a message that names something the scenario does not know is
// refused with a FormatError naming the message and field. Also HRP-2's
// messages (hrp2_command_t, hrp2_state_t, hrp2_bridge_status_t) to and from
// the bridge's and the simulated controller's types.
#include "acyclic/configuration_t.hpp"
#include "acyclic/contact_t.hpp"
#include "acyclic/hrp2_bridge_status_t.hpp"
#include "acyclic/hrp2_command_t.hpp"
#include "acyclic/hrp2_state_t.hpp"
#include "acyclic/plan_t.hpp"
#include "acyclic/trajectory_t.hpp"
#include "hrp2_bridge/bridge.h"
#include "hrp2_bridge/sim/simulated_controller.h"
#include "planner/plan/plan.h"
#include "planner/plan/trajectory.h"

namespace acyclic::convert {

configuration_t toMessage(const Configuration& q);
// The same with the quaternion as it is, not normalized again: a solver's
// knot, so that a trajectory made from it is the solver's, bit for bit.
configuration_t toMessageAsIs(const Configuration& q);
Configuration fromMessage(const configuration_t& m, const Scenario& sc, const std::string& origin);

// A contact's spot, surface, support and placement (and its frame's world
// pose; no points or forces). Read back, `at` names the field in `origin`.
contact_t toMessage(const ContactSpec& s, const Scenario& sc);
ContactSpec fromMessage(const contact_t& c, const Scenario& sc, const std::string& origin, const std::string& at);

// The plan's stances and stats; header fields (utime, request_id, status,
// scenario) are the caller's.
plan_t toMessage(const Plan& plan, const Scenario& sc);
Plan fromMessage(const plan_t& m, const Scenario& sc);

// Samples, phases and dt. A phase's stabilizer flag is left false here: the
// HRP-2 bridge schedules the stabilizer itself.
trajectory_t toMessage(const Trajectory& tr, const Scenario& sc);
Trajectory fromMessage(const trajectory_t& m, const Scenario& sc);

// HRP-2's enums and the messages' constants, value by value: a value the
// other side does not know is refused (FormatError naming the field), never
// cast into an enum that has no such value.
int8_t toMessage(hrp2::BridgeState s);
hrp2::BridgeState bridgeStateFromMessage(int8_t state);
int8_t toMessage(hrp2::CommandMode mode);
hrp2::CommandMode commandModeFromMessage(int8_t mode);

// The messages' utime is the caller's: the time it sends them, on its clock.
hrp2_command_t toMessage(const hrp2::Command& c, int64_t utime);
hrp2_bridge_status_t toMessage(const hrp2::BridgeStatus& s, int64_t utime);
hrp2_state_t toMessage(const hrp2::SimState& s, int64_t utime);
// Joint vectors as they come (the receiver checks their size against its
// robot: a wrong size is the bridge's fault, the controller's refusal); a
// command's unknown mode is refused here.
hrp2::MeasuredState fromMessage(const hrp2_state_t& m);
hrp2::SimCommand fromMessage(const hrp2_command_t& m);

}  // namespace acyclic::convert
