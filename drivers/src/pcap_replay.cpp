#include "adit/drivers/pcap_replay.hpp"

#include <chrono>
#include <thread>

#include "adit/common/clock.hpp"

namespace adit::drivers {

PacedPcapReader::PacedPcapReader(const std::filesystem::path& file, double speed) : reader_(file), speed_(speed) {}

bool PacedPcapReader::next(UdpDatagram& out) {
  if (!reader_.next(out)) return false;
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
  return true;
}

}  // namespace adit::drivers
