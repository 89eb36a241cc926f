// The SocketCAN reading path, fed through socketpair(AF_UNIX, SOCK_SEQPACKET):
// same records, same recvmsg, as a PF_CAN socket (this kernel has no CAN).

#include <linux/can.h>
#include <linux/can/error.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <cstring>

#include <gtest/gtest.h>

#include "adit/drivers/can/socketcan.hpp"

namespace can = adit::drivers::can;

namespace {

class Pair : public ::testing::Test {
 protected:
  void SetUp() override {
    int fds[2];
    ASSERT_EQ(socketpair(AF_UNIX, SOCK_SEQPACKET, 0, fds), 0);
    writer_ = fds[1];
    reader_.emplace(can::CanSocket::adopt(fds[0], "can0"));
  }
  void TearDown() override {
    if (writer_ >= 0) close(writer_);
  }
  void send(const void* data, std::size_t size) { ASSERT_EQ(write(writer_, data, size), static_cast<ssize_t>(size)); }
  void send(const can_frame& f) { send(&f, sizeof f); }
  can::Frame read_ok() {
    can::Frame f;
    EXPECT_EQ(reader_->read(f, 1000), can::ReadResult::frame);
    return f;
  }
  int writer_ = -1;
  std::optional<can::CanSocket> reader_;
};

can_frame error_frame(canid_t cls, std::uint8_t ctrl = 0) {
  can_frame f{};
  f.can_id = CAN_ERR_FLAG | cls;
  f.len = CAN_ERR_DLC;
  f.data[1] = ctrl;
  return f;
}

}  // namespace

TEST_F(Pair, ClassicExtendedRemoteAndFdFramesWithTimestamps) {
  can_frame c{};
  c.can_id = 0x0AA;
  c.len = 8;
  const std::uint8_t payload[8] = {0x25, 0xB5, 0x25, 0xB5, 0x25, 0xA0, 0x25, 0x8D};
  std::memcpy(c.data, payload, 8);
  send(c);
  const auto before = std::chrono::duration_cast<std::chrono::microseconds>(
                          std::chrono::system_clock::now().time_since_epoch()).count();
  can::Frame f = read_ok();
  EXPECT_EQ(f.id, 0xAAU);
  EXPECT_FALSE(f.extended);
  EXPECT_EQ(f.length, 8);
  EXPECT_EQ(f.data[7], 0x8D);
  EXPECT_EQ(f.interface_name(), "can0");
  EXPECT_LE(std::abs(f.time_us - before), 5'000'000);  // a receive timestamp from the kernel or the clock

  can_frame e{};
  e.can_id = 0x18FEF100 | CAN_EFF_FLAG;
  e.len = 3;
  send(e);
  f = read_ok();
  EXPECT_TRUE(f.extended);
  EXPECT_EQ(f.id, 0x18FEF100U);

  can_frame r{};
  r.can_id = 0x123 | CAN_RTR_FLAG;
  r.len = 4;
  send(r);
  f = read_ok();
  EXPECT_TRUE(f.remote);
  EXPECT_EQ(f.length, 4);

  canfd_frame fd{};
  fd.can_id = 0x321;
  fd.len = 48;
  fd.flags = CANFD_BRS;
  fd.data[47] = 0x5A;
  send(&fd, sizeof fd);
  f = read_ok();
  EXPECT_TRUE(f.fd);
  EXPECT_EQ(f.length, 48);
  EXPECT_EQ(f.fd_flags, can::kFdBitRateSwitch);
  EXPECT_EQ(f.data[47], 0x5A);
  EXPECT_EQ(reader_->stats().frames, 4U);
}

TEST_F(Pair, RecordsOfWrongSizeOrLengthAreCountedNotReturned) {
  const std::uint8_t junk[10] = {};
  send(junk, sizeof junk);
  const std::uint8_t big[100] = {};
  send(big, sizeof big);  // larger than canfd_frame: truncated
  can_frame bad{};
  bad.len = 9;  // no classic frame carries 9 bytes
  send(bad);
  canfd_frame bad_fd{};
  bad_fd.len = 13;  // no DLC encodes 13 bytes
  send(&bad_fd, sizeof bad_fd);
  can::Frame f;
  for (int i = 0; i < 4; ++i) EXPECT_EQ(reader_->read(f, 1000), can::ReadResult::malformed) << i;
  EXPECT_EQ(reader_->stats().malformed, 4U);
  EXPECT_EQ(reader_->stats().frames, 0U);
}

