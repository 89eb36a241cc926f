#pragma once
// One CAN or CAN FD frame as a plain value, the same whether it came from a
// SocketCAN socket or a candump log. Fixed size: no allocation per frame.

#include <algorithm>
#include <array>
#include <cstdint>
#include <string_view>

namespace adit::drivers::can {

inline constexpr std::size_t kMaxClassicLength = 8;
inline constexpr std::size_t kMaxFdLength = 64;
inline constexpr std::size_t kMaxInterfaceName = 15;  // IFNAMSIZ (16) minus the NUL

// CAN FD flags as in linux/can.h (struct canfd_frame::flags).
inline constexpr std::uint8_t kFdBitRateSwitch = 0x01;       // CANFD_BRS
inline constexpr std::uint8_t kFdErrorStateIndicator = 0x02;  // CANFD_ESI

struct Frame {
  std::int64_t time_us = 0;  // receive or log time, microseconds on the source's clock
  std::uint32_t id = 0;      // 11- or 29-bit identifier; for error frames the error class bits
  std::uint8_t length = 0;   // payload bytes (classic 0..8, FD 0..64 in DLC steps)
  std::uint8_t fd_flags = 0;  // kFdBitRateSwitch | kFdErrorStateIndicator (FD only)
  std::uint8_t len8_dlc = 0;  // classic frames with length 8: the raw DLC 9..15 when sent so
  bool extended = false;      // 29-bit identifier
  bool remote = false;        // RTR: no payload, `length` is the requested length
  bool error = false;         // SocketCAN error frame (CAN_ERR_FLAG)
  bool fd = false;            // CAN FD frame
  std::array<char, kMaxInterfaceName + 1> interface{};  // NUL-terminated, e.g. "can0"
  std::array<std::uint8_t, kMaxFdLength> data{};

  std::string_view interface_name() const { return std::string_view(interface.data()); }
  // Copies at most kMaxInterfaceName characters; false if `name` had to be cut.
  bool set_interface_name(std::string_view name) {
    const std::size_t n = std::min(name.size(), kMaxInterfaceName);
    std::copy_n(name.data(), n, interface.data());
    interface[n] = '\0';
    return n == name.size();
  }
  std::uint8_t payload(std::size_t i) const { return data[i]; }
};

// Equal in everything that is carried, payload compared up to `length`.
inline bool operator==(const Frame& a, const Frame& b) {
  return a.time_us == b.time_us && a.id == b.id && a.length == b.length && a.fd_flags == b.fd_flags &&
         a.len8_dlc == b.len8_dlc && a.extended == b.extended && a.remote == b.remote && a.error == b.error &&
         a.fd == b.fd && a.interface_name() == b.interface_name() &&
         (a.remote || std::equal(a.data.begin(), a.data.begin() + a.length, b.data.begin()));
}

// CAN FD payload lengths (ISO 11898-1:2015, DLC 9..15 map to 12..64 bytes).
inline constexpr bool is_valid_fd_length(std::size_t n) {
  return n <= 8 || n == 12 || n == 16 || n == 20 || n == 24 || n == 32 || n == 48 || n == 64;
}

}  // namespace adit::drivers::can
