#pragma once
// Sending a capture's UDP payloads to a host and port at a chosen pace: the
// work of `adit pcap-send`, also the traffic source of `adit bench pipeline`.

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <string>

namespace adit::tools {

struct SendTotals {
  std::uint64_t sent = 0;
  std::uint64_t refused = 0;  // the kernel did not take the datagram
};

// `speed` is × the recorded rate, 0 = as fast as possible; `only_port` > 0
// keeps the datagrams that were sent to that port. Stops early when `stop`
// becomes true. Throws adit::InputError for a bad file or host.
SendTotals send_capture(const std::filesystem::path& file, const std::string& host, std::uint16_t port, double speed,
                        int only_port, const std::atomic<bool>& stop);

}  // namespace adit::tools
