#pragma once
// Where a signal sits in a CAN payload and how raw bits become a value, as in
// a DBC file (Vector's format: SG_ lines) or written inline in the config.
// Plain value structs with defaults; the YAML `can:` section binds to them.

#include <cstdint>
#include <string>
#include <vector>

namespace adit::drivers::can {

enum class ByteOrder : std::uint8_t {
  intel,     // DBC "@1": little endian, start bit is the least significant bit
  motorola,  // DBC "@0": big endian, start bit is the most significant bit
};

enum class ValueType : std::uint8_t {
  integer,  // raw bits, unsigned or two's complement
  float32,  // IEEE 754 single (DBC SIG_VALTYPE_ 1), length must be 32
  float64,  // IEEE 754 double (DBC SIG_VALTYPE_ 2), length must be 64
};

enum class Multiplex : std::uint8_t {
  none,
  selector,     // DBC "M": its raw value says which multiplexed signals are present
  multiplexed,  // DBC "mN": present only when the selector's raw value is N
};

struct SignalSpec {
  std::string name;
  unsigned start_bit = 0;  // DBC bit numbering: byte * 8 + bit in byte (bit 0 = LSB)
  unsigned length = 1;     // bits, 1..64
  ByteOrder byte_order = ByteOrder::intel;
  bool is_signed = false;
  ValueType type = ValueType::integer;
  double factor = 1.0;  // physical = raw * factor + offset, in `unit`
  double offset = 0.0;
  double minimum = 0.0;  // DBC [min|max]; informational (both 0 means unspecified)
  double maximum = 0.0;
  std::string unit;  // e.g. "km/h"; decoded values are converted to SI (units.hpp)
  Multiplex multiplex = Multiplex::none;
  unsigned multiplex_value = 0;  // for Multiplex::multiplexed
};

struct MessageSpec {
  std::uint32_t id = 0;
  bool extended = false;  // 29-bit identifier
  std::string name;
  unsigned length = 8;  // expected payload length (DLC); frames of other lengths are counted, not decoded
  bool exact_length = true;  // false: `length` is a minimum (inline signals), longer frames decode too
  std::vector<SignalSpec> signals;
};

// Signals written inline in the config carry their own id; this groups them
// into messages whose minimum length covers every signal. Throws
// std::invalid_argument naming the signal when it cannot fit a CAN FD frame.
void add_inline_signal(std::vector<MessageSpec>& messages, std::uint32_t id, bool extended, SignalSpec signal);

}  // namespace adit::drivers::can
