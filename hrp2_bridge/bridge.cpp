#include "hrp2_bridge/bridge.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "planner/common/fmt.h"

namespace acyclic::hrp2 {

namespace {

constexpr std::size_t kRememberedCommands = 400;   // 2 s at 200 Hz: covers any sane latency
constexpr double kForeignWindow = 0.5;             // s: the start guard's memory of foreign commands

std::int64_t us(double seconds) { return static_cast<std::int64_t>(std::llround(seconds * 1e6)); }
double ms(std::int64_t micro) { return micro * 1e-3; }


}  // namespace

const char* toString(BridgeState s) {
  switch (s) {
    case BridgeState::Idle: return "idle";
    case BridgeState::Checking: return "checking";
    case BridgeState::Streaming: return "streaming";
    case BridgeState::Holding: return "holding";
    case BridgeState::Stopped: return "stopped";
    case BridgeState::Fault: return "fault";
  }
  return "?";
}

Bridge::Bridge(std::shared_ptr<const RobotModel> robot, BridgeConfig config)
    : robot_(std::move(robot)), cfg_(config) {
  cfg_.validate();
}

void Bridge::event(std::int64_t now, const std::string& text, bool safety) {
  events_.push_back({now, state_, text, safety});
  reason_ = text;
  if (safety) ++safety_events_;
}

void Bridge::enter(BridgeState s, std::int64_t now, const std::string& why, bool safety) {
  state_ = s;
  event(now, why, safety);
}

std::vector<BridgeEvent> Bridge::takeEvents() {
  std::vector<BridgeEvent> e;
  e.swap(events_);
  return e;
}

bool Bridge::stateFresh(std::int64_t now) const {
  return measured_ && now - measured_at_ <= us(cfg_.state_timeout);
}

void Bridge::onState(const MeasuredState& s, std::int64_t now) {
  const CheckResult ok = checkMeasured(s.q, s.dq, *robot_);
  if (!ok.ok) {
    // Not taken as fresh: the watchdog keeps counting from the last good one.
    if (state_ == BridgeState::Streaming) {
      active_ = false;
      enter(BridgeState::Fault, now, "fault: " + ok.reason, true);
    } else if (reason_ != ok.reason) {
      event(now, ok.reason, true);
    }
    return;
  }
  const bool seen_before = measured_.has_value();
  measured_ = s;
  measured_at_ = now;
  if (s.command_sequence != last_ack_) {
    last_ack_ = s.command_sequence;
    ack_changed_at_ = now;
    const bool ours = std::any_of(sent_.begin(), sent_.end(), [&](const Command& c) {
      return c.sequence == s.command_sequence && c.request_id == s.request_id;
    });
    // The first state only tells where the controller stands; a change after
    // it that is not ours means someone else is commanding the robot.
    if (!ours && seen_before && s.command_sequence >= 0) foreign_ack_at_ = now;
  }
  if (state_ != BridgeState::Streaming) return;
  // Tracking error against the command the controller says it applied.
  for (auto it = sent_.rbegin(); it != sent_.rend(); ++it) {
    if (it->sequence != s.command_sequence) continue;
    if (it->mode != CommandMode::Stream) break;
    Eigen::Index j = 0;
    tracking_error_last_ = (it->q - s.q).cwiseAbs().maxCoeff(&j);
    tracking_error_max_ = std::max(tracking_error_max_, tracking_error_last_);
    if (tracking_error_last_ > cfg_.max_tracking_error) {
      active_ = false;
      enter(BridgeState::Fault, now,
            "fault: tracking error " + fmt("%.3f rad on ", tracking_error_last_) + robot_->joints()[j].name +
                fmt(" (limit %.3f rad): holding", cfg_.max_tracking_error),
            true);
    }
    break;
  }
}

void Bridge::onEstop(bool engage, const std::string& reason, std::int64_t now) {
  const std::string why = reason.empty() ? "" : " (" + reason + ")";
  if (engage) {
    if (state_ == BridgeState::Stopped) {
      event(now, "e-stop engaged again" + why, false);
      return;
    }
    // Only a trajectory interrupted while streaming resumes on release.
    if (state_ != BridgeState::Streaming) active_ = false;
    checking_id_ = -1;
    if (!last_ && measured_) {
      // Never commanded: freeze where the robot is.
      Command c;
      c.q = measured_->q;
      c.dq = Eigen::VectorXd::Zero(c.q.size());
      last_ = c;
    }
    enter(BridgeState::Stopped, now, "e-stop engaged" + why + ": frozen", true);
    return;
  }
  if (state_ != BridgeState::Stopped) {
    event(now, "e-stop release ignored: not stopped" + why, false);
    return;
  }
  if (active_) {
    blend_start_ = now;
    ack_changed_at_ = now;
    enter(BridgeState::Streaming, now,
          "e-stop released" + why + fmt(": resuming at %.3f s, speed blended over %.2f s", tau_, cfg_.release_blend),
          true);
  } else {
    enter(BridgeState::Idle, now, "e-stop released" + why + ": idle", true);
  }
}

bool Bridge::beginCheck(std::int64_t request_id, std::int64_t now, std::string* why) {
  if (state_ != BridgeState::Idle && state_ != BridgeState::Holding) {
    std::string w = "refused request " + std::to_string(request_id) + ": bridge " + toString(state_);
    if (state_ == BridgeState::Streaming || state_ == BridgeState::Checking)
      w += " request " + std::to_string(state_ == BridgeState::Checking ? checking_id_ : request_id_) +
           " (not queued: send it again when idle)";
    if (state_ == BridgeState::Fault) w += " (reset: e-stop engage then release)";
    if (state_ == BridgeState::Stopped) w += " (e-stop engaged)";
    if (why) *why = w;
    events_.push_back({now, state_, w, false, request_id, false, true});  // the state's own reason stays
    return false;
  }
  before_check_ = state_;
  checking_id_ = request_id;
  enter(BridgeState::Checking, now, "checking request " + std::to_string(request_id), false);
  return true;
}

void Bridge::endCheck(std::int64_t request_id, PrepareResult result, std::int64_t now) {
  if (state_ != BridgeState::Checking || request_id != checking_id_) {
    event(now, "check of request " + std::to_string(request_id) + " dropped: bridge " + toString(state_), false);
    return;
  }
  checking_id_ = -1;
  auto refuse = [&](const std::string& why) {
    enter(before_check_, now, "refused request " + std::to_string(request_id) + ": " + why, true);
    events_.back().request_id = request_id;
    events_.back().refused = true;
  };
  if (!result.check.ok) return refuse(result.check.reason);
  if (result.prepared.samples.empty()) return refuse("nothing to stream");
  if (!measured_) return refuse("no robot state received (HRP2_STATE)");
  if (!stateFresh(now)) return refuse(fmt("robot state stale (last HRP2_STATE %.1f ms ago)", ms(now - measured_at_)));
  if (!measured_->servo_on) return refuse("start guard: servo off");
  Eigen::Index j = 0;
  const double v = measured_->dq.cwiseAbs().maxCoeff(&j);
  if (v > cfg_.rest_velocity)
    return refuse("start guard: " + robot_->joints()[j].name +
                  fmt(" moving at %.3f rad/s (at most %.3f at rest): a controller left running?", v, cfg_.rest_velocity));
  if (foreign_ack_at_ >= 0 && now - foreign_ack_at_ < us(kForeignWindow))
    return refuse(fmt("start guard: the controller applied commands not from this bridge %.0f ms ago "
                      "(another bridge or a pattern left running?)",
                      ms(now - foreign_ack_at_)));
  const CheckResult start = checkStart(result.prepared.samples.front().q, measured_->q, *robot_, cfg_);
  if (!start.ok) return refuse(start.reason);

  traj_ = std::move(result.prepared);
  request_id_ = request_id;
  tau_ = 0;
  pos_ = 0;
  active_ = true;
  blend_start_ = -1;
  stream_start_ = now;
  first_stream_seq_ = -1;
  ack_changed_at_ = now;
  tracking_error_max_ = tracking_error_last_ = 0;
  enter(BridgeState::Streaming, now,
        "streaming request " + std::to_string(request_id) +
            fmt(": %.3f s, %.0f commands, %.0f stabilizer switches", traj_.duration(),
                double(traj_.samples.size()), double(traj_.switches.size())),
        false);
}

void Bridge::refuse(std::int64_t request_id, const std::string& why, std::int64_t now) {
  event(now, "refused request " + std::to_string(request_id) + ": " + why, true);
  events_.back().request_id = request_id;
  events_.back().refused = true;
}

Command& Bridge::remember(Command c) {
  c.sequence = ++sequence_;
  sent_.push_back(c);
  if (sent_.size() > kRememberedCommands) sent_.pop_front();
  last_ = c;
  ++commands_sent_;
  last_command_at_ = c.utime;
  return *last_;
}

Command Bridge::holdCommand(std::int64_t now, CommandMode mode) {
  Command c = *last_;
  c.utime = now;
  c.mode = mode;
  c.request_id = -1;
  c.dq = Eigen::VectorXd::Zero(c.q.size());
  return remember(c);
}

Command Bridge::streamCommand(std::int64_t now) {
  // Playback speed: 1, or the smoothstep ramp after an e-stop release.
  double rate = 1;
  if (blend_start_ >= 0) {
    const double u = cfg_.release_blend > 0 ? (now - blend_start_) * 1e-6 / cfg_.release_blend : 1.0;
    if (u >= 1) {
      blend_start_ = -1;
      event(now, fmt("blend done at %.3f s", tau_), false);
    } else {
      rate = u * u * (3 - 2 * u);
    }
  }
  // Playback position counted in samples (exact while the rate is 1), so
  // that plain playback sends the prepared samples bit for bit.
  if (first_stream_seq_ >= 0) pos_ += rate;
  const auto& s = traj_.samples;
  const double last_pos = double(s.size() - 1);
  const bool last = pos_ >= last_pos - 1e-9;
  const double pos = std::min(pos_, last_pos);
  const std::size_t k = std::min(s.size() - 1, static_cast<std::size_t>(std::floor(pos + 1e-9)));
  const std::size_t k1 = std::min(s.size() - 1, k + 1);
  const double u = k1 == k ? 0.0 : std::clamp(pos - double(k), 0.0, 1.0);
  tau_ = pos * traj_.dt;
  const double d = traj_.duration();
  Command c;
  c.utime = now;
  c.request_id = request_id_;
  c.mode = CommandMode::Stream;
  c.q = (1 - u) * s[k].q + u * s[k1].q;
  c.dq = rate * ((1 - u) * s[k].dq + u * s[k1].dq);
  c.waist_position = (1 - u) * s[k].waist_position + u * s[k1].waist_position;
  c.waist_rpy = (1 - u) * s[k].waist_rpy + u * s[k1].waist_rpy;
  c.zmp_waist = (1 - u) * s[k].zmp_waist + u * s[k1].zmp_waist;
  // Off if either neighbour is off: never on across a non-coplanar contact.
  c.stabilizer = s[k].stabilizer && (u == 0 || s[k1].stabilizer);
  if (last) c.dq.setZero();
  Command& sent = remember(c);
  if (first_stream_seq_ < 0) first_stream_seq_ = sent.sequence;
  if (last) {
    active_ = false;
    finished_request_id_ = request_id_;
    enter(BridgeState::Idle, now,
          "done: request " + std::to_string(request_id_) +
              fmt(" played (%.3f s), worst tracking error %.4f rad", d, tracking_error_max_),
          false);
    events_.back().request_id = request_id_;
    events_.back().done = true;
  }
  return sent;
}

std::optional<Command> Bridge::tick(std::int64_t now) {
  if (last_tick_ < 0 || now - last_tick_ > us(1.5 * cfg_.dt)) {
    if (last_tick_ >= 0) ++late_ticks_;
    listening_since_ = now;
  }
  last_tick_ = now;
  // A watchdog fires only after the bridge has been listening on time for
  // its whole timeout: a stall of the bridge (or of the whole machine) is
  // not the robot's silence.
  auto listened = [&](double timeout) { return now - listening_since_ >= us(timeout); };
  switch (state_) {
    case BridgeState::Idle:
      return std::nullopt;
    case BridgeState::Checking:
      // Checking from holding: keep holding meanwhile.
      if (before_check_ == BridgeState::Holding && last_) return holdCommand(now, CommandMode::Hold);
      return std::nullopt;
    case BridgeState::Streaming:
      if (!stateFresh(now) && listened(cfg_.state_timeout)) {
        active_ = false;
        enter(BridgeState::Holding, now,
              measured_ ? fmt("holding: robot state stale (none for %.1f ms, limit %.1f ms)", ms(now - measured_at_),
                              cfg_.state_timeout * 1e3)
                        : std::string("holding: no robot state"),
              true);
        return last_ ? std::optional<Command>(holdCommand(now, CommandMode::Hold)) : std::nullopt;
      }
      if (first_stream_seq_ >= 0 && now - ack_changed_at_ > us(cfg_.stall_timeout) && listened(cfg_.stall_timeout)) {
        active_ = false;
        enter(BridgeState::Holding, now,
              fmt("holding: stream stalled (the controller acknowledged no command for %.1f ms, limit %.1f ms)",
                  ms(now - ack_changed_at_), cfg_.stall_timeout * 1e3),
              true);
        return holdCommand(now, CommandMode::Hold);
      }
      return streamCommand(now);
    case BridgeState::Holding:
    case BridgeState::Fault:
      if (last_) return holdCommand(now, CommandMode::Hold);
      return std::nullopt;
    case BridgeState::Stopped:
      if (last_) return holdCommand(now, CommandMode::Freeze);
      return std::nullopt;
  }
  return std::nullopt;
}

BridgeStatus Bridge::status(std::int64_t now) const {
  BridgeStatus st;
  st.utime = now;
  st.request_id = state_ == BridgeState::Checking ? checking_id_ : request_id_;
  st.state = state_;
  st.reason = reason_;
  st.progress = traj_.duration() > 0 ? std::min(1.0, tau_ / traj_.duration()) : 0.0;
  st.commands_sent = commands_sent_;
  st.tracking_error_max = tracking_error_max_;
  st.tracking_error_last = tracking_error_last_;
  st.safety_events = safety_events_;
  st.state_fresh = stateFresh(now);
  st.finished_request_id = finished_request_id_;
  return st;
}

}  // namespace acyclic::hrp2
