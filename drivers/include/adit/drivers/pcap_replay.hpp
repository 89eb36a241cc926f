#pragma once
// Pcap replay at a chosen pace: as fast as possible (speed 0) or at `speed`
// times the recorded rate, each datagram released when its capture time,
// scaled from the first one, comes due on CLOCK_MONOTONIC (sleeping until that
// instant, so delays do not accumulate).
//
// A recording in parts (aditd's, session.record_part_mb) is one capture:
// X.pcap goes on in X.1.pcap, X.2.pcap, ... (pcap_part()), read in turn.

#include <cstdint>
#include <filesystem>
#include <limits>
#include <optional>

#include "adit/drivers/pcap_reader.hpp"

namespace adit::drivers {

// Part `index` of a recording that starts with `first`: the first itself for
// 0, else its name with ".<index>" before the extension (lidar.1.pcap).
std::filesystem::path pcap_part(const std::filesystem::path& first, int index);

class PacedPcapReader {
 public:
  // speed ≤ 0: no pacing. Throws adit::InputError as PcapReader does.
  // A reader held up by more than max_catch_up_ns (a descheduled thread)
  // resumes the recorded pace from where it is instead of releasing the
  // overdue datagrams at once: a sensor never bursts, and a burst can
  // overflow a receiver's socket buffer that the steady stream would not.
  // The default catches up however late it is (a file replay's duration
  // stays the recording's over the speed).
  PacedPcapReader(const std::filesystem::path& file, double speed,
                  std::int64_t max_catch_up_ns = std::numeric_limits<std::int64_t>::max());

  // The next datagram, once it is due; false at the end of the capture.
  bool next(UdpDatagram& out);
  // Totals over the parts read so far.
  PcapStats stats() const;
  int parts() const { return part_ + 1; }
  // How late the latest datagram was released, ns (scheduling and I/O lag).
  std::int64_t last_lateness_ns() const { return lateness_ns_; }

 private:
  PcapReader reader_;
  std::filesystem::path first_;
  int part_ = 0;
  PcapStats earlier_parts_;
  double speed_;
  std::int64_t max_catch_up_ns_;
  std::optional<std::int64_t> first_capture_ns_;
  std::int64_t start_monotonic_ns_ = 0;
  std::int64_t lateness_ns_ = 0;
};

}  // namespace adit::drivers
