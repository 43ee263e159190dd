#pragma once
// Conversions between the libraries' plans and trajectories and their LCM
// messages (plan_t, trajectory_t). Names (joints, spots, surfaces) come from a
// scenario; a message that names something the scenario does not know is
// refused with a FormatError naming the message and field.
#include "acyclic/configuration_t.hpp"
#include "acyclic/plan_t.hpp"
#include "acyclic/trajectory_t.hpp"
#include "planner/plan/plan.h"
#include "planner/plan/trajectory.h"

namespace acyclic::convert {

configuration_t toMessage(const Configuration& q);
Configuration fromMessage(const configuration_t& m, const Scenario& sc, const std::string& origin);

// The plan's stances and stats; header fields (utime, request_id, status,
// scenario) are the caller's.
plan_t toMessage(const Plan& plan, const Scenario& sc);
Plan fromMessage(const plan_t& m, const Scenario& sc);

// Samples, phases and dt. A phase's stabilizer flag is left false here: the
// HRP-2 bridge schedules the stabilizer itself.
trajectory_t toMessage(const Trajectory& tr, const Scenario& sc);
Trajectory fromMessage(const trajectory_t& m, const Scenario& sc);

}  // namespace acyclic::convert
