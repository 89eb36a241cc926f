#include "adit/drivers/can/socketcan.hpp"

#include <linux/can.h>
#include <linux/can/error.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

#include <fmt/format.h>

#include "adit/common/clock.hpp"

namespace adit::drivers::can {
namespace {

static_assert(sizeof(can_frame) == 16 && sizeof(canfd_frame) == 72);

void set_option(int fd, int level, int name, const void* value, socklen_t size, const std::string& interface,
                const char* what) {
  if (setsockopt(fd, level, name, value, size) != 0) {
    const int e = errno;
    close(fd);
    throw std::runtime_error(fmt::format("CAN interface '{}': cannot set {}: {}", interface, what, std::strerror(e)));
  }
}

}  // namespace

ReceiveMeta parse_control_messages(const msghdr& message) {
  ReceiveMeta meta;
  for (const cmsghdr* c = CMSG_FIRSTHDR(&message); c != nullptr; c = CMSG_NXTHDR(const_cast<msghdr*>(&message), const_cast<cmsghdr*>(c))) {
    if (c->cmsg_level != SOL_SOCKET) continue;
    if (c->cmsg_type == SCM_TIMESTAMP && c->cmsg_len >= CMSG_LEN(sizeof(timeval))) {
      timeval tv{};
      std::memcpy(&tv, CMSG_DATA(c), sizeof tv);
      meta.has_timestamp = true;
      meta.time_us = static_cast<std::int64_t>(tv.tv_sec) * 1'000'000 + tv.tv_usec;
    } else if (c->cmsg_type == SO_RXQ_OVFL && c->cmsg_len >= CMSG_LEN(sizeof(std::uint32_t))) {
      std::memcpy(&meta.drops, CMSG_DATA(c), sizeof meta.drops);
      meta.has_drops = true;
    }
  }
  return meta;
}

bool from_kernel_record(std::span<const std::uint8_t> record, Frame& out) {
  canid_t raw_id = 0;
  if (record.size() == sizeof(can_frame)) {
    can_frame k{};
    std::memcpy(&k, record.data(), sizeof k);
    if (k.len > CAN_MAX_DLEN) return false;
    raw_id = k.can_id;
    out.fd = false;
    out.length = k.len;
    out.fd_flags = 0;
    out.len8_dlc = k.len == CAN_MAX_DLEN && k.len8_dlc > CAN_MAX_DLEN && k.len8_dlc <= 15 ? k.len8_dlc : 0;
    std::memcpy(out.data.data(), k.data, CAN_MAX_DLEN);
  } else if (record.size() == sizeof(canfd_frame)) {
    canfd_frame k{};
    std::memcpy(&k, record.data(), sizeof k);
    if (k.len > CANFD_MAX_DLEN || !is_valid_fd_length(k.len)) return false;
    raw_id = k.can_id;
    out.fd = true;
    out.length = k.len;
    out.fd_flags = k.flags & (CANFD_BRS | CANFD_ESI);
    out.len8_dlc = 0;
    std::memcpy(out.data.data(), k.data, CANFD_MAX_DLEN);
  } else {
    return false;
  }
  out.error = (raw_id & CAN_ERR_FLAG) != 0;
  out.remote = !out.error && (raw_id & CAN_RTR_FLAG) != 0;
  out.extended = !out.error && (raw_id & CAN_EFF_FLAG) != 0;
  out.id = out.error ? raw_id & CAN_ERR_MASK : out.extended ? raw_id & CAN_EFF_MASK : raw_id & CAN_SFF_MASK;
  if (out.fd && (out.remote || out.error)) return false;  // FD has neither
  return true;
}

std::size_t to_kernel_record(const Frame& f, std::span<std::uint8_t, 72> out) {
  canid_t id = f.error ? (f.id & CAN_ERR_MASK) | CAN_ERR_FLAG
                       : f.extended ? (f.id & CAN_EFF_MASK) | CAN_EFF_FLAG : f.id & CAN_SFF_MASK;
  if (f.remote) id |= CAN_RTR_FLAG;
  if (f.fd) {
    canfd_frame k{};
    k.can_id = id;
    k.len = std::min<std::uint8_t>(f.length, CANFD_MAX_DLEN);
    k.flags = f.fd_flags;
    std::memcpy(k.data, f.data.data(), k.len);
    std::memcpy(out.data(), &k, sizeof k);
    return sizeof k;
  }
  can_frame k{};
  k.can_id = id;
  k.len = std::min<std::uint8_t>(f.length, CAN_MAX_DLEN);
  k.len8_dlc = f.len8_dlc;
  if (!f.remote) std::memcpy(k.data, f.data.data(), k.len);
  std::memcpy(out.data(), &k, sizeof k);
  return sizeof k;
}

CanSocket::CanSocket(int fd, const std::string& name) : fd_(fd) { name_template_.set_interface_name(name); }

CanSocket::CanSocket(CanSocket&& other) noexcept
    : fd_(other.fd_), name_template_(other.name_template_), stats_(other.stats_), bus_(other.bus_) {
  other.fd_ = -1;
}

CanSocket& CanSocket::operator=(CanSocket&& other) noexcept {
  if (this != &other) {
    if (fd_ >= 0) close(fd_);
    fd_ = other.fd_;
    name_template_ = other.name_template_;
    stats_ = other.stats_;
    bus_ = other.bus_;
    other.fd_ = -1;
  }
  return *this;
}

CanSocket::~CanSocket() {
  if (fd_ >= 0) close(fd_);
}

CanSocket CanSocket::open(const SocketOptions& o) {
  if (o.interface.empty() || o.interface.size() >= IFNAMSIZ)
    throw std::runtime_error(fmt::format("CAN interface '{}': name must be 1..{} characters", o.interface, IFNAMSIZ - 1));
  const int fd = socket(PF_CAN, SOCK_RAW | SOCK_CLOEXEC, CAN_RAW);
  if (fd < 0) {
    const int e = errno;
    throw std::runtime_error(fmt::format(
        "CAN interface '{}': cannot open a raw CAN socket: {}{}", o.interface, std::strerror(e),
        e == EAFNOSUPPORT || e == EPROTONOSUPPORT ? " (this kernel has no PF_CAN protocol family: load the can and can_raw modules)" : ""));
  }
  ifreq ifr{};
  std::memcpy(ifr.ifr_name, o.interface.c_str(), o.interface.size() + 1);
  if (ioctl(fd, SIOCGIFINDEX, &ifr) != 0) {
    const int e = errno;
    close(fd);
    throw std::runtime_error(fmt::format("CAN interface '{}' not found: {}", o.interface, std::strerror(e)));
  }
  if (!o.filters.empty()) {
    std::vector<can_filter> filters;
    for (const IdFilter& f : o.filters) {
      const canid_t flag = f.extended ? CAN_EFF_FLAG : 0;
      // Include the EFF flag in the mask so an 11-bit filter never matches a 29-bit id.
      filters.push_back({f.id | flag, (f.mask & (f.extended ? CAN_EFF_MASK : CAN_SFF_MASK)) | CAN_EFF_FLAG | CAN_RTR_FLAG});
    }
    set_option(fd, SOL_CAN_RAW, CAN_RAW_FILTER, filters.data(), static_cast<socklen_t>(filters.size() * sizeof(can_filter)),
               o.interface, "CAN_RAW_FILTER");
  }
  if (o.error_frames) {
    const can_err_mask_t mask = CAN_ERR_TX_TIMEOUT | CAN_ERR_CRTL | CAN_ERR_PROT | CAN_ERR_TRX | CAN_ERR_ACK |
                                CAN_ERR_BUSOFF | CAN_ERR_RESTARTED;  // not BUSERROR: it may flood
    set_option(fd, SOL_CAN_RAW, CAN_RAW_ERR_FILTER, &mask, sizeof mask, o.interface, "CAN_RAW_ERR_FILTER");
  }
  if (o.fd_frames) {
    const int on = 1;
    set_option(fd, SOL_CAN_RAW, CAN_RAW_FD_FRAMES, &on, sizeof on, o.interface, "CAN_RAW_FD_FRAMES");
  }
  if (o.receive_buffer_bytes > 0)
    set_option(fd, SOL_SOCKET, SO_RCVBUF, &o.receive_buffer_bytes, sizeof o.receive_buffer_bytes, o.interface, "SO_RCVBUF");
  const int on = 1;
  set_option(fd, SOL_SOCKET, SO_TIMESTAMP, &on, sizeof on, o.interface, "SO_TIMESTAMP");
  set_option(fd, SOL_SOCKET, SO_RXQ_OVFL, &on, sizeof on, o.interface, "SO_RXQ_OVFL");
  sockaddr_can addr{};
  addr.can_family = AF_CAN;
  addr.can_ifindex = ifr.ifr_ifindex;
  if (bind(fd, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0) {
    const int e = errno;
    close(fd);
    throw std::runtime_error(fmt::format("CAN interface '{}': bind failed: {}", o.interface, std::strerror(e)));
  }
  return CanSocket(fd, o.interface);
}

CanSocket CanSocket::adopt(int fd, const std::string& name) {
  const int on = 1;
  // Best effort: AF_UNIX supports SO_TIMESTAMP; SO_RXQ_OVFL is accepted but never reported.
  (void)setsockopt(fd, SOL_SOCKET, SO_TIMESTAMP, &on, sizeof on);
  (void)setsockopt(fd, SOL_SOCKET, SO_RXQ_OVFL, &on, sizeof on);
  return CanSocket(fd, name);
}

ReadResult CanSocket::read(Frame& out, int timeout_ms) {
  pollfd p{fd_, POLLIN, 0};
  const int ready = poll(&p, 1, timeout_ms);
  if (ready == 0) return ReadResult::timeout;
  if (ready < 0) return errno == EINTR ? ReadResult::timeout : ReadResult::failed;

  alignas(canfd_frame) std::uint8_t record[sizeof(canfd_frame)];
  alignas(cmsghdr) std::uint8_t control[CMSG_SPACE(sizeof(timeval)) + CMSG_SPACE(sizeof(std::uint32_t)) + 64];
  iovec iov{record, sizeof record};
  msghdr msg{};
  msg.msg_iov = &iov;
  msg.msg_iovlen = 1;
  msg.msg_control = control;
  msg.msg_controllen = sizeof control;
  const ssize_t n = recvmsg(fd_, &msg, MSG_DONTWAIT);
  if (n < 0) return errno == EAGAIN || errno == EINTR ? ReadResult::timeout : ReadResult::failed;
  if (n == 0 && (p.revents & POLLHUP)) return ReadResult::closed;

  const ReceiveMeta meta = parse_control_messages(msg);
  if (meta.has_drops) stats_.kernel_drops = meta.drops;
  if ((msg.msg_flags & MSG_TRUNC) != 0 ||
      !from_kernel_record({record, static_cast<std::size_t>(n)}, out)) {
    ++stats_.malformed;
    return ReadResult::malformed;
  }
  out.time_us = meta.has_timestamp ? meta.time_us : realtime_us();
  out.interface = name_template_.interface;
  bus_.on_frame(out);
  ++(out.error ? stats_.error_frames : stats_.frames);
  return ReadResult::frame;
}

}  // namespace adit::drivers::can
