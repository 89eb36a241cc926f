// The layout check in front of lcm-gen's decoders: every adit type encoded by
// LCM passes, lies about counts and string lengths do not.
#include <gtest/gtest.h>

#include <cstring>
#include <vector>

#include "adit/protocol/checked_decode.hpp"

namespace adit::protocol {
namespace {

template <typename M>
std::vector<std::uint8_t> encoded(const M& m) {
  std::vector<std::uint8_t> b(static_cast<std::size_t>(m.getEncodedSize()));
  m.encode(b.data(), 0, static_cast<int>(b.size()));
  return b;
}

// Every numeric field set: lcm-gen leaves them uninitialised.
command_t sample_command() {
  command_t c{};
  c.utime = 1;
  c.schema = 1;
  c.request_id = 42;
  c.payload_id = "rig1";
  c.verb = "EXPORT";
  c.args = {"s1", "format=las"};
  c.n_args = 2;
  c.auth = {1, 2, 3};
  c.auth_size = 3;
  return c;
}

template <typename M>
void expect_round_trip(const M& m) {
  const auto bytes = encoded(m);
  M back{};
  EXPECT_TRUE(checked_decode(bytes.data(), bytes.size(), back)) << M::getTypeName();
  EXPECT_EQ(encoded(back), bytes) << M::getTypeName();
  for (std::size_t cut : {std::size_t{0}, std::size_t{7}, bytes.size() / 2, bytes.size() - 1})
    EXPECT_FALSE(checked_decode(bytes.data(), cut, back)) << M::getTypeName() << " cut at " << cut;
  auto longer = bytes;
  longer.push_back(0);
  EXPECT_FALSE(checked_decode(longer.data(), longer.size(), back)) << M::getTypeName() << " with a trailing byte";
}

TEST(CheckedDecode, EveryTypeEncodedByLcmPasses) {
  expect_round_trip(sample_command());

  pose_t pose{};
  pose.session_id = "s1";
  expect_round_trip(pose);

  status_t status{};
  status.payload_id = "rig1";
  status.sensors = {{"lidar0", 10.0f, 3, 99, 0.001f}, {"imu", 200.0f, 0, 98, 0.0f}};
  status.n_sensors = 2;
  status.threads = {{"odometry", 0.5f, 2, 64}};
  status.n_threads = 1;
  status.fault = "none";
  expect_round_trip(status);

  command_ack_t ack{};
  ack.reason = "ok";
  ack.detail = "s0\ns1\n";
  expect_round_trip(ack);

  tile_index_t index{};
  index.tile_ids = {1, 2, 3};
  index.versions = {1, 1, 2};
  index.n_chunks = {1, 2, 3};
  index.n_points = {10, 20, 30};
  index.n_tiles = 3;
  expect_round_trip(index);

  tile_segment_t segment{};
  segment.data = {9, 8, 7, 6};
  segment.size = 4;
  expect_round_trip(segment);

  tile_request_t request{};
  request.tile_ids = {5, 6};
  request.versions = {1, 2};
  request.chunks = {-1, 3};
  request.n_entries = 2;
  expect_round_trip(request);

  file_request_t file_request{};
  file_request.path = "products/top_view.png";
  file_request.n_chunks = 64;
  expect_round_trip(file_request);

  file_chunk_t chunk{};
  chunk.path = "products/grid.yaml";
  chunk.data = {1, 2, 3};
  chunk.size = 3;
  chunk.n_chunks = 1;
  expect_round_trip(chunk);

  grid_patch_t patch{};
  patch.session_id = "s1";
  patch.data = {4, 5, 6, 7, 8};
  patch.size = 5;
  expect_round_trip(patch);

  frame_t frame{};
  frame.session_id = "s1";
  frame.source = frame_t::SOURCE_PRIOR_MAP;
  frame.orientation[0] = 1.0;
  frame.tiles_orientation[0] = 1.0;
  expect_round_trip(frame);

  graph_path_t path{};
  path.session_id = "s1";
  path.positions = {{1.0F, 2.0F, 3.0F}, {4.0F, 5.0F, 6.0F}};
  path.n = 2;
  expect_round_trip(path);

  loop_status_t loops{};
  loops.payload_id = "rig1";
  loops.session_id = "s1";
  loops.accepted = 3;
  loops.correction_m = 0.25F;
  loops.moves_map = 1;
  expect_round_trip(loops);
}

// Byte offset of n_args in sample_command(): hash, utime, schema, request id,
// "rig1" (4 + 5), "EXPORT" (4 + 7).
constexpr std::size_t kNArgsAt = 8 + 8 + 2 + 8 + 9 + 11;

TEST(CheckedDecode, CountsAndLengthsThatDoNotFitAreRefused) {
  const auto good = encoded(sample_command());
  command_t out;
  ASSERT_EQ(good[kNArgsAt + 3], 2);
  for (const std::uint32_t lie : {0x7fffffffu, 0xffffffffu, 3u}) {  // huge, negative, one too many
    auto bad = good;
    const std::uint8_t be[4] = {static_cast<std::uint8_t>(lie >> 24), static_cast<std::uint8_t>(lie >> 16),
                                static_cast<std::uint8_t>(lie >> 8), static_cast<std::uint8_t>(lie)};
    std::memcpy(bad.data() + kNArgsAt, be, 4);
    EXPECT_FALSE(checked_decode(bad.data(), bad.size(), out)) << lie;
  }
  auto zero_length = good;
  std::memset(zero_length.data() + 26, 0, 4);  // payload id length 0: lcm-gen would throw
  EXPECT_FALSE(checked_decode(zero_length.data(), zero_length.size(), out));
  auto no_nul = good;
  no_nul[26 + 4 + 4] = 'x';  // the payload id's terminating NUL
  EXPECT_FALSE(checked_decode(no_nul.data(), no_nul.size(), out));
  auto other_type = encoded(tile_segment_t{});
  EXPECT_FALSE(checked_decode(other_type.data(), other_type.size(), out));
}

}  // namespace
}  // namespace adit::protocol
