#pragma once
// Pcap replay at a chosen pace: as fast as possible (speed 0) or at `speed`
// times the recorded rate, each datagram released when its capture time,
// scaled from the first one, comes due on CLOCK_MONOTONIC (absolute sleeps, so
// delays do not accumulate).

#include <cstdint>
#include <filesystem>
#include <optional>

#include "adit/drivers/pcap_reader.hpp"

namespace adit::drivers {

class PacedPcapReader {
 public:
  // speed ≤ 0: no pacing. Throws adit::InputError as PcapReader does.
  PacedPcapReader(const std::filesystem::path& file, double speed);

  // The next datagram, once it is due; false at the end of the capture.
  bool next(UdpDatagram& out);
  const PcapStats& stats() const { return reader_.stats(); }
  // How late the latest datagram was released, ns (scheduling and I/O lag).
  std::int64_t last_lateness_ns() const { return lateness_ns_; }

 private:
  PcapReader reader_;
  double speed_;
  std::optional<std::int64_t> first_capture_ns_;
  std::int64_t start_monotonic_ns_ = 0;
  std::int64_t lateness_ns_ = 0;
};

}  // namespace adit::drivers
