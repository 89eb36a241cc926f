// A real capture replayed over loopback UDP at 10× its recorded rate through
// the live receiver (recvmmsg, kernel timestamps, drop counter), decoded and
// assembled as the daemon would: nothing may be lost, and the scans must be
// the same as decoding the file directly.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <cstdio>
#include <thread>

#include "adit/common/clock.hpp"
#include "adit/common/error.hpp"
#include "adit/drivers/lidar/decode_stream.hpp"
#include "adit/drivers/lidar/velodyne.hpp"
#include "adit/drivers/pcap_replay.hpp"
#include "adit/drivers/udp.hpp"
#include "shared_data.hpp"

namespace adit::drivers {
namespace {

struct Outcome {
  PacketCounters counters;
  ScanAssemblerTotals totals;
  std::vector<std::size_t> points_per_scan;
};

TEST(UdpLoopback, ReplayAt10xDropsNothing) {
  ADIT_REQUIRE_SHARED_DATA(dir, "lidar/velodyne-hdl32e");
  const auto calibration = load_velodyne_calibration(dir / "HDL32.yaml");
  const std::int64_t period = velodyne_packet_period_ns(VelodyneModel::hdl32e, VelodyneReturnMode::strongest);

  // Reference: the file decoded directly.
  Outcome direct;
  {
    VelodyneDecoder decoder(VelodyneModel::hdl32e, calibration);
    ScanAssembler assembler(assembler_config_for(decoder, period, 0.0F));
    DecodeStream stream(decoder, assembler, [&](LidarScan& s) { direct.points_per_scan.push_back(s.points.size()); });
    PcapReader reader(dir / "capture.pcap");
    UdpDatagram d;
    while (reader.next(d)) stream.push(d.payload, d.capture_time_ns);
    stream.finish();
    direct.counters = stream.counters();
    direct.totals = assembler.totals();
  }

  UdpReceiverConfig config;
  config.bind_address = "127.0.0.1";
  UdpReceiver receiver(config);
  std::atomic<bool> done{false};
  std::uint64_t sent = 0;
  std::uint64_t refused = 0;
  std::thread sender([&] {
    UdpSender out("127.0.0.1", receiver.port());
    PacedPcapReader reader(dir / "capture.pcap", 10.0);
    UdpDatagram d;
    while (reader.next(d)) sent += out.send(d.payload) ? 1 : 0;
    refused = out.failures();
    done = true;
  });

  Outcome live;
  VelodyneDecoder decoder(VelodyneModel::hdl32e, calibration);
  ScanAssembler assembler(assembler_config_for(decoder, period, 0.0F));
  DecodeStream stream(decoder, assembler, [&](LidarScan& s) { live.points_per_scan.push_back(s.points.size()); });
  // Kernel receive stamps: every datagram has one, and they follow the send
  // order except where loopback itself reorders (a sender that moves between
  // CPUs leaves datagrams in two CPUs' backlogs, stamped on entry and
  // delivered in either order): such steps back are counted and bounded.
  const std::int64_t test_start_ns = realtime_ns();
  const std::int64_t clock_offset_ns = realtime_ns() - monotonic_ns();
  std::int64_t previous_kernel_ns = 0;
  std::int64_t latest_kernel_ns = 0;
  std::size_t unstamped = 0;
  std::size_t steps_back = 0;
  std::int64_t largest_step_back_ns = 0;
  for (int idle = 0; idle < 3;) {
    const auto batch = receiver.receive(100);
    if (batch.empty() && done) ++idle;
    for (const ReceivedDatagram& d : batch) {
      if (d.kernel_time_ns <= 0) ++unstamped;
      if (d.kernel_time_ns < previous_kernel_ns) {
        ++steps_back;
        largest_step_back_ns = std::max(largest_step_back_ns, previous_kernel_ns - d.kernel_time_ns);
      }
      previous_kernel_ns = d.kernel_time_ns;
      latest_kernel_ns = std::max(latest_kernel_ns, d.kernel_time_ns);
      stream.push(d.payload, d.kernel_time_ns);
    }
  }
  sender.join();
  stream.finish();
  live.counters = stream.counters();
  live.totals = assembler.totals();

  EXPECT_EQ(sent, 976u);
  EXPECT_EQ(refused, 0u);
  EXPECT_EQ(receiver.stats().datagrams, sent);
  EXPECT_EQ(receiver.stats().kernel_drops, 0u);
  EXPECT_EQ(receiver.stats().truncated, 0u);
  EXPECT_EQ(unstamped, 0u);
  // The stamps are wall-clock time: a host clock stepped meanwhile (NTP, PTP)
  // moves them as much, so their order is only checked on a steady clock.
  const std::int64_t clock_step_ns = (realtime_ns() - monotonic_ns()) - clock_offset_ns;
  if (std::abs(clock_step_ns) < 1'000'000) {
    EXPECT_LT(largest_step_back_ns, 5'000'000) << steps_back << " steps back";
    EXPECT_LE(steps_back, 10u) << "largest " << largest_step_back_ns << " ns";
    EXPECT_GE(latest_kernel_ns, test_start_ns);
    EXPECT_LE(latest_kernel_ns, realtime_ns());
  } else {
    std::printf("the host clock stepped by %lld ns during the test: stamp order not checked\n",
                static_cast<long long>(clock_step_ns));
  }
  std::printf("kernel stamps: %zu steps back (largest %lld ns)\n", steps_back, static_cast<long long>(largest_step_back_ns));
  EXPECT_EQ(live.counters.by_status, direct.counters.by_status);
  EXPECT_EQ(live.totals.missing_packets, 0u);
  EXPECT_EQ(live.totals.complete_scans, direct.totals.complete_scans);
  EXPECT_EQ(live.points_per_scan, direct.points_per_scan);
  std::printf("loopback at 10x: %llu datagrams in %llu batches, kernel buffer %d bytes, %llu kernel drops\n",
              static_cast<unsigned long long>(receiver.stats().datagrams),
              static_cast<unsigned long long>(receiver.stats().batches), receiver.stats().receive_buffer_bytes,
              static_cast<unsigned long long>(receiver.stats().kernel_drops));
}

TEST(UdpLoopback, KernelDropsAreCounted) {
  // A tiny receive buffer and nobody reading: the kernel must drop, and say so.
  UdpReceiverConfig config;
  config.bind_address = "127.0.0.1";
  config.receive_buffer_bytes = 4096;
  UdpReceiver receiver(config);
  UdpSender out("127.0.0.1", receiver.port());
  const std::vector<std::uint8_t> payload(1206, 0xAB);
  for (int i = 0; i < 200; ++i) out.send(payload);
  std::uint64_t received = 0;
  for (auto batch = receiver.receive(100); !batch.empty(); batch = receiver.receive(100)) received += batch.size();
  // The kernel reports its drop count with the next datagram it queues (SO_RXQ_OVFL).
  out.send(payload);
  received += receiver.receive(100).size();
  EXPECT_GT(receiver.stats().kernel_drops, 0u);
  EXPECT_EQ(received + receiver.stats().kernel_drops, 201u);
}

TEST(UdpLoopback, RejectsBadAddresses) {
  UdpReceiverConfig config;
  config.bind_address = "not-an-address";
  EXPECT_THROW(UdpReceiver{config}, InputError);
  config.bind_address = "0.0.0.0";
  config.multicast_group = "10.0.0.1";
  EXPECT_THROW(UdpReceiver{config}, InputError);
  EXPECT_THROW(parse_host_port("localhost", "--to"), InputError);
  EXPECT_THROW(parse_host_port("localhost:99999", "--to"), InputError);
  EXPECT_EQ(parse_host_port("127.0.0.1:2368", "--to").second, 2368);
}

}  // namespace
}  // namespace adit::drivers
