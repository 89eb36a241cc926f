// Bit-exact check of the Ouster decoding against the sensor maker's SDK: our
// digests of the test captures must equal the SDK's `*_digest.json` files.
#include <gtest/gtest.h>

#include <fstream>

#include <nlohmann/json.hpp>

#include "adit/common/error.hpp"
#include "adit/drivers/lidar/ouster_digest.hpp"
#include "shared_data.hpp"

namespace adit::drivers {
namespace {

namespace fs = std::filesystem;

nlohmann::ordered_json read_json(const fs::path& file) {
  std::ifstream in(file);
  return nlohmann::ordered_json::parse(in);
}

void expect_digest_matches(const fs::path& dir, const std::string& capture) {
  SCOPED_TRACE(capture);
  const auto expected = read_json(dir / (capture + "_digest.json"));
  const std::string ours_text = ouster_digest_json(dir / (capture + ".pcap"), dir / (capture + ".json"));
  const auto ours = nlohmann::ordered_json::parse(ours_text);
  // Same keys in the same order and the same checksums, field by field first
  // (readable failures), then as a whole.
  ASSERT_EQ(ours["packet_hash"].size(), expected["packet_hash"].size());
  for (const auto& [field, md5] : expected["packet_hash"].items()) EXPECT_EQ(ours["packet_hash"][field], md5) << field;
  ASSERT_EQ(ours["scans"].size(), expected["scans"].size());
  for (std::size_t s = 0; s < expected["scans"].size(); ++s)
    for (const auto& [field, md5] : expected["scans"][s].items()) EXPECT_EQ(ours["scans"][s][field], md5) << field;
  EXPECT_EQ(ours, expected);
  EXPECT_EQ(ours.dump(4), expected.dump(4));
}

TEST(OusterDigestRealData, LegacyProfileOs1_32MatchesTheSdk) {
  ADIT_REQUIRE_SHARED_DATA(dir, "lidar/ouster/OS-1-32-G_v2.1.1_1024x10_digest.json");
  expect_digest_matches(dir.parent_path(), "OS-1-32-G_v2.1.1_1024x10");
}

TEST(OusterDigestRealData, LowDataProfileOs0_128MatchesTheSdk) {
  ADIT_REQUIRE_SHARED_DATA(dir, "lidar/ouster/OS-0-128-U1_v2.3.0_1024x10_digest.json");
  expect_digest_matches(dir.parent_path(), "OS-0-128-U1_v2.3.0_1024x10");
}

TEST(OusterDigestRealData, ThreeFrameCaptureGivesThreeScans) {
  ADIT_REQUIRE_SHARED_DATA(dir, "lidar/ouster/OS-1-128_v2.3.0_1024x10_lb_n3.pcap");
  const auto ours = nlohmann::json::parse(
      ouster_digest_json(dir, dir.parent_path() / "OS-1-128_v2.3.0_1024x10.json"));
  ASSERT_EQ(ours["scans"].size(), 3U);
  // Consecutive frames, and different content in each.
  const int first = std::stoi(ours["scans"][0]["FRAME_ID"].get<std::string>());
  EXPECT_EQ(std::stoi(ours["scans"][1]["FRAME_ID"].get<std::string>()), first + 1);
  EXPECT_EQ(std::stoi(ours["scans"][2]["FRAME_ID"].get<std::string>()), first + 2);
  EXPECT_NE(ours["scans"][0]["RANGE"], ours["scans"][1]["RANGE"]);
}

TEST(OusterDigest, MissingFilesAreInputErrors) {
  EXPECT_THROW((void)ouster_digest_json("no-such.pcap", "no-such.json"), InputError);
}

}  // namespace
}  // namespace adit::drivers
