#pragma once
// can-utils' candump log format (`candump -L`, read back by canplayer):
//   (1700000000.123456) can0 123#DEADBEEF        classic, 3 hex digits = 11-bit id
//   (1700000000.123456) can0 1ABCDEF0#00         8 hex digits = 29-bit id
//   (1700000000.123456) can0 123#R  123#R4       remote frame, optional length
//   (1700000000.123456) can0 123##1DEADBEEF      CAN FD: one hex digit of flags, then data
//   (1700000000.123456) can0 20000004#0004...    error frame: CAN_ERR_FLAG in an 8-digit id
//   (1700000000.123456) can0 123#1122334455667788_C   classic 8 bytes sent with raw DLC 12
// Layout as written by can-utils lib.c (sprint_canframe) and parsed by
// parse_canframe; data bytes may be separated by '.' when reading.
// Writing then reading gives the same Frame; reading then writing a line in
// the canonical form (upper-case hex, 6 fraction digits) gives the same text.

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "adit/drivers/can/frame.hpp"

namespace adit::drivers::can {

enum class LineError : std::uint8_t {
  none,
  timestamp,   // missing or malformed "(seconds.fraction)"
  interface,   // missing interface name, or longer than 15 characters
  identifier,  // not 3 or 8 hex digits, or out of range
  separator,   // no '#' after the identifier
  data,        // odd number of hex digits or a non-hex character
  length,      // too many bytes, or an FD length that no DLC encodes
  trailing,    // unexpected text after the frame
};
std::string_view describe(LineError error);

// Parses one line (without its newline; a trailing '\r' or spaces are ignored).
// Allocation-free; `out` is fully overwritten on success.
LineError parse_candump_line(std::string_view line, Frame& out);

// Longest line the writer produces: timestamp, name, "12345678##F" and 128 hex digits.
inline constexpr std::size_t kMaxCandumpLine = 32 + kMaxInterfaceName + 12 + 2 * kMaxFdLength;

// Writes the line (no newline) into `out` (at least kMaxCandumpLine bytes); returns its length.
std::size_t format_candump_line(const Frame& frame, std::span<char> out);
std::string to_candump_line(const Frame& frame);

struct MalformedLine {
  std::size_t line = 0;
  LineError error = LineError::none;
};

struct CandumpStats {
  std::uint64_t lines = 0;
  std::uint64_t frames = 0;
  std::uint64_t blank = 0;      // empty lines (skipped, not errors)
  std::uint64_t malformed = 0;  // skipped; the first few are kept in errors()
};

// Reads a log line by line (streaming, one reused buffer). Malformed lines are
// counted and skipped; the first kKeptErrors are kept with their line numbers.
class CandumpReader {
 public:
  static constexpr std::size_t kKeptErrors = 20;
  // Throws adit::InputError naming the file when it cannot be opened.
  explicit CandumpReader(const std::filesystem::path& file);

  bool next(Frame& out);
  const CandumpStats& stats() const { return stats_; }
  const std::vector<MalformedLine>& errors() const { return errors_; }
  // "file:line: reason" for a kept error, for messages to the user.
  std::string describe(const MalformedLine& error) const;
  const std::filesystem::path& file() const { return file_; }

 private:
  std::filesystem::path file_;
  std::ifstream in_;
  std::string line_;
  CandumpStats stats_;
  std::vector<MalformedLine> errors_;
};

// Appends frames to a log in the canonical form. Buffered; flushes on destruction.
class CandumpWriter {
 public:
  // Throws adit::InputError naming the file when it cannot be created.
  explicit CandumpWriter(const std::filesystem::path& file);
  void write(const Frame& frame);
  void flush();

 private:
  std::filesystem::path file_;
  std::ofstream out_;
};

}  // namespace adit::drivers::can
