#pragma once
// Every LCM channel name of the pipeline, in one place (docs/design.md section 2).
// Command/status pairs: requests go down the pipeline, answers come back up.

namespace acyclic::channels {

inline constexpr const char* kRequest = "ACYCLIC_REQUEST";          // request_t
inline constexpr const char* kCancel = "ACYCLIC_CANCEL";            // cancel_t
inline constexpr const char* kGuide = "ACYCLIC_GUIDE";              // guide_t
inline constexpr const char* kPlan = "ACYCLIC_PLAN";                // plan_t
// The transitions the planner's verification solved for a plan, sent just
// before it: a cache for the interpolator, never needed.
inline constexpr const char* kTransitions = "ACYCLIC_TRANSITIONS";  // transitions_t
inline constexpr const char* kTrajectory = "ACYCLIC_TRAJECTORY";    // trajectory_t
inline constexpr const char* kProgress = "ACYCLIC_PROGRESS";        // progress_t
inline constexpr const char* kStatus = "ACYCLIC_STATUS";            // process_status_t
inline constexpr const char* kHrp2Command = "HRP2_COMMAND";         // hrp2_command_t
inline constexpr const char* kHrp2State = "HRP2_STATE";             // hrp2_state_t
inline constexpr const char* kHrp2Estop = "HRP2_ESTOP";             // hrp2_estop_t
inline constexpr const char* kHrp2BridgeStatus = "HRP2_BRIDGE_STATUS";  // hrp2_bridge_status_t

}  // namespace acyclic::channels
