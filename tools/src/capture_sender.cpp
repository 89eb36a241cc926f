#include "capture_sender.hpp"

#include "adit/drivers/pcap_replay.hpp"
#include "adit/drivers/udp.hpp"

#include <deque>

namespace adit::tools {
namespace {
constexpr std::int64_t kMaxCatchUpNs = 5'000'000;
}  // namespace

SendTotals send_capture(const std::filesystem::path& file, const std::string& host, std::span<const SendRoute> routes,
                        double speed, const std::atomic<bool>& stop) {
  // Held up by a busy machine, the sender resumes the recorded pace rather
  // than bursting the overdue datagrams, which a sensor never does.
  drivers::PacedPcapReader reader(file, speed, kMaxCatchUpNs);
  std::deque<drivers::UdpSender> senders;  // a socket each, built in place (not movable)
  for (const SendRoute& r : routes) senders.emplace_back(host, r.to_port);
  drivers::UdpDatagram d;
  SendTotals totals;
  while (!stop.load(std::memory_order_relaxed) && reader.next(d)) {
    for (std::size_t i = 0; i < routes.size(); ++i) {
      if (routes[i].from_port > 0 && d.dst_port != routes[i].from_port) continue;
      if (senders[i].send(d.payload)) ++totals.sent;
      break;
    }
  }
  for (const drivers::UdpSender& s : senders) totals.refused += s.failures();
  return totals;
}

}  // namespace adit::tools
