// What acyclic-launch makes of the bridge's status about its request: the
// finished_request_id field, not the wording of the reason.
#include <gtest/gtest.h>

#include "processes/bridge_outcome.h"

using namespace acyclic;
using proc::BridgeOutcome;

namespace {

hrp2_bridge_status_t status(int8_t state, std::int64_t finished, const std::string& reason = "") {
  hrp2_bridge_status_t b{};
  b.request_id = 4;
  b.state = state;
  b.finished_request_id = finished;
  b.reason = reason;
  return b;
}

}  // namespace

TEST(BridgeOutcome, FinishedIsTheFieldNotTheReason) {
  EXPECT_EQ(proc::bridgeOutcome(status(+hrp2_bridge_status_t::IDLE, 4), 4), BridgeOutcome::Finished);
  // Whatever the reason says.
  EXPECT_EQ(proc::bridgeOutcome(status(+hrp2_bridge_status_t::IDLE, 4, "something else"), 4), BridgeOutcome::Finished);
  EXPECT_EQ(proc::bridgeOutcome(status(+hrp2_bridge_status_t::IDLE, -1, "done: request 4 played (1.000 s)"), 4),
            BridgeOutcome::Going);
  // Another request finished: not ours.
  EXPECT_EQ(proc::bridgeOutcome(status(+hrp2_bridge_status_t::IDLE, 3), 4), BridgeOutcome::Going);
  EXPECT_EQ(proc::bridgeOutcome(status(+hrp2_bridge_status_t::STREAMING, 3), 4), BridgeOutcome::Going);
  EXPECT_EQ(proc::bridgeOutcome(status(+hrp2_bridge_status_t::CHECKING, -1), 4), BridgeOutcome::Going);
}

TEST(BridgeOutcome, HoldingFaultStopOrRefusalIsBroken) {
  for (int8_t s : {+hrp2_bridge_status_t::HOLDING, +hrp2_bridge_status_t::FAULT, +hrp2_bridge_status_t::STOPPED})
    EXPECT_EQ(proc::bridgeOutcome(status(s, -1), 4), BridgeOutcome::Broken) << int(s);
  EXPECT_EQ(proc::bridgeOutcome(status(+hrp2_bridge_status_t::IDLE, -1, "refused request 4: limits"), 4),
            BridgeOutcome::Broken);
}
