#pragma once
// Message definitions for two common wheel-encoder interfaces (and
// add_inline_signal, declared in signal.hpp, for signals written in the config), so a config
// can say "canopen node 3" instead of spelling out bit layouts.

#include <cstdint>
#include <string>

#include "adit/drivers/can/signal.hpp"

namespace adit::drivers::can {

// CANopen transmit PDO carrying a CiA 402 drive's "position actual value"
// (object 0x6064, INTEGER32, encoder counts) in bytes 0..3 and "velocity actual
// value" (0x606C, INTEGER32) in bytes 4..7, little endian (CiA 301 §7.1).
// COB-ID of TPDO n (1..4) is 0x080 + n * 0x100 + node (CiA 301 pre-defined
// connection set: 0x180, 0x280, 0x380, 0x480). `velocity_unit` is what the
// drive is configured to send (often "counts/s" or "rpm").
// Signals: "<prefix>position" and "<prefix>velocity".
MessageSpec canopen_tpdo_position_velocity(unsigned node_id, unsigned pdo = 1, const std::string& prefix = "",
                                           const std::string& velocity_unit = "counts/s");

// ODrive CAN Simple protocol: arbitration id = node_id << 5 | command; command
// 0x009 Get_Encoder_Estimates carries Pos_Estimate (float32, turns) in bytes
// 0..3 and Vel_Estimate (float32, turns/s) in bytes 4..7, little endian.
// Signals: "<prefix>pos_estimate" (rad after SI conversion), "<prefix>vel_estimate" (rad/s).
MessageSpec odrive_encoder_estimates(unsigned node_id, const std::string& prefix = "");

}  // namespace adit::drivers::can
