#include "capture_sender.hpp"

#include "adit/drivers/pcap_replay.hpp"
#include "adit/drivers/udp.hpp"

namespace adit::tools {
namespace {
constexpr std::int64_t kMaxCatchUpNs = 5'000'000;
}  // namespace

SendTotals send_capture(const std::filesystem::path& file, const std::string& host, std::uint16_t port, double speed,
                        int only_port, const std::atomic<bool>& stop) {
  // Held up by a busy machine, the sender resumes the recorded pace rather
  // than bursting the overdue datagrams, which a sensor never does.
  drivers::PacedPcapReader reader(file, speed, kMaxCatchUpNs);
  drivers::UdpSender sender(host, port);
  drivers::UdpDatagram d;
  SendTotals totals;
  while (!stop.load(std::memory_order_relaxed) && reader.next(d)) {
    if (only_port > 0 && d.dst_port != only_port) continue;
    if (sender.send(d.payload)) ++totals.sent;
  }
  totals.refused = sender.failures();
  return totals;
}

}  // namespace adit::tools