TEST_F(Pair, TimeoutAndClosedPeer) {
  can::Frame f;
  EXPECT_EQ(reader_->read(f, 10), can::ReadResult::timeout);
  close(writer_);
  writer_ = -1;
  EXPECT_EQ(reader_->read(f, 1000), can::ReadResult::closed);
}

TEST_F(Pair, BusOffIsAFaultAndRecoversWhenTheBusComesBack) {
  send(error_frame(CAN_ERR_CRTL, CAN_ERR_CRTL_RX_WARNING));
  read_ok();
  EXPECT_EQ(reader_->bus().state(), can::BusState::warning);
  send(error_frame(CAN_ERR_CRTL, CAN_ERR_CRTL_TX_PASSIVE));
  read_ok();
  EXPECT_EQ(reader_->bus().state(), can::BusState::error_passive);
  send(error_frame(CAN_ERR_BUSOFF));
  const can::Frame err = read_ok();
  EXPECT_TRUE(err.error);
  EXPECT_EQ(err.id, static_cast<std::uint32_t>(CAN_ERR_BUSOFF));
  EXPECT_TRUE(reader_->bus().fault());
  can_frame data{};
  data.can_id = 0x10;
  data.len = 1;
  send(data);
  read_ok();
  EXPECT_EQ(reader_->bus().state(), can::BusState::ok);
  EXPECT_FALSE(reader_->bus().fault());
  send(error_frame(CAN_ERR_CRTL, CAN_ERR_CRTL_RX_PASSIVE | CAN_ERR_CRTL_RX_OVERFLOW));
  read_ok();
  send(error_frame(CAN_ERR_CRTL, CAN_ERR_CRTL_ACTIVE));
  read_ok();
  EXPECT_EQ(reader_->bus().state(), can::BusState::ok);
  const can::BusCounters& c = reader_->bus().counters();
  EXPECT_EQ(c.bus_off, 1U);
  EXPECT_EQ(c.error_passive, 2U);
  EXPECT_EQ(c.recoveries, 2U);
  EXPECT_EQ(c.controller_overflows, 1U);
  EXPECT_EQ(c.error_frames, 5U);
  EXPECT_EQ(reader_->stats().error_frames, 5U);
}

TEST(SocketCan, KernelRecordRoundTrip) {
  can::Frame f;
  f.id = 0x1ABCDEF;
  f.extended = true;
  f.length = 8;
  f.len8_dlc = 13;
  f.data[0] = 0x11;
  std::array<std::uint8_t, 72> record{};
  const std::size_t n = can::to_kernel_record(f, record);
  ASSERT_EQ(n, 16U);
  can::Frame back;
  ASSERT_TRUE(can::from_kernel_record({record.data(), n}, back));
  back.time_us = f.time_us;
  EXPECT_EQ(back, f);
}

TEST(SocketCan, ControlMessagesCarryTimestampAndDrops) {
  alignas(cmsghdr) std::uint8_t control[CMSG_SPACE(sizeof(timeval)) + CMSG_SPACE(sizeof(std::uint32_t))] = {};
  msghdr msg{};
  msg.msg_control = control;
  msg.msg_controllen = sizeof control;
  cmsghdr* c = CMSG_FIRSTHDR(&msg);
  c->cmsg_level = SOL_SOCKET;
  c->cmsg_type = SCM_TIMESTAMP;
  c->cmsg_len = CMSG_LEN(sizeof(timeval));
  const timeval tv{1700000000, 123456};
  std::memcpy(CMSG_DATA(c), &tv, sizeof tv);
  c = CMSG_NXTHDR(&msg, c);
  c->cmsg_level = SOL_SOCKET;
  c->cmsg_type = SO_RXQ_OVFL;
  c->cmsg_len = CMSG_LEN(sizeof(std::uint32_t));
  const std::uint32_t drops = 42;
  std::memcpy(CMSG_DATA(c), &drops, sizeof drops);
  const can::ReceiveMeta meta = can::parse_control_messages(msg);
  EXPECT_TRUE(meta.has_timestamp);
  EXPECT_EQ(meta.time_us, 1700000000123456);
  EXPECT_TRUE(meta.has_drops);
  EXPECT_EQ(meta.drops, 42U);
}

TEST(SocketCan, OpeningARealSocketFailsClearlyWithoutCan) {
  can::SocketOptions o;
  o.interface = "can7";
  try {
    can::CanSocket s = can::CanSocket::open(o);
    GTEST_SKIP() << "this kernel has CAN and a can7 interface";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("'can7'"), std::string::npos) << what;
    // Either the protocol family is missing (this machine) or the interface is.
    EXPECT_TRUE(what.find("PF_CAN") != std::string::npos || what.find("not found") != std::string::npos) << what;
  }
}
