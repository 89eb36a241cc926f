#pragma once
// Live UDP for sensor packets.
//
// UdpReceiver binds one port (optionally to one interface, optionally joining
// a multicast group), asks for a large kernel receive buffer, and receives in
// batches with recvmmsg(2). Each datagram carries its kernel receive time
// (SO_TIMESTAMPNS, CLOCK_REALTIME) and the socket reports the kernel's count
// of datagrams dropped for lack of buffer space (SO_RXQ_OVFL, socket(7)).
// Buffers are allocated once at construction; receiving allocates nothing.
//
// UdpSender sends datagrams to one address (adit pcap-send, tests).

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

namespace adit::drivers {

struct UdpReceiverConfig {
  std::string bind_address = "0.0.0.0";
  std::uint16_t port = 0;               // 0: any free port (tests); see UdpReceiver::port()
  std::string interface;                // bind to this device (SO_BINDTODEVICE) and join multicast on it
  std::string multicast_group;          // IPv4 group to join, e.g. "239.255.0.1"; empty: unicast/broadcast
  int receive_buffer_bytes = 32 << 20;  // SO_RCVBUF(FORCE); the kernel may grant less, see stats
  std::size_t batch = 64;               // datagrams per recvmmsg
  std::size_t max_datagram_bytes = 65'536;
};

struct ReceivedDatagram {
  std::span<const std::uint8_t> payload;  // valid until the next receive()
  std::int64_t kernel_time_ns = 0;        // CLOCK_REALTIME at reception (0 if the kernel gave none)
  std::uint32_t src_ip = 0;               // host byte order
  std::uint16_t src_port = 0;
};

struct UdpReceiverStats {
  std::uint64_t datagrams = 0;
  std::uint64_t batches = 0;
  std::uint64_t kernel_drops = 0;  // SO_RXQ_OVFL: dropped by the kernel before we read them
  std::uint64_t truncated = 0;     // longer than max_datagram_bytes, cut (MSG_TRUNC)
  std::uint64_t errors = 0;        // failed receives other than timeouts/interrupts
  int receive_buffer_bytes = 0;    // what the kernel granted
};

class UdpReceiver {
 public:
  // Throws adit::InputError (bad address/interface/group) or std::system_error.
  explicit UdpReceiver(const UdpReceiverConfig& config);
  ~UdpReceiver();
  UdpReceiver(const UdpReceiver&) = delete;
  UdpReceiver& operator=(const UdpReceiver&) = delete;

  // Waits up to `timeout_ms` (-1: forever) for at least one datagram and
  // returns everything that is queued, up to a batch. Empty on timeout.
  std::span<const ReceivedDatagram> receive(int timeout_ms);

  std::uint16_t port() const;
  const UdpReceiverStats& stats() const;

 private:
  struct Impl;  // the socket and the recvmmsg arrays (keeps <sys/socket.h> out of this header)
  std::unique_ptr<Impl> impl_;
};

class UdpSender {
 public:
  // `host` is an IPv4 address or name; throws adit::InputError when it does not resolve.
  UdpSender(const std::string& host, std::uint16_t port);
  ~UdpSender();
  UdpSender(const UdpSender&) = delete;
  UdpSender& operator=(const UdpSender&) = delete;
  // False when the kernel refused the datagram (counted in failures()).
  bool send(std::span<const std::uint8_t> payload);
  std::uint64_t failures() const { return failures_; }

 private:
  int fd_ = -1;
  std::vector<std::uint8_t> address_;
  std::uint64_t failures_ = 0;
};

// Splits "host:port"; throws adit::InputError naming `what` when malformed.
std::pair<std::string, std::uint16_t> parse_host_port(const std::string& text, const std::string& what);

}  // namespace adit::drivers
