#include "adit/drivers/can/presets.hpp"

#include "adit/drivers/can/frame.hpp"

#include <algorithm>
#include <stdexcept>

#include <fmt/format.h>

namespace adit::drivers::can {
namespace {

SignalSpec little_endian(std::string name, unsigned start, unsigned length, bool is_signed, ValueType type,
                         std::string unit) {
  SignalSpec s;
  s.name = std::move(name);
  s.start_bit = start;
  s.length = length;
  s.byte_order = ByteOrder::intel;
  s.is_signed = is_signed;
  s.type = type;
  s.unit = std::move(unit);
  return s;
}

}  // namespace

MessageSpec canopen_tpdo_position_velocity(unsigned node_id, unsigned pdo, const std::string& prefix,
                                           const std::string& velocity_unit) {
  if (node_id < 1 || node_id > 127) throw std::invalid_argument(fmt::format("CANopen node id {} not in 1..127", node_id));
  if (pdo < 1 || pdo > 4) throw std::invalid_argument(fmt::format("CANopen TPDO {} not in 1..4", pdo));
  MessageSpec m;
  m.id = 0x080U + 0x100U * pdo + node_id;
  m.name = fmt::format("{}TPDO{}_NODE{}", prefix, pdo, node_id);
  m.length = 8;
  m.signals.push_back(little_endian(prefix + "position", 0, 32, true, ValueType::integer, "counts"));
  m.signals.push_back(little_endian(prefix + "velocity", 32, 32, true, ValueType::integer, velocity_unit));
  return m;
}

void add_inline_signal(std::vector<MessageSpec>& messages, std::uint32_t id, bool extended, SignalSpec s) {
  if (id > (extended ? 0x1FFFFFFFU : 0x7FFU))
    throw std::invalid_argument(fmt::format("signal {}: id {:#x} out of range", s.name, id));
  if (s.length < 1 || s.length > 64)
    throw std::invalid_argument(fmt::format("signal {}: length {} not in 1..64", s.name, s.length));
  if ((s.type == ValueType::float32 && s.length != 32) || (s.type == ValueType::float64 && s.length != 64))
    throw std::invalid_argument(fmt::format("signal {}: a float needs 32 or 64 bits", s.name));
  unsigned last = 0;
  if (s.byte_order == ByteOrder::intel) {
    last = (s.start_bit + s.length - 1) / 8;
  } else {
    last = ((s.start_bit / 8) * 8 + 7 - s.start_bit % 8 + s.length - 1) / 8;
  }
  if (last >= 64) throw std::invalid_argument(fmt::format("signal {}: does not fit 64 bytes", s.name));
  auto it = std::find_if(messages.begin(), messages.end(),
                         [&](const MessageSpec& m) { return m.id == id && m.extended == extended; });
  if (it == messages.end()) {
    MessageSpec m;
    m.id = id;
    m.extended = extended;
    m.name = fmt::format("{}{:X}", extended ? "ID_X" : "ID_", id);
    m.length = 0;
    m.exact_length = false;
    messages.push_back(std::move(m));
    it = messages.end() - 1;
  }
  // FD frames come in DLC steps; round the minimum up to one.
  unsigned need = last + 1;
  while (!is_valid_fd_length(need)) ++need;
  it->length = std::max(it->length, need);
  it->signals.push_back(std::move(s));
}

MessageSpec odrive_encoder_estimates(unsigned node_id, const std::string& prefix) {
  if (node_id > 0x3F) throw std::invalid_argument(fmt::format("ODrive node id {} not in 0..63", node_id));
  MessageSpec m;
  m.id = node_id << 5 | 0x009U;
  m.name = fmt::format("{}ODRIVE{}_ENCODER_ESTIMATES", prefix, node_id);
  m.length = 8;
  m.signals.push_back(little_endian(prefix + "pos_estimate", 0, 32, false, ValueType::float32, "turns"));
  m.signals.push_back(little_endian(prefix + "vel_estimate", 32, 32, false, ValueType::float32, "turns/s"));
  return m;
}

}  // namespace adit::drivers::can
