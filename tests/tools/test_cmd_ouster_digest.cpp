// `adit decode FILE --ouster-digest` end to end: the printed JSON equals the
// Ouster SDK's digest file of the same capture, field by field.

#include <gtest/gtest.h>

#include <fstream>

#include <nlohmann/json.hpp>

#include "run_program.hpp"
#include "shared_data.hpp"

namespace adit::test {
namespace {

TEST(CmdOusterDigest, PrintsTheSdkDigestOfEachCapture) {
  ADIT_REQUIRE_SHARED_DATA(dir, "lidar/ouster");
  for (const char* name : {"OS-1-32-G_v2.1.1_1024x10", "OS-0-128-U1_v2.3.0_1024x10"}) {
    const auto r = run_program({(binary_dir() / "bin/adit").string(), "decode", (dir / (std::string(name) + ".pcap")).string(),
                                "--calibration", (dir / (std::string(name) + ".json")).string(), "--ouster-digest"});
    ASSERT_EQ(r.exit_status, 0) << r.err;
    std::ifstream expected_file(dir / (std::string(name) + "_digest.json"));
    EXPECT_EQ(nlohmann::json::parse(r.out), nlohmann::json::parse(expected_file)) << name;
  }
}

TEST(CmdOusterDigest, WithoutMetadataItExitsWithStatus2) {
  ADIT_REQUIRE_SHARED_DATA(dir, "lidar/ouster");
  const auto r = run_program({(binary_dir() / "bin/adit").string(), "decode",
                              (dir / "OS-1-32-G_v2.1.1_1024x10.pcap").string(), "--ouster-digest"});
  EXPECT_EQ(r.exit_status, 2);
  EXPECT_NE(r.err.find("--ouster-digest needs the sensor metadata JSON"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace adit::test
