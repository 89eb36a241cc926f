#pragma once
// Reading frames from a SocketCAN raw socket (Documentation/networking/can.rst
// in the Linux tree). One reading path for a real PF_CAN socket and for any
// socket that carries the same records (struct can_frame, 16 bytes, or struct
// canfd_frame, 72 bytes) with message boundaries, such as one end of
// socketpair(AF_UNIX, SOCK_SEQPACKET) in tests.

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "adit/drivers/can/bus_status.hpp"
#include "adit/drivers/can/frame.hpp"

struct msghdr;

namespace adit::drivers::can {

struct IdFilter {
  std::uint32_t id = 0;
  std::uint32_t mask = 0x7FF;  // bits that must match (CAN_RAW_FILTER semantics)
  bool extended = false;
};

// Binds to the `can:` config section (one per bus).
struct SocketOptions {
  std::string interface = "can0";
  std::vector<IdFilter> filters;  // empty: every frame
  bool error_frames = true;       // bus-off, error-passive, controller problems, no-ack, ...
  bool fd_frames = true;          // accept CAN FD (CAN_RAW_FD_FRAMES)
  int receive_buffer_bytes = 0;   // SO_RCVBUF; 0 keeps the kernel default
};

struct SourceStats {
  std::uint64_t frames = 0;        // data and remote frames returned
  std::uint64_t error_frames = 0;  // error frames returned (also fed to the bus monitor)
  std::uint64_t malformed = 0;     // records of a size that is neither can_frame nor canfd_frame, or truncated
  std::uint64_t kernel_drops = 0;  // SO_RXQ_OVFL: frames the kernel dropped, cumulative
};

enum class ReadResult : std::uint8_t { frame, timeout, malformed, closed, failed };

// What recvmsg's ancillary data said.
struct ReceiveMeta {
  bool has_timestamp = false;
  std::int64_t time_us = 0;  // SO_TIMESTAMP, CLOCK_REALTIME
  bool has_drops = false;
  std::uint32_t drops = 0;   // SO_RXQ_OVFL cumulative count
};
ReceiveMeta parse_control_messages(const msghdr& message);

// Kernel record <-> Frame. from_kernel_record is false for a record of any
// other size or with an impossible length.
bool from_kernel_record(std::span<const std::uint8_t> record, Frame& out);
// Writes a can_frame (16 bytes) or, for FD, a canfd_frame (72); returns the size.
std::size_t to_kernel_record(const Frame& frame, std::span<std::uint8_t, 72> out);

class CanSocket {
 public:
  // A PF_CAN raw socket bound to options.interface with filters, error frames,
  // FD, SO_TIMESTAMP and SO_RXQ_OVFL. Throws std::runtime_error naming the
  // interface when the kernel lacks PF_CAN or the interface does not exist.
  static CanSocket open(const SocketOptions& options);
  // Adopts `fd` (closed on destruction); asks for SO_TIMESTAMP and SO_RXQ_OVFL
  // where the socket supports them. `name` becomes each frame's interface.
  static CanSocket adopt(int fd, const std::string& name);

  CanSocket(CanSocket&& other) noexcept;
  CanSocket& operator=(CanSocket&& other) noexcept;
  CanSocket(const CanSocket&) = delete;
  CanSocket& operator=(const CanSocket&) = delete;
  ~CanSocket();

  // Waits up to timeout_ms (-1: forever) for one record. No allocation.
  ReadResult read(Frame& out, int timeout_ms);
  int fd() const { return fd_; }
  const SourceStats& stats() const { return stats_; }
  const BusMonitor& bus() const { return bus_; }

 private:
  CanSocket(int fd, const std::string& name);
  int fd_ = -1;
  Frame name_template_;
  SourceStats stats_;
  BusMonitor bus_;
};

}  // namespace adit::drivers::can
