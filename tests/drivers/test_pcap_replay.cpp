// The paced reader behind replays and the loopback sender: datagrams are
// released at their recorded spacing over the speed; one held up catches up,
// or, given a catch-up limit, resumes the recorded pace as a sensor would.
#include "adit/drivers/pcap_replay.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <thread>
#include <vector>

#include "adit/common/clock.hpp"
#include "pcap_builder.hpp"

namespace adit::drivers {
namespace {

constexpr int kDatagrams = 12;
constexpr std::int64_t kSpacingNs = 20'000'000;
constexpr auto kStall = std::chrono::milliseconds(150);  // holds 7 datagrams' worth

std::filesystem::path evenly_spaced_capture(const std::string& name) {
  test::PcapBuilder pcap;
  const test::Bytes payload(64, 0x5A);
  for (int i = 0; i < kDatagrams; ++i)
    pcap.add(100, static_cast<std::uint32_t>(i * kSpacingNs / 1000),
             test::ethernet_frame(test::ipv4_packet({}, test::udp_segment(2368, 2368, payload))));
  const auto file = test::scratch_file(name);
  pcap.write(file);
  return file;
}

struct Released {
  std::vector<std::int64_t> at_ns;        // monotonic release time per datagram
  std::vector<std::int64_t> lateness_ns;  // as the reader reports it
};

// Reads the first datagram, stalls as a descheduled sender would, reads the rest.
Released read_with_a_stall(PacedPcapReader& reader) {
  Released r;
  UdpDatagram d;
  bool first = true;
  while (reader.next(d)) {
    r.at_ns.push_back(monotonic_ns());
    r.lateness_ns.push_back(reader.last_lateness_ns());
    if (first) std::this_thread::sleep_for(kStall);
    first = false;
  }
  return r;
}

TEST(PacedPcapReader, AHeldUpReaderCatchesUpByDefault) {
  const auto file = evenly_spaced_capture("paced-catch-up.pcap");
  PacedPcapReader reader(file, 1.0);
  const Released r = read_with_a_stall(reader);
  ASSERT_EQ(r.at_ns.size(), static_cast<std::size_t>(kDatagrams));
  // Datagram 7 was due 140 ms after the first and is read after the 150 ms
  // stall: released late rather than 20 ms after datagram 6.
  EXPECT_GE(r.lateness_ns[7], 10'000'000);
  // The replay as a whole keeps the recording's duration.
  EXPECT_GE(r.at_ns.back() - r.at_ns.front(), (kDatagrams - 1) * kSpacingNs);
  std::filesystem::remove(file);
}

TEST(PacedPcapReader, WithACatchUpLimitAHeldUpReaderResumesTheRecordedPace) {
  const auto file = evenly_spaced_capture("paced-resume.pcap");
  PacedPcapReader reader(file, 1.0, 5'000'000);
  const Released r = read_with_a_stall(reader);
  ASSERT_EQ(r.at_ns.size(), static_cast<std::size_t>(kDatagrams));
  // Datagram 1 comes straight after the stall; every later one keeps its
  // recorded spacing from there (sleeping never ends early: a lower bound
  // that holds on a loaded machine), so no overdue burst is released.
  for (int i = 2; i < kDatagrams; ++i)
    EXPECT_GE(r.at_ns[static_cast<std::size_t>(i)] - r.at_ns[1], (i - 1) * kSpacingNs) << "datagram " << i;
  std::filesystem::remove(file);
}

}  // namespace
}  // namespace adit::drivers
