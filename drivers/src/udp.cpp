#include "adit/drivers/udp.hpp"

#include <arpa/inet.h>
#include <net/if.h>
#include <netdb.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cstring>
#include <algorithm>
#include <system_error>

#include "adit/common/error.hpp"

namespace adit::drivers {
namespace {

[[noreturn]] void fail(const char* what) { throw std::system_error(errno, std::generic_category(), what); }

in_addr parse_ipv4(const std::string& text, const std::string& key) {
  in_addr address{};
  if (inet_pton(AF_INET, text.c_str(), &address) != 1) throw InputError("", key, "not an IPv4 address: " + text);
  return address;
}

// Room for the control messages we ask for: a timespec and a u32 drop counter.
constexpr std::size_t kControlBytes = CMSG_SPACE(sizeof(timespec)) + CMSG_SPACE(sizeof(std::uint32_t)) + 64;

}  // namespace

struct UdpReceiver::Impl {
  int fd = -1;
  std::uint16_t port = 0;
  UdpReceiverConfig config;
  UdpReceiverStats stats;
  std::uint32_t last_drop_counter = 0;
  std::vector<std::uint8_t> buffers;
  std::vector<std::uint8_t> controls;
  std::vector<mmsghdr> messages;
  std::vector<iovec> vectors;
  std::vector<sockaddr_in> sources;
  std::vector<ReceivedDatagram> out;

  ~Impl() {
    if (fd >= 0) ::close(fd);
  }
  void open();
};

void UdpReceiver::Impl::open() {
  fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (fd < 0) fail("socket");
  const int on = 1;
  if (::setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &on, sizeof on) != 0) fail("SO_REUSEADDR");
  // SO_RCVBUFFORCE passes net.core.rmem_max when we have CAP_NET_ADMIN; otherwise the capped SO_RCVBUF.
  const int wanted = config.receive_buffer_bytes;
  if (::setsockopt(fd, SOL_SOCKET, SO_RCVBUFFORCE, &wanted, sizeof wanted) != 0 &&
      ::setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &wanted, sizeof wanted) != 0) {
    fail("SO_RCVBUF");
  }
  socklen_t length = sizeof stats.receive_buffer_bytes;
  ::getsockopt(fd, SOL_SOCKET, SO_RCVBUF, &stats.receive_buffer_bytes, &length);
  if (::setsockopt(fd, SOL_SOCKET, SO_TIMESTAMPNS, &on, sizeof on) != 0) fail("SO_TIMESTAMPNS");
  if (::setsockopt(fd, SOL_SOCKET, SO_RXQ_OVFL, &on, sizeof on) != 0) fail("SO_RXQ_OVFL");
  if (!config.interface.empty() &&
      ::setsockopt(fd, SOL_SOCKET, SO_BINDTODEVICE, config.interface.c_str(),
                   static_cast<socklen_t>(config.interface.size())) != 0) {
    throw InputError("", "interface", "cannot bind to device " + config.interface + ": " + std::strerror(errno));
  }
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(config.port);
  address.sin_addr = parse_ipv4(config.bind_address, "bind_address");
  if (::bind(fd, reinterpret_cast<const sockaddr*>(&address), sizeof address) != 0) {
    throw InputError("", "port",
                     "cannot bind " + config.bind_address + ":" + std::to_string(config.port) + ": " + std::strerror(errno));
  }
  socklen_t address_length = sizeof address;
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&address), &address_length);
  port = ntohs(address.sin_port);
  if (!config.multicast_group.empty()) {
    ip_mreqn request{};
    request.imr_multiaddr = parse_ipv4(config.multicast_group, "multicast_group");
    if (!IN_MULTICAST(ntohl(request.imr_multiaddr.s_addr))) {
      throw InputError("", "multicast_group", config.multicast_group + " is not a multicast address");
    }
    request.imr_ifindex = config.interface.empty() ? 0 : static_cast<int>(if_nametoindex(config.interface.c_str()));
    if (::setsockopt(fd, IPPROTO_IP, IP_ADD_MEMBERSHIP, &request, sizeof request) != 0) {
      throw InputError("", "multicast_group", "cannot join " + config.multicast_group + ": " + std::strerror(errno));
    }
  }
}

UdpReceiver::UdpReceiver(const UdpReceiverConfig& config) : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.config = config;
  m.config.batch = std::max<std::size_t>(m.config.batch, 1);
  m.open();
  const std::size_t n = m.config.batch;
  m.buffers.resize(n * m.config.max_datagram_bytes);
  m.controls.resize(n * kControlBytes);
  m.messages.resize(n);
  m.vectors.resize(n);
  m.sources.resize(n);
  m.out.resize(n);
}

UdpReceiver::~UdpReceiver() = default;
std::uint16_t UdpReceiver::port() const { return impl_->port; }
const UdpReceiverStats& UdpReceiver::stats() const { return impl_->stats; }

