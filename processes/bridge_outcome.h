#pragma once
// What a caller that sent one trajectory makes of the bridge's status about
// it (acyclic-launch --execute): played to the end when the status's
// finished_request_id is that request (a field, not the wording of the
// human-readable reason); broken when the bridge holds, faults, is stopped
// by an e-stop or refused the request (it then waits for an operator, which
// a launcher is not); else still going.
#include <cstdint>

#include "acyclic/hrp2_bridge_status_t.hpp"

namespace acyclic::proc {

enum class BridgeOutcome { Going, Finished, Broken };

inline BridgeOutcome bridgeOutcome(const hrp2_bridge_status_t& b, std::int64_t request_id) {
  if (b.finished_request_id == request_id) return BridgeOutcome::Finished;
  const bool refused = b.reason.rfind("refused", 0) == 0;  // a refusal has no field of its own
  if (b.state == hrp2_bridge_status_t::FAULT || b.state == hrp2_bridge_status_t::STOPPED ||
      b.state == hrp2_bridge_status_t::HOLDING || refused)
    return BridgeOutcome::Broken;
  return BridgeOutcome::Going;
}

}  // namespace acyclic::proc
