#include "adit/drivers/can/decoder.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>

#include <fmt/format.h>

#include "adit/common/error.hpp"
#include "adit/drivers/can/units.hpp"

namespace adit::drivers::can {
namespace {

bool wanted_match(std::span<const std::string> wanted, const MessageSpec& m, const SignalSpec& s) {
  if (wanted.empty()) return true;
  for (const std::string& w : wanted) {
    if (w == s.name) return true;
    if (w.size() == m.name.size() + 1 + s.name.size() && w.starts_with(m.name) && w[m.name.size()] == '.' &&
        w.ends_with(s.name))
      return true;
  }
  return false;
}

}  // namespace

SignalDecoder::SignalDecoder(std::span<const MessageSpec> messages, std::span<const std::string> wanted, bool to_si)
    : standard_index_(2048, -1) {
  std::vector<bool> used(wanted.size(), false);
  for (const MessageSpec& m : messages) {
    Message out{m.id, m.extended, static_cast<std::uint8_t>(std::min(m.length, 64U)), m.exact_length,
                static_cast<std::uint32_t>(signals_.size()), 0, -1};
    // A wanted multiplexed signal needs its selector decoded too.
    bool wants_multiplexed = false;
    for (const SignalSpec& s : m.signals)
      wants_multiplexed |= s.multiplex == Multiplex::multiplexed && wanted_match(wanted, m, s);
    for (const SignalSpec& s : m.signals) {
      const bool is_wanted = wanted_match(wanted, m, s);
      if (!is_wanted && !(wants_multiplexed && s.multiplex == Multiplex::selector)) continue;
      for (std::size_t i = 0; i < wanted.size(); ++i) used[i] = used[i] || wanted_match(wanted.subspan(i, 1), m, s);
      Layout l;
      l.length = static_cast<std::uint8_t>(std::clamp(s.length, 1U, 64U));
      l.mask = l.length == 64 ? ~0ULL : (1ULL << l.length) - 1;
      l.motorola = s.byte_order == ByteOrder::motorola;
      l.is_signed = s.is_signed;
      l.type = s.type;
      l.multiplex = s.multiplex;
      l.multiplex_value = s.multiplex_value;
      unsigned first = 0;
      unsigned last = 0;
      if (l.motorola) {
        const unsigned msb = (s.start_bit / 8) * 8 + 7 - s.start_bit % 8;  // big-endian bit stream position
        first = msb / 8;
        last = (msb + l.length - 1) / 8;
        l.shift = static_cast<std::uint8_t>(7 - (msb + l.length - 1) % 8);
      } else {
        first = s.start_bit / 8;
        last = (s.start_bit + l.length - 1) / 8;
        l.shift = static_cast<std::uint8_t>(s.start_bit % 8);
      }
      if (last >= out.length || last - first > 8)
        throw InputError(m.name, s.name, fmt::format("signal does not fit the message's {} bytes", out.length));
      l.first_byte = static_cast<std::uint8_t>(first);
      l.last_byte = static_cast<std::uint8_t>(last);
      const SiConversion si = to_si ? si_conversion(s.unit) : SiConversion{1.0, s.unit, false};
      l.factor = s.factor * si.scale;
      l.offset = s.offset * si.scale;
      if (s.multiplex == Multiplex::selector) out.selector = static_cast<int>(layouts_.size());
      layouts_.push_back(l);
      signals_.push_back({m.name, s.name, std::string(si.si_unit), m.id, m.extended});
      ++out.count;
    }
    if (out.count == 0) continue;
    const auto index = static_cast<std::uint32_t>(messages_.size());
    if (m.extended) {
      extended_index_.emplace_back(m.id, index);
    } else if (m.id < standard_index_.size()) {
      standard_index_[m.id] = static_cast<std::int32_t>(index);
    }
    messages_.push_back(out);
  }
  std::sort(extended_index_.begin(), extended_index_.end());
  for (std::size_t i = 0; i < wanted.size(); ++i)
    if (!used[i]) throw InputError("", wanted[i], "no such signal in the message definitions");
}

int SignalDecoder::slot(std::string_view name) const {
  for (std::size_t i = 0; i < signals_.size(); ++i) {
    const DecodedSignal& s = signals_[i];
    if (s.name == name) return static_cast<int>(i);
    if (name.size() == s.message.size() + 1 + s.name.size() && name.starts_with(s.message) &&
        name[s.message.size()] == '.' && name.ends_with(s.name))
      return static_cast<int>(i);
  }
  return -1;
}

const SignalDecoder::Message* SignalDecoder::lookup(const Frame& frame) const {
  if (!frame.extended) {
    const std::int32_t i = frame.id < standard_index_.size() ? standard_index_[frame.id] : -1;
    return i < 0 ? nullptr : &messages_[static_cast<std::size_t>(i)];
  }
  const auto it = std::lower_bound(extended_index_.begin(), extended_index_.end(),
                                   std::pair<std::uint32_t, std::uint32_t>{frame.id, 0});
  return it != extended_index_.end() && it->first == frame.id ? &messages_[it->second] : nullptr;
}

// Gathers bytes first..last (at most 9) into 128 bits, big- or little-endian,
// then shifts the signal down to bit 0.
std::uint64_t SignalDecoder::raw_bits(const Layout& l, const std::uint8_t* data) {
  unsigned __int128 acc = 0;
  if (l.motorola) {
    for (unsigned b = l.first_byte; b <= l.last_byte; ++b) acc = acc << 8 | data[b];
  } else {
    for (unsigned b = l.last_byte + 1; b-- > l.first_byte;) acc = acc << 8 | data[b];
  }
  return static_cast<std::uint64_t>(acc >> l.shift) & l.mask;
}

DecodeResult SignalDecoder::decode(const Frame& frame, std::span<double> values) {
  if (frame.error || frame.remote) {
    ++stats_.not_data;
    return {DecodeStatus::not_data, 0, 0};
  }
  const Message* m = lookup(frame);
  if (m == nullptr) {
    ++stats_.unknown_id;
    return {DecodeStatus::unknown_id, 0, 0};
  }
  if (frame.length < m->length || (m->exact && frame.length != m->length)) {
    ++stats_.wrong_length;
    return {DecodeStatus::wrong_length, m->first, m->count};
  }
  const std::uint64_t selector =
      m->selector >= 0 ? raw_bits(layouts_[static_cast<std::size_t>(m->selector)], frame.data.data()) : 0;
  for (std::uint32_t i = m->first; i < m->first + m->count; ++i) {
    const Layout& l = layouts_[i];
    if (l.multiplex == Multiplex::multiplexed && selector != l.multiplex_value) {
      values[i] = std::numeric_limits<double>::quiet_NaN();
      continue;
    }
    const std::uint64_t raw = raw_bits(l, frame.data.data());
    double v = 0.0;
    if (l.type == ValueType::float32) {
      v = std::bit_cast<float>(static_cast<std::uint32_t>(raw));
    } else if (l.type == ValueType::float64) {
      v = std::bit_cast<double>(raw);
    } else if (l.is_signed && l.length < 64 && (raw >> (l.length - 1)) != 0) {
      v = static_cast<double>(static_cast<std::int64_t>(raw | ~l.mask));  // sign extension
    } else if (l.is_signed) {
      v = static_cast<double>(static_cast<std::int64_t>(raw));
    } else {
      v = static_cast<double>(raw);
    }
    values[i] = v * l.factor + l.offset;
  }
  ++stats_.decoded;
  return {DecodeStatus::decoded, m->first, m->count};
}

}  // namespace adit::drivers::can