std::span<const ReceivedDatagram> UdpReceiver::receive(int timeout_ms) {
  Impl& m = *impl_;
  pollfd p{m.fd, POLLIN, 0};
  const int ready = ::poll(&p, 1, timeout_ms);
  if (ready <= 0) {
    if (ready < 0 && errno != EINTR) ++m.stats.errors;
    return {};
  }
  const std::size_t n = m.config.batch;
  for (std::size_t i = 0; i < n; ++i) {
    m.vectors[i] = {m.buffers.data() + i * m.config.max_datagram_bytes, m.config.max_datagram_bytes};
    msghdr& h = m.messages[i].msg_hdr;
    h = {};
    h.msg_name = &m.sources[i];
    h.msg_namelen = sizeof(sockaddr_in);
    h.msg_iov = &m.vectors[i];
    h.msg_iovlen = 1;
    h.msg_control = m.controls.data() + i * kControlBytes;
    h.msg_controllen = kControlBytes;
  }
  const int count = ::recvmmsg(m.fd, m.messages.data(), static_cast<unsigned>(n), MSG_DONTWAIT, nullptr);
  if (count <= 0) {
    if (count < 0 && errno != EAGAIN && errno != EINTR) ++m.stats.errors;
    return {};
  }
  ++m.stats.batches;
  for (int i = 0; i < count; ++i) {
    const msghdr& h = m.messages[i].msg_hdr;
    ReceivedDatagram& d = m.out[i];
    const std::size_t length = std::min<std::size_t>(m.messages[i].msg_len, m.config.max_datagram_bytes);
    if ((h.msg_flags & MSG_TRUNC) != 0) ++m.stats.truncated;
    d.payload = {m.buffers.data() + i * m.config.max_datagram_bytes, length};
    d.src_ip = ntohl(m.sources[i].sin_addr.s_addr);
    d.src_port = ntohs(m.sources[i].sin_port);
    d.kernel_time_ns = 0;
    for (cmsghdr* c = CMSG_FIRSTHDR(&h); c != nullptr; c = CMSG_NXTHDR(const_cast<msghdr*>(&h), c)) {
      if (c->cmsg_level != SOL_SOCKET) continue;
      if (c->cmsg_type == SCM_TIMESTAMPNS) {
        timespec t;
        std::memcpy(&t, CMSG_DATA(c), sizeof t);
        d.kernel_time_ns = std::int64_t{t.tv_sec} * 1'000'000'000 + t.tv_nsec;
      } else if (c->cmsg_type == SO_RXQ_OVFL) {
        // The kernel's running count of drops on this socket (wraps at 2^32).
        std::uint32_t drops;
        std::memcpy(&drops, CMSG_DATA(c), sizeof drops);
        m.stats.kernel_drops += drops - m.last_drop_counter;
        m.last_drop_counter = drops;
      }
    }
  }
  m.stats.datagrams += static_cast<std::uint64_t>(count);
  return {m.out.data(), static_cast<std::size_t>(count)};
}

UdpSender::UdpSender(const std::string& host, std::uint16_t port) {
  addrinfo hints{};
  hints.ai_family = AF_INET;
  hints.ai_socktype = SOCK_DGRAM;
  addrinfo* found = nullptr;
  if (::getaddrinfo(host.c_str(), nullptr, &hints, &found) != 0 || found == nullptr) {
    throw InputError("", "to", "cannot resolve " + host);
  }
  sockaddr_in address{};
  std::memcpy(&address, found->ai_addr, sizeof address);
  ::freeaddrinfo(found);
  address.sin_port = htons(port);
  address_.resize(sizeof address);
  std::memcpy(address_.data(), &address, sizeof address);
  fd_ = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (fd_ < 0) fail("socket");
  const int on = 1;
  ::setsockopt(fd_, SOL_SOCKET, SO_BROADCAST, &on, sizeof on);
}

UdpSender::~UdpSender() {
  if (fd_ >= 0) ::close(fd_);
}

bool UdpSender::send(std::span<const std::uint8_t> payload) {
  const auto sent = ::sendto(fd_, payload.data(), payload.size(), 0, reinterpret_cast<const sockaddr*>(address_.data()),
                             static_cast<socklen_t>(address_.size()));
  if (sent == static_cast<ssize_t>(payload.size())) return true;
  ++failures_;
  return false;
}

std::pair<std::string, std::uint16_t> parse_host_port(const std::string& text, const std::string& what) {
  const auto colon = text.rfind(':');
  unsigned port = 0;
  if (colon == std::string::npos || colon == 0) throw InputError("", what, "want HOST:PORT, got `" + text + "`");
  const char* begin = text.data() + colon + 1;
  const char* end = text.data() + text.size();
  const auto [p, ec] = std::from_chars(begin, end, port);
  if (ec != std::errc{} || p != end || port == 0 || port > 65535) {
    throw InputError("", what, "bad port in `" + text + "`");
  }
  return {text.substr(0, colon), static_cast<std::uint16_t>(port)};
}

}  // namespace adit::drivers
