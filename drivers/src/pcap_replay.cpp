#include "adit/drivers/pcap_replay.hpp"

#include <chrono>
#include <thread>

#include "adit/common/clock.hpp"

namespace adit::drivers {

std::filesystem::path pcap_part(const std::filesystem::path& first, int index) {
  if (index == 0) return first;
  std::filesystem::path part = first;
  part.replace_filename(first.stem().string() + "." + std::to_string(index) + first.extension().string());
  return part;
}

PacedPcapReader::PacedPcapReader(const std::filesystem::path& file, double speed, std::int64_t max_catch_up_ns)
    : reader_(file), first_(file), speed_(speed), max_catch_up_ns_(max_catch_up_ns) {}

PcapStats PacedPcapReader::stats() const {
  PcapStats s = reader_.stats();
  s.records += earlier_parts_.records;
  s.datagrams += earlier_parts_.datagrams;
  s.non_udp += earlier_parts_.non_udp;
  s.damaged += earlier_parts_.damaged;
  s.reassembled += earlier_parts_.reassembled;
  s.fragments_dropped += earlier_parts_.fragments_dropped;
  return s;
}

bool PacedPcapReader::next(UdpDatagram& out) {
  while (!reader_.next(out)) {
    const std::filesystem::path next_part = pcap_part(first_, part_ + 1);
    if (!std::filesystem::exists(next_part)) return false;
    earlier_parts_ = stats();
    reader_ = PcapReader(next_part);  // throws adit::InputError naming a part that is no capture
    ++part_;
  }
  if (speed_ <= 0.0) return true;
  if (!first_capture_ns_) {
    first_capture_ns_ = out.capture_time_ns;
    start_monotonic_ns_ = monotonic_ns();
    return true;
  }
  // Captures can step backwards (clock adjustments): never wait for those.
  const std::int64_t since_first = std::max<std::int64_t>(out.capture_time_ns - *first_capture_ns_, 0);
  const std::int64_t due = start_monotonic_ns_ + static_cast<std::int64_t>(static_cast<double>(since_first) / speed_);
  // On the monotonic clock (monotonic_ns() is steady_clock's). Not an
  // absolute clock_nanosleep: libfaketime (the clock-step tests) returns from
  // that at once, and sleep_until does the same here.
  std::this_thread::sleep_until(std::chrono::steady_clock::time_point(std::chrono::nanoseconds(due)));
  lateness_ns_ = monotonic_ns() - due;
  // Too late to catch up: the schedule moves on by the lateness, so the
  // datagrams after this one keep their recorded spacing from now.
  if (lateness_ns_ > max_catch_up_ns_) start_monotonic_ns_ += lateness_ns_;
  return true;
}

}  // namespace adit::drivers
