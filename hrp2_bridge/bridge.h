#pragma once
// The HRP-2 bridge's state machine (docs/design.md section 11), without LCM and
// without clocks: every input carries `now` (microseconds, one monotonic time
// base), so tests drive it deterministically.
//
//   idle ──trajectory──► checking ──ok──► streaming ──end──► idle
//                           └─refused─► (back where it was)
//   streaming ──stale state / stalled controller──► holding (hold the last command)
//   streaming ──tracking error, bad measured state──► fault (hold the last command)
//   any ──e-stop engage──► stopped (freeze) ──release──► streaming (speed blended
//                                                        from 0 to 1) or idle
//   holding ──trajectory (start checked)──► checking
//   fault, holding ──e-stop engage, release──► idle (the operator's reset)
//
// A trajectory arriving while checking, streaming, stopped or in fault is
// refused (not queued): the sender re-sends when the bridge reports idle.
#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "hrp2_bridge/bridge_config.h"
#include "hrp2_bridge/prepared_trajectory.h"

namespace acyclic::hrp2 {

enum class BridgeState { Idle = 0, Checking = 1, Streaming = 2, Holding = 3, Stopped = 4, Fault = 5 };
const char* toString(BridgeState s);

enum class CommandMode { Stream = 0, Hold = 1, Freeze = 2 };  // hrp2_command_t's constants

struct MeasuredState {
  Eigen::VectorXd q, dq;             // controller order
  std::int64_t request_id = -1;      // of the last command applied
  std::int64_t command_sequence = -1;
  bool servo_on = true;
};

struct Command {
  std::int64_t utime = 0;
  std::int64_t request_id = -1;      // -1 when holding or frozen
  std::int64_t sequence = 0;         // +1 per command
  CommandMode mode = CommandMode::Stream;
  Eigen::VectorXd q, dq;
  Eigen::Vector3d waist_position = Eigen::Vector3d::Zero(), waist_rpy = Eigen::Vector3d::Zero();
  Eigen::Vector3d zmp_waist = Eigen::Vector3d::Zero();
  bool stabilizer = true;
};

struct BridgeStatus {
  std::int64_t utime = 0;
  std::int64_t request_id = -1;
  BridgeState state = BridgeState::Idle;
  std::string reason;                // the last event
  double progress = 0;               // 0..1 of the trajectory played
  std::int64_t commands_sent = 0;
  double tracking_error_max = 0;     // rad, worst while streaming the current/last trajectory
  double tracking_error_last = 0;    // rad, at the last state
  std::int64_t safety_events = 0;
  bool state_fresh = false;
  std::int64_t finished_request_id = -1;  // the last trajectory played to the end, -1 none
};

// Something the process should log (and count, when `safety`).
struct BridgeEvent {
  std::int64_t utime = 0;
  BridgeState state = BridgeState::Idle;
  std::string text;
  bool safety = false;
  std::int64_t request_id = -1;  // the trajectory it is about, when done or refused
  bool done = false;             // played to the end
  bool refused = false;          // refused (busy, a check, the start guard, bad input)
};

class Bridge {
 public:
  Bridge(std::shared_ptr<const RobotModel> robot, BridgeConfig config);

  const BridgeConfig& config() const { return cfg_; }
  BridgeState state() const { return state_; }

  // The latest measured state (only the latest is ever used).
  void onState(const MeasuredState& s, std::int64_t now);
  // E-stop: engage freezes from any state; release blends back (streaming) or resets to idle.
  void onEstop(bool engage, const std::string& reason, std::int64_t now);

  // A trajectory arrived. True: the bridge is checking it (call endCheck with
  // the prepared result, possibly computed on another thread). False: refused
  // (busy), with the reason in *why and an event.
  bool beginCheck(std::int64_t request_id, std::int64_t now, std::string* why = nullptr);
  // The check is done: on success the start guard and the start posture are
  // checked against the latest state, then streaming begins at the next tick.
  // Ignored unless the bridge is still checking this request (an e-stop may
  // have come in between).
  void endCheck(std::int64_t request_id, PrepareResult result, std::int64_t now);

  // A trajectory refused before it reached the bridge (it did not convert:
  // a NaN, an unknown joint): reported like any refusal, nothing changes.
  void refuse(std::int64_t request_id, const std::string& why, std::int64_t now);

  // One control period: the command to send, if any (none while idle: the
  // controller keeps its own reference).
  std::optional<Command> tick(std::int64_t now);

  BridgeStatus status(std::int64_t now) const;
  std::vector<BridgeEvent> takeEvents();

  // Ticks that came more than 1.5 periods after the previous one.
  long lateTicks() const { return late_ticks_; }

  // The prepared trajectory being (or last) streamed.
  const PreparedTrajectory& trajectory() const { return traj_; }

 private:
  void event(std::int64_t now, const std::string& text, bool safety);
  void enter(BridgeState s, std::int64_t now, const std::string& why, bool safety);
  bool stateFresh(std::int64_t now) const;
  Command holdCommand(std::int64_t now, CommandMode mode);
  Command streamCommand(std::int64_t now);
  Command& remember(Command c);

  std::shared_ptr<const RobotModel> robot_;
  BridgeConfig cfg_;
  BridgeState state_ = BridgeState::Idle;
  std::string reason_ = "idle: waiting for a trajectory";
  std::vector<BridgeEvent> events_;
  std::int64_t safety_events_ = 0;

  // Robot state.
  std::optional<MeasuredState> measured_;
  std::int64_t measured_at_ = 0;
  std::int64_t last_ack_ = -1, ack_changed_at_ = 0;
  std::int64_t foreign_ack_at_ = -1;     // acknowledgements of commands not ours (start guard)
  double tracking_error_last_ = 0, tracking_error_max_ = 0;

  // Trajectory and playback.
  PreparedTrajectory traj_;
  std::int64_t request_id_ = -1, checking_id_ = -1;
  std::int64_t finished_request_id_ = -1;
  BridgeState before_check_ = BridgeState::Idle;
  double tau_ = 0;                        // s of trajectory played
  double pos_ = 0;                        // the same in samples
  bool active_ = false;                   // a trajectory is under way (streaming or interrupted by an e-stop)
  std::int64_t blend_start_ = -1;         // e-stop release: speed ramp start
  std::int64_t stream_start_ = 0;

  // The bridge's own timeliness: a tick more than 1.5 periods after the
  // previous one means the bridge itself was not running (the machine
  // stalled); the watchdogs then wait for a full timeout of on-time ticks
  // before they blame the robot, whose states were queued meanwhile.
  std::int64_t last_tick_ = -1, listening_since_ = -1;
  long late_ticks_ = 0;

  // Commands.
  std::int64_t sequence_ = 0, commands_sent_ = 0, last_command_at_ = -1;
  std::int64_t first_stream_seq_ = -1;
  std::deque<Command> sent_;              // recent commands, for the tracking error
  std::optional<Command> last_;
};

}  // namespace acyclic::hrp2
