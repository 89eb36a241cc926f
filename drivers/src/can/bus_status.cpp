#include "adit/drivers/can/bus_status.hpp"

#include <linux/can/error.h>

namespace adit::drivers::can {

std::string_view bus_state_name(BusState state) {
  switch (state) {
    case BusState::ok: return "ok";
    case BusState::warning: return "warning";
    case BusState::error_passive: return "error-passive";
    case BusState::bus_off: return "bus-off";
  }
  return "unknown";
}

void BusMonitor::enter(BusState next) {
  if (next == state_) return;
  if (next == BusState::bus_off) ++counters_.bus_off;
  if (next == BusState::error_passive) ++counters_.error_passive;
  if (next == BusState::ok && (state_ == BusState::bus_off || state_ == BusState::error_passive)) ++counters_.recoveries;
  state_ = next;
}

BusState BusMonitor::on_frame(const Frame& f) {
  if (!f.error) {
    // Frames arriving again after bus-off: the controller is back on the bus
    // (some drivers restart automatically without a CAN_ERR_RESTARTED frame).
    if (state_ == BusState::bus_off) enter(BusState::ok);
    return state_;
  }
  ++counters_.error_frames;
  const std::uint32_t cls = f.id;
  const std::uint8_t ctrl = f.length > 1 ? f.data[1] : 0;
  if (cls & CAN_ERR_TX_TIMEOUT) ++counters_.tx_timeouts;
  if (cls & CAN_ERR_PROT) ++counters_.protocol;
  if (cls & CAN_ERR_ACK) ++counters_.no_ack;
  if (cls & CAN_ERR_CRTL) {
    ++counters_.controller;
    if (ctrl & (CAN_ERR_CRTL_RX_OVERFLOW | CAN_ERR_CRTL_TX_OVERFLOW)) ++counters_.controller_overflows;
  }
  if (cls & CAN_ERR_BUSOFF) {
    enter(BusState::bus_off);
  } else if (cls & CAN_ERR_RESTARTED) {
    enter(BusState::ok);
  } else if (cls & CAN_ERR_CRTL) {
    if (ctrl & CAN_ERR_CRTL_ACTIVE) {
      enter(BusState::ok);
    } else if (ctrl & (CAN_ERR_CRTL_RX_PASSIVE | CAN_ERR_CRTL_TX_PASSIVE)) {
      if (state_ != BusState::bus_off) enter(BusState::error_passive);
    } else if (ctrl & (CAN_ERR_CRTL_RX_WARNING | CAN_ERR_CRTL_TX_WARNING)) {
      if (state_ == BusState::ok) enter(BusState::warning);
    }
  }
  return state_;
}

}  // namespace adit::drivers::can
