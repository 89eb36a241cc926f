#pragma once
// The bus's health from SocketCAN error frames (linux/can/error.h): the error
// class bits in the id and controller details in data[1]. Bus-off is a fault;
// it clears when the controller reports a restart or error-active again, or
// when data frames arrive again (the bus came back).

#include <cstdint>
#include <string_view>

#include "adit/drivers/can/frame.hpp"

namespace adit::drivers::can {

enum class BusState : std::uint8_t { ok, warning, error_passive, bus_off };
std::string_view bus_state_name(BusState state);

struct BusCounters {
  std::uint64_t error_frames = 0;
  std::uint64_t bus_off = 0;          // transitions into bus-off
  std::uint64_t error_passive = 0;    // transitions into error-passive
  std::uint64_t recoveries = 0;       // transitions back to ok from error-passive or bus-off
  std::uint64_t controller = 0;       // CAN_ERR_CRTL frames (incl. controller buffer overflows)
  std::uint64_t protocol = 0;         // CAN_ERR_PROT
  std::uint64_t no_ack = 0;           // CAN_ERR_ACK
  std::uint64_t tx_timeouts = 0;      // CAN_ERR_TX_TIMEOUT
  std::uint64_t controller_overflows = 0;  // CAN_ERR_CRTL_RX/TX_OVERFLOW
};

class BusMonitor {
 public:
  // Feed every frame (error and data); returns the state after it.
  BusState on_frame(const Frame& frame);
  BusState state() const { return state_; }
  bool fault() const { return state_ == BusState::bus_off; }
  const BusCounters& counters() const { return counters_; }

 private:
  void enter(BusState next);
  BusState state_ = BusState::ok;
  BusCounters counters_;
};

}  // namespace adit::drivers::can
