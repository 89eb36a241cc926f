#pragma once
// Sending a capture's UDP payloads to a host and port at a chosen pace: the
// work of `adit pcap-send`, also the traffic source of `adit bench pipeline`.

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>

namespace adit::tools {

struct SendTotals {
  std::uint64_t sent = 0;
  std::uint64_t refused = 0;  // the kernel did not take the datagram
};

// Where the datagrams recorded to one port go: `from_port` ≤ 0 takes every datagram.
struct SendRoute {
  int from_port = 0;
  std::uint16_t to_port = 0;
};

// `speed` is × the recorded rate, 0 = as fast as possible. Each datagram goes
// to the first route that takes its recorded port (none: not sent), all at
// the one recorded pace (a LiDAR's data and IMU packets keep their order).
// Stops early when `stop` becomes true. Throws adit::InputError for a bad
// file or host.
SendTotals send_capture(const std::filesystem::path& file, const std::string& host, std::span<const SendRoute> routes,
                        double speed, const std::atomic<bool>& stop);

}  // namespace adit::tools
