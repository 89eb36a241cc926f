// The RAV4 drive: decoding against an independent decoder's output, and log
// round trip on a real recording.

#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "adit/drivers/can/candump.hpp"
#include "adit/drivers/can/dbc.hpp"
#include "adit/drivers/can/decoder.hpp"
#include "shared_data.hpp"

namespace can = adit::drivers::can;

TEST(Rav4, WheelSpeedsReproduceTheReferenceExactly) {
  ADIT_REQUIRE_SHARED_DATA(dir, "can/toyota-rav4-2017");
  const can::Database db = can::load_dbc(dir / "toyota_rav4_2017.dbc");
  const std::vector<std::string> wanted{"WHEEL_SPEED_FL", "WHEEL_SPEED_FR", "WHEEL_SPEED_RL", "WHEEL_SPEED_RR"};
  can::SignalDecoder decoder(db.messages, wanted);
  std::vector<double> v(decoder.slot_count());
  std::vector<int> slot;
  for (const auto& w : wanted) slot.push_back(decoder.slot(w));

  // The reference prints m/s with 6 decimals: the DBC value (raw * 0.01 -
  // 67.67 km/h) divided by 3.6, rounded half away from zero by printf. The
  // exact value is (raw - 6767) / 360 m/s, whose 7th-decimal remainder is a
  // multiple of 1/9, never a tie, so our double formatted the same way must
  // match character for character. speed_mean is the mean of the four.
  std::ifstream ref(dir / "reference-wheel-speeds.csv");
  std::string line;
  std::getline(ref, line);  // comment
  std::getline(ref, line);  // header
  ASSERT_EQ(line, "t,fl,fr,rl,rr,speed_mean");

  can::CandumpReader reader(dir / "drive.candump.log");
  can::Frame f;
  std::size_t compared = 0;
  std::size_t mismatches = 0;
  while (reader.next(f)) {
    if (f.interface_name() != "can0") continue;
    if (decoder.decode(f, v).status != can::DecodeStatus::decoded) continue;
    const double fl = v[slot[0]], fr = v[slot[1]], rl = v[slot[2]], rr = v[slot[3]];
    const std::string ours = fmt::format("{}.{:06d},{:.6f},{:.6f},{:.6f},{:.6f},{:.6f}", f.time_us / 1'000'000,
                                         f.time_us % 1'000'000, fl, fr, rl, rr, (fl + fr + rl + rr) / 4);
    ASSERT_TRUE(std::getline(ref, line)) << "reference ends before frame " << compared;
    if (ours != line && ++mismatches <= 5) ADD_FAILURE() << "sample " << compared << ": ours " << ours << " reference " << line;
    ++compared;
  }
  EXPECT_FALSE(std::getline(ref, line)) << "reference has more samples than the log";
  EXPECT_EQ(compared, 4974U);
  EXPECT_EQ(mismatches, 0U);
  EXPECT_EQ(reader.stats().malformed, 0U);
}

TEST(Rav4, WholeLogWrittenBackIsByteIdentical) {
  ADIT_REQUIRE_SHARED_DATA(dir, "can/toyota-rav4-2017");
  const auto out = std::filesystem::temp_directory_path() / "adit-rav4-roundtrip.log";
  std::size_t frames = 0;
  {
    can::CandumpReader reader(dir / "drive.candump.log");
    can::CandumpWriter writer(out);
    can::Frame f;
    while (reader.next(f)) {
      writer.write(f);
      ++frames;
    }
    EXPECT_EQ(reader.stats().malformed, 0U);
  }
  EXPECT_EQ(frames, 135468U);
  const auto slurp = [](const std::filesystem::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
  };
  EXPECT_TRUE(slurp(out) == slurp(dir / "drive.candump.log"));
  std::filesystem::remove(out);
}

TEST(Rav4, EveryDbcMessageDecodesAndOtherIdsAreCounted) {
  ADIT_REQUIRE_SHARED_DATA(dir, "can/toyota-rav4-2017");
  const can::Database db = can::load_dbc(dir / "toyota_rav4_2017.dbc");
  EXPECT_GT(db.messages.size(), 50U);
  can::SignalDecoder decoder(db.messages);
  std::vector<double> v(decoder.slot_count());
  can::CandumpReader reader(dir / "drive.candump.log");
  can::Frame f;
  while (reader.next(f)) decoder.decode(f, v);
  const can::DecoderStats& s = decoder.stats();
  EXPECT_EQ(s.decoded + s.unknown_id + s.wrong_length + s.not_data, 135468U);
  EXPECT_GT(s.decoded, 4974U);
  EXPECT_GT(s.unknown_id, 0U);
  fmt::print("decoded {} unknown id {} wrong length {}\n", s.decoded, s.unknown_id, s.wrong_length);
}
