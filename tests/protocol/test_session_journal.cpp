// The session journal's records: round trips, and a reader that stops at
// the first torn or damaged record wherever a crash cut the file.
#include <gtest/gtest.h>

#include <random>

#include "adit/protocol/session_journal.hpp"

namespace adit::protocol {
namespace {

std::vector<std::uint8_t> record(JournalRecordType type, const std::vector<std::uint8_t>& payload) {
  std::vector<std::uint8_t> out;
  append_journal_record(out, type, payload);
  return out;
}

JournalTilePoints some_tile(std::size_t n, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-20.0, 20.0);
  JournalTilePoints t;
  t.tile = {-1, 2, 0};
  for (std::size_t i = 0; i < n; ++i)
    t.points.push_back({u(rng), u(rng), u(rng), static_cast<float>(i % 256), 1.7e9 + 0.1 * static_cast<double>(i / 100)});
  return t;
}

// A journal of a header, then poses, tiles and keyframes; `ends` holds each record's end offset.
std::vector<std::uint8_t> journal(std::vector<std::size_t>& ends) {
  std::vector<std::uint8_t> out;
  const std::string header = R"({"session":"x","tile_size_m":20})";
  append_journal_record(out, JournalRecordType::header, std::vector<std::uint8_t>(header.begin(), header.end()));
  ends.push_back(out.size());
  for (int k = 0; k < 5; ++k) {
    std::vector<std::uint8_t> payload;
    encode_journal_pose({1000 + k, {1.0 * k, 2.0, 3.0}, {1, 0, 0, 0}}, payload);
    append_journal_record(out, JournalRecordType::map_pose, payload);
    ends.push_back(out.size());
    payload.clear();
    encode_journal_tile_points(some_tile(50 + 10 * static_cast<std::size_t>(k), static_cast<std::uint32_t>(k)), payload);
    append_journal_record(out, JournalRecordType::tile_points, payload);
    ends.push_back(out.size());
  }
  append_journal_record(out, JournalRecordType::end, {});  // an empty payload (from a null span)
  ends.push_back(out.size());
  return out;
}

TEST(SessionJournal, PayloadsRoundTripExactly) {
  const JournalPose pose{123456789012345, {1.5, -2.25, 3.125}, {0.5, 0.5, -0.5, 0.5}};
  std::vector<std::uint8_t> bytes;
  encode_journal_pose(pose, bytes);
  JournalPose back;
  ASSERT_TRUE(decode_journal_pose(bytes, back));
  EXPECT_EQ(back.stamp_ns, pose.stamp_ns);
  EXPECT_EQ(back.position, pose.position);
  EXPECT_EQ(back.orientation, pose.orientation);

  const JournalTilePoints tile = some_tile(1000, 3);
  bytes.clear();
  encode_journal_tile_points(tile, bytes);
  JournalTilePoints tile_back;
  ASSERT_TRUE(decode_journal_tile_points(bytes, tile_back));
  EXPECT_EQ(tile_back.tile, tile.tile);
  ASSERT_EQ(tile_back.points.size(), tile.points.size());
  for (std::size_t i = 0; i < tile.points.size(); ++i) {  // lossless: the map's own numbers
    EXPECT_EQ(tile_back.points[i].x, tile.points[i].x);
    EXPECT_EQ(tile_back.points[i].z, tile.points[i].z);
    EXPECT_EQ(tile_back.points[i].intensity, tile.points[i].intensity);
    EXPECT_EQ(tile_back.points[i].time, tile.points[i].time);
  }
  EXPECT_LT(bytes.size(), tile.points.size() * 36);  // compressed below the raw 36 B a point

  const JournalKeyframe keyframe{pose, {{1.0F, 2.0F, 3.0F}, {-4.0F, 5.5F, 0.25F}}};
  bytes.clear();
  encode_journal_keyframe(keyframe, bytes);
  JournalKeyframe keyframe_back;
  ASSERT_TRUE(decode_journal_keyframe(bytes, keyframe_back));
  EXPECT_EQ(keyframe_back.points, keyframe.points);
  EXPECT_EQ(keyframe_back.pose.stamp_ns, pose.stamp_ns);
}

TEST(SessionJournal, ReadsEveryRecordOfAWholeJournal) {
  std::vector<std::size_t> ends;
  const std::vector<std::uint8_t> bytes = journal(ends);
  JournalReader reader(bytes);
  std::size_t n = 0;
  while (reader.next()) ++n;
  EXPECT_EQ(n, ends.size());
  EXPECT_EQ(reader.good_bytes(), bytes.size());
  EXPECT_EQ(reader.stop_reason(), "");
}

// A crash can cut the file anywhere: the reader keeps exactly the whole records before the cut.
TEST(SessionJournal, ATornTailIsCutAtTheLastWholeRecordWhereverTheFileEnds) {
  std::vector<std::size_t> ends;
  const std::vector<std::uint8_t> bytes = journal(ends);
  for (std::size_t cut = 0; cut <= bytes.size(); ++cut) {
    JournalReader reader(std::span<const std::uint8_t>(bytes).first(cut));
    std::size_t n = 0;
    while (reader.next()) ++n;
    const std::size_t whole = static_cast<std::size_t>(std::upper_bound(ends.begin(), ends.end(), cut) - ends.begin());
    ASSERT_EQ(n, whole) << "cut at byte " << cut;
    ASSERT_EQ(reader.good_bytes(), whole == 0 ? 0 : ends[whole - 1]);
    ASSERT_EQ(reader.stop_reason().empty(), whole == 0 ? cut == 0 : ends[whole - 1] == cut) << cut;
  }
}

// A damaged byte (a page the disk never wrote) stops the reader at its record.
TEST(SessionJournal, ADamagedByteStopsTheReaderAtItsRecord) {
  std::vector<std::size_t> ends;
  const std::vector<std::uint8_t> clean = journal(ends);
  std::mt19937 rng(5);
  for (int trial = 0; trial < 300; ++trial) {
    std::vector<std::uint8_t> bytes = clean;
    const std::size_t at = std::uniform_int_distribution<std::size_t>(0, bytes.size() - 1)(rng);
    bytes[at] ^= static_cast<std::uint8_t>(1U << (trial % 8));
    JournalReader reader(bytes);
    std::size_t n = 0;
    while (reader.next()) ++n;
    const std::size_t damaged = static_cast<std::size_t>(std::upper_bound(ends.begin(), ends.end(), at) - ends.begin());
    ASSERT_EQ(n, damaged) << "byte " << at;
    EXPECT_NE(reader.stop_reason(), "");
  }
}

TEST(SessionJournal, MalformedPayloadsAreRefusedNotRead) {
  JournalTilePoints tile;
  JournalPose pose;
  JournalKeyframe keyframe;
  const std::vector<std::uint8_t> empty;
  EXPECT_FALSE(decode_journal_pose(empty, pose));
  EXPECT_FALSE(decode_journal_tile_points(empty, tile));
  EXPECT_FALSE(decode_journal_keyframe(empty, keyframe));
  std::vector<std::uint8_t> bytes;
  encode_journal_tile_points(some_tile(100, 1), bytes);
  bytes[12] ^= 0x40;  // the point count no longer matches the compressed points
  EXPECT_FALSE(decode_journal_tile_points(bytes, tile));
  EXPECT_EQ(record(JournalRecordType::end, {}).size(), kJournalRecordHeader);
}

}  // namespace
}  // namespace adit::protocol
