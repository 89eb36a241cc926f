// candump -L reading and writing; see candump.hpp for the format.

#include "adit/drivers/can/candump.hpp"

#include <fmt/format.h>

#include "adit/common/error.hpp"

namespace adit::drivers::can {
namespace {

constexpr std::uint32_t kErrFlag = 0x20000000U;  // CAN_ERR_FLAG, linux/can.h
constexpr std::uint32_t kSffMask = 0x7FFU;       // CAN_SFF_MASK
constexpr std::uint32_t kEffMask = 0x1FFFFFFFU;  // CAN_EFF_MASK (also CAN_ERR_MASK)
constexpr std::uint8_t kErrorFrameLength = 8;    // CAN_ERR_DLC

int hex_value(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  return -1;
}

constexpr char kHex[] = "0123456789ABCDEF";

// Reads hex byte pairs (optionally '.'-separated) from `s` into `out`.
LineError parse_data(std::string_view& s, std::uint8_t* out, std::size_t max, std::uint8_t& length) {
  std::size_t n = 0;
  while (!s.empty() && s.front() != '_' && s.front() != ' ' && s.front() != '\t') {
    if (s.front() == '.') {
      s.remove_prefix(1);
      continue;
    }
    if (s.size() < 2) return LineError::data;
    const int hi = hex_value(s[0]);
    const int lo = hex_value(s[1]);
    if (hi < 0 || lo < 0) return LineError::data;
    if (n == max) return LineError::length;
    out[n++] = static_cast<std::uint8_t>(hi << 4 | lo);
    s.remove_prefix(2);
  }
  length = static_cast<std::uint8_t>(n);
  return LineError::none;
}

}  // namespace

std::string_view describe(LineError error) {
  switch (error) {
    case LineError::none: return "ok";
    case LineError::timestamp: return "missing or malformed timestamp \"(seconds.fraction)\"";
    case LineError::interface: return "missing interface name, or longer than 15 characters";
    case LineError::identifier: return "identifier is not 3 or 8 hex digits in range";
    case LineError::separator: return "no '#' after the identifier";
    case LineError::data: return "data is not pairs of hex digits";
    case LineError::length: return "too many data bytes, or a length no DLC encodes";
    case LineError::trailing: return "unexpected text after the frame";
  }
  return "unknown";
}

LineError parse_candump_line(std::string_view s, Frame& out) {
  while (!s.empty() && (s.back() == '\r' || s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  out = Frame{};

  // "(seconds.fraction)": fraction of 1..9 digits, kept to microseconds.
  if (s.empty() || s.front() != '(') return LineError::timestamp;
  s.remove_prefix(1);
  std::int64_t seconds = 0;
  std::size_t digits = 0;
  while (!s.empty() && s.front() >= '0' && s.front() <= '9') {
    if (++digits > 12) return LineError::timestamp;
    seconds = seconds * 10 + (s.front() - '0');
    s.remove_prefix(1);
  }
  if (digits == 0 || s.empty() || s.front() != '.') return LineError::timestamp;
  s.remove_prefix(1);
  std::int64_t micros = 0;
  digits = 0;
  while (!s.empty() && s.front() >= '0' && s.front() <= '9') {
    if (++digits > 9) return LineError::timestamp;
    if (digits <= 6) micros = micros * 10 + (s.front() - '0');
    s.remove_prefix(1);
  }
  if (digits == 0 || s.empty() || s.front() != ')') return LineError::timestamp;
  for (std::size_t d = digits; d < 6; ++d) micros *= 10;
  out.time_us = seconds * 1'000'000 + micros;
  s.remove_prefix(1);

  // " name "
  if (s.empty() || s.front() != ' ') return LineError::interface;
  while (!s.empty() && s.front() == ' ') s.remove_prefix(1);
  const std::size_t name_end = s.find_first_of(" \t");
  if (name_end == 0 || name_end == std::string_view::npos) return LineError::interface;
  const std::string_view name = s.substr(0, name_end);
  // Interface names are printable (Linux dev_valid_name also forbids '/' and ':').
  for (const char c : name)
    if (c <= ' ' || c > '~' || c == '/' || c == ':') return LineError::interface;
  if (!out.set_interface_name(name)) return LineError::interface;
  s.remove_prefix(name_end);
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);

  // identifier: 3 hex digits (standard) or 8 (extended, or error with CAN_ERR_FLAG)
  std::uint32_t id = 0;
  std::size_t id_digits = 0;
  while (!s.empty() && s.front() != '#') {
    const int v = hex_value(s.front());
    if (v < 0 || ++id_digits > 8) return LineError::identifier;
    id = id << 4 | static_cast<std::uint32_t>(v);
    s.remove_prefix(1);
  }
  if (s.empty()) return id_digits == 3 || id_digits == 8 ? LineError::separator : LineError::identifier;
  s.remove_prefix(1);  // '#'
  if (id_digits == 3) {
    if (id > kSffMask) return LineError::identifier;
    out.id = id;
  } else if (id_digits == 8) {
    if ((id & ~(kEffMask | kErrFlag)) != 0) return LineError::identifier;
    out.error = (id & kErrFlag) != 0;
    out.extended = !out.error;
    out.id = id & kEffMask;
  } else {
    return LineError::identifier;
  }

  if (!s.empty() && s.front() == '#') {  // CAN FD
    if (out.error) return LineError::identifier;
    s.remove_prefix(1);
    if (s.empty()) return LineError::data;
    const int flags = hex_value(s.front());
    if (flags < 0) return LineError::data;
    s.remove_prefix(1);
    out.fd = true;
    out.fd_flags = static_cast<std::uint8_t>(flags & (kFdBitRateSwitch | kFdErrorStateIndicator));
    if (const LineError e = parse_data(s, out.data.data(), kMaxFdLength, out.length); e != LineError::none) return e;
    if (!is_valid_fd_length(out.length)) return LineError::length;
  } else if (!s.empty() && (s.front() == 'R' || s.front() == 'r')) {  // remote
    if (out.error) return LineError::identifier;
    s.remove_prefix(1);
    out.remote = true;
    if (!s.empty() && s.front() >= '0' && s.front() <= '8') {
      out.length = static_cast<std::uint8_t>(s.front() - '0');
      s.remove_prefix(1);
    }
  } else {
    if (const LineError e = parse_data(s, out.data.data(), kMaxClassicLength, out.length); e != LineError::none) return e;
    if (out.error && out.length != kErrorFrameLength) return LineError::length;
  }
  // Optional "_D": raw DLC 9..F of a classic 8-byte frame (len8_dlc).
  if (!s.empty() && s.front() == '_') {
    if (out.fd || out.length != 8 || s.size() < 2) return LineError::length;
    const int dlc = hex_value(s[1]);
    if (dlc < 9) return LineError::length;
    out.len8_dlc = static_cast<std::uint8_t>(dlc);
    s.remove_prefix(2);
  }
  if (!s.empty()) return LineError::trailing;
  return LineError::none;
}

std::size_t format_candump_line(const Frame& f, std::span<char> out) {
  char* p = out.data();
  const auto r = fmt::format_to_n(p, out.size(), "({}.{:06d}) {} ", f.time_us / 1'000'000, f.time_us % 1'000'000,
                                  f.interface_name());
  p += r.size;
  auto put_hex = [&p](std::uint32_t v, int digits) {
    for (int i = digits - 1; i >= 0; --i) *p++ = kHex[(v >> (4 * i)) & 0xF];
  };
  if (f.error) {
    put_hex(f.id | kErrFlag, 8);
  } else {
    put_hex(f.id, f.extended ? 8 : 3);
  }
  *p++ = '#';
  if (f.fd) {
    *p++ = '#';
    *p++ = kHex[f.fd_flags & 0xF];
  } else if (f.remote) {
    *p++ = 'R';
    if (f.length > 0) *p++ = static_cast<char>('0' + std::min<std::uint8_t>(f.length, 8));
  }
  if (!f.remote) {
    const std::size_t n = std::min<std::size_t>(f.length, f.fd ? kMaxFdLength : kMaxClassicLength);
    for (std::size_t i = 0; i < n; ++i) put_hex(f.data[i], 2);
  }
  // The raw DLC 9..F of an 8-byte classic frame, remote ones included (as
  // can-utils' sprint_canframe writes "R8_F"); found by fuzz_candump.
  if (!f.fd && f.length == 8 && f.len8_dlc > 8) {
    *p++ = '_';
    *p++ = kHex[f.len8_dlc & 0xF];
  }
  return static_cast<std::size_t>(p - out.data());
}

std::string to_candump_line(const Frame& frame) {
  std::array<char, kMaxCandumpLine> buffer{};
  return std::string(buffer.data(), format_candump_line(frame, buffer));
}

CandumpReader::CandumpReader(const std::filesystem::path& file) : file_(file), in_(file) {
  if (!in_) throw InputError(file.string(), "", "cannot open candump log");
  line_.reserve(kMaxCandumpLine);
}

bool CandumpReader::next(Frame& out) {
  while (std::getline(in_, line_)) {
    ++stats_.lines;
    if (line_.empty() || line_ == "\r") {
      ++stats_.blank;
      continue;
    }
    const LineError e = parse_candump_line(line_, out);
    if (e == LineError::none) {
      ++stats_.frames;
      return true;
    }
    ++stats_.malformed;
    if (errors_.size() < kKeptErrors) errors_.push_back({static_cast<std::size_t>(stats_.lines), e});
  }
  return false;
}

std::string CandumpReader::describe(const MalformedLine& error) const {
  return fmt::format("{}:{}: {}", file_.string(), error.line, can::describe(error.error));
}

CandumpWriter::CandumpWriter(const std::filesystem::path& file) : file_(file), out_(file, std::ios::binary) {
  if (!out_) throw InputError(file.string(), "", "cannot create candump log");
}

void CandumpWriter::write(const Frame& frame) {
  std::array<char, kMaxCandumpLine + 1> buffer{};
  const std::size_t n = format_candump_line(frame, buffer);
  buffer[n] = '\n';
  out_.write(buffer.data(), static_cast<std::streamsize>(n + 1));
}

void CandumpWriter::flush() { out_.flush(); }

}  // namespace adit::drivers::can
