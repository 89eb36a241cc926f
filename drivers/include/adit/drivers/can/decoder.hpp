#pragma once
// Decoding selected signals out of frames. All lookups and bit layouts are
// prepared at construction; decode() allocates nothing and never throws.

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "adit/drivers/can/frame.hpp"
#include "adit/drivers/can/signal.hpp"

namespace adit::drivers::can {

struct DecodedSignal {
  std::string message;
  std::string name;
  std::string unit;  // SI unit after conversion (or the DBC unit when unknown)
  std::uint32_t id = 0;
  bool extended = false;
};

enum class DecodeStatus : std::uint8_t {
  decoded,       // the slots [first, first + count) were written
  unknown_id,    // no selected signal in this message: ignored, counted
  wrong_length,  // known id, payload length differs from the message's (or is below an inline minimum): counted, not decoded
  not_data,      // error or remote frame
};

struct DecodeResult {
  DecodeStatus status = DecodeStatus::unknown_id;
  std::uint32_t first = 0;  // first output slot of this message's signals
  std::uint32_t count = 0;
};

struct DecoderStats {
  std::uint64_t decoded = 0;
  std::uint64_t unknown_id = 0;
  std::uint64_t wrong_length = 0;
  std::uint64_t not_data = 0;
};

class SignalDecoder {
 public:
  // `wanted` lists signal names ("NAME" or "MESSAGE.NAME"); empty means every
  // signal. Throws adit::InputError when a wanted name matches nothing.
  // With `to_si`, values are converted by units.hpp (km/h -> m/s, ...).
  SignalDecoder(std::span<const MessageSpec> messages, std::span<const std::string> wanted = {}, bool to_si = true);

  // One slot per selected signal, grouped by message, in this order.
  const std::vector<DecodedSignal>& signals() const { return signals_; }
  std::size_t slot_count() const { return signals_.size(); }
  // The slot of "NAME" or "MESSAGE.NAME"; -1 if absent.
  int slot(std::string_view name) const;

  // Writes this frame's signals into `values` (size slot_count()). A
  // multiplexed signal whose selector does not match is written as NaN.
  DecodeResult decode(const Frame& frame, std::span<double> values);
  const DecoderStats& stats() const { return stats_; }

 private:
  struct Layout {
    std::uint64_t mask = 0;
    std::uint8_t first_byte = 0;
    std::uint8_t last_byte = 0;
    std::uint8_t shift = 0;  // right shift after assembling first..last
    std::uint8_t length = 0;
    bool motorola = false;
    bool is_signed = false;
    ValueType type = ValueType::integer;
    Multiplex multiplex = Multiplex::none;
    std::uint32_t multiplex_value = 0;
    double factor = 1.0;  // including the SI scale
    double offset = 0.0;
  };
  struct Message {
    std::uint32_t id = 0;
    bool extended = false;
    std::uint8_t length = 0;
    bool exact = true;  // else `length` is a minimum
    std::uint32_t first = 0;
    std::uint32_t count = 0;
    int selector = -1;  // index into layouts_ of the multiplexer signal, if any
  };
  static std::uint64_t raw_bits(const Layout& l, const std::uint8_t* data);
  const Message* lookup(const Frame& frame) const;

  std::vector<DecodedSignal> signals_;
  std::vector<Layout> layouts_;  // parallel to signals_
  std::vector<Message> messages_;
  std::vector<std::int32_t> standard_index_;  // 2048 entries: 11-bit id -> messages_ index or -1
  std::vector<std::pair<std::uint32_t, std::uint32_t>> extended_index_;  // sorted (id, messages_ index)
  DecoderStats stats_;
};

}  // namespace adit::drivers::can
