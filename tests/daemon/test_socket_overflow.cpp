// A burst the live receiver cannot keep up with, into the smallest receive
// buffer the configuration allows: what the kernel drops from the full socket
// is counted as the session's socket drops (and named in its faults), so
// every datagram sent is either received or counted, none unaccounted.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <thread>
#include <vector>

#include <fmt/format.h>
#include <unistd.h>

#include "adit/daemon/pipeline.hpp"
#include "adit/drivers/udp.hpp"
#include "pipeline_run.hpp"
#include "shared_data.hpp"

namespace adit::daemon {
namespace {

TEST(SocketOverflow, WhatTheKernelDropsFromAFullSocketIsCounted) {
  const auto port = static_cast<std::uint16_t>(30000 + ::getpid() % 10000);
  const std::string yaml = fmt::format(
      "payload:\n  id: test\n  state_dir: {}\nlidar:\n  model: Mid-360\n  source: udp\n  address: 127.0.0.1\n"
      "  port: {}\n  receive_buffer_bytes: 65536\nthreads:\n  lock_memory: false\n",
      (test::binary_dir() / "socket-overflow").string(), port);
  const std::unique_ptr<Pipeline> pipeline = test::live_pipeline(yaml);
  ASSERT_TRUE(test::start_and_wait_for_receiver(*pipeline));

  // 20 000 packet-sized datagrams as fast as one thread sends them, into a
  // buffer of some 50 (what they hold does not matter: undecodable ones are
  // counted bad after they were received).
  drivers::UdpSender sender("127.0.0.1", port);
  const std::vector<std::uint8_t> payload(1206, 0);
  std::uint64_t sent = 0;
  for (int i = 0; i < 20000; ++i) sent += sender.send(payload) ? 1 : 0;

  // The kernel reports its drop count with the next datagram it queues
  // (SO_RXQ_OVFL), as a sensor's steady stream brings: so a datagram every
  // 20 ms after the burst, until all are accounted for.
  const PipelineStats& s = pipeline->stats();
  const auto accounted = [&] { return s.datagrams.load() + s.socket_drops.load(); };
  for (int i = 0; i < 250 && accounted() < sent; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    sent += sender.send(payload) ? 1 : 0;
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  pipeline->end_source();
  pipeline->join();
  std::printf("sent %llu, received %llu, the kernel dropped %llu\n", static_cast<unsigned long long>(sent),
              static_cast<unsigned long long>(s.datagrams.load()), static_cast<unsigned long long>(s.socket_drops.load()));
  EXPECT_GT(sent, 19000U);
  EXPECT_EQ(accounted(), sent);
}

}  // namespace
}  // namespace adit::daemon
