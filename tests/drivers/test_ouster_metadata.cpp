#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "adit/common/error.hpp"
#include "adit/drivers/lidar/ouster_encoder.hpp"
#include "adit/drivers/lidar/ouster_metadata.hpp"
#include "shared_data.hpp"

namespace adit::drivers {
namespace {

namespace fs = std::filesystem;

std::vector<fs::path> json_files(const fs::path& dir) {
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.is_regular_file() && e.path().extension() == ".json") files.push_back(e.path());
  std::sort(files.begin(), files.end());
  return files;
}

TEST(OusterMetadataRealData, EveryWellFormedFileIsAccepted) {
  ADIT_REQUIRE_SHARED_DATA(dir, "lidar/ouster/metadata");
  const auto files = json_files(dir);
  ASSERT_GE(files.size(), 20U);
  for (const auto& f : files) {
    SCOPED_TRACE(f.filename().string());
    OusterMetadata m;
    ASSERT_NO_THROW(m = load_ouster_metadata(f));
    EXPECT_EQ(m.legacy_layout, f.filename().string().find("legacy") != std::string::npos ||
                                   f.filename().string().find("ouster-studio") != std::string::npos);
    EXPECT_EQ(static_cast<int>(m.beam_altitude_deg.size()), m.pixels_per_column);
    EXPECT_EQ(static_cast<int>(m.pixel_shift_by_row.size()), m.pixels_per_column);
    EXPECT_GT(m.columns_per_frame, 0);
    EXPECT_EQ(m.columns_per_frame % m.columns_per_packet, 0);
  }
}

TEST(OusterMetadataRealData, CaptureMetadataIsAccepted) {
  ADIT_REQUIRE_SHARED_DATA(dir, "lidar/ouster");
  int files = 0;
  for (const auto& f : json_files(dir)) {
    if (f.filename().string().ends_with("_digest.json")) continue;
    SCOPED_TRACE(f.filename().string());
    EXPECT_NO_THROW((void)load_ouster_metadata(f));
    ++files;
  }
  EXPECT_EQ(files, 3);
}

TEST(OusterMetadataRealData, EveryMalformedFileIsRejectedNamingFileAndProblem) {
  ADIT_REQUIRE_SHARED_DATA(dir, "lidar/ouster/metadata/malformed");
  const auto files = json_files(dir);
  ASSERT_GE(files.size(), 8U);
  for (const auto& f : files) {
    SCOPED_TRACE(f.filename().string());
    try {
      (void)load_ouster_metadata(f);
      ADD_FAILURE() << "accepted";
    } catch (const InputError& e) {
      EXPECT_EQ(e.where(), f.string());
      EXPECT_FALSE(e.reason().empty());
    }
  }
}

// The reason each malformed file is rejected, as the user sees it.
TEST(OusterMetadataRealData, MalformedFilesSayWhatIsWrong) {
  ADIT_REQUIRE_SHARED_DATA(dir, "lidar/ouster/metadata/malformed");
  const auto error_of = [&](const std::string& name) -> std::string {
    try {
      (void)load_ouster_metadata(dir / name);
    } catch (const InputError& e) {
      return e.key() + ": " + e.reason();
    }
    return "accepted";
  };
  EXPECT_EQ(error_of("complete_but_all_zeros_legacy.json").rfind("beam_altitude_angles: all zeros", 0), 0U);
  EXPECT_EQ(error_of("incomplete_data_format_legacy.json"), "data_format.columns_per_frame: missing key");
  EXPECT_EQ(error_of("incomplete_data_format_nonlegacy.json"), "lidar_data_format.pixels_per_column: missing key");
  EXPECT_EQ(error_of("incomplete_no_calref_nonlegacy.json"), "calibration_status: missing key");
  EXPECT_EQ(error_of("incomplete_no_sensor_info_nonlegacy.json"), "sensor_info: missing key");
  EXPECT_EQ(error_of("incorrect_nbeam_angles_legacy_113.json"),
            "beam_altitude_angles: 63 altitude angles but 64 azimuth angles (beam_azimuth_angles)");
  EXPECT_NE(error_of("garbled_legacy_and_nonlegacy.json").find("mixes the non-legacy layout"), std::string::npos);
  EXPECT_NE(error_of("legacy_with_calibration_status.json").find("(section 'calibration_status')"), std::string::npos);
}

TEST(OusterMetadataRealData, CaptureMetadataFields) {
  ADIT_REQUIRE_SHARED_DATA(dir, "lidar/ouster");
  const auto m = load_ouster_metadata(dir / "OS-0-128-U1_v2.3.0_1024x10.json");
  EXPECT_EQ(m.prod_line, "OS-0-128");
  EXPECT_EQ(m.firmware, "v2.3.0");
  EXPECT_EQ(m.lidar_profile, OusterProfile::rng15_rfl8_nir8);
  EXPECT_EQ(m.columns_per_frame, 1024);
  EXPECT_EQ(m.frame_rate_hz, 10);
  EXPECT_EQ(m.columns_per_packet, 16);
  EXPECT_EQ(m.pixels_per_column, 128);
  EXPECT_EQ(m.pixel_shift_by_row[0], 64);
  EXPECT_DOUBLE_EQ(m.lidar_origin_to_beam_origin_mm, 27.67);
  EXPECT_DOUBLE_EQ(m.beam_to_lidar[3], 27.67);
  EXPECT_DOUBLE_EQ(m.lidar_to_sensor[11], 36.18);
  EXPECT_DOUBLE_EQ(m.beam_altitude_deg[0], 45.75);
  EXPECT_EQ(m.column_window, (std::array<int, 2>{0, 1023}));

  const auto dual = load_ouster_metadata(dir / "metadata/3_0_1_os-122246000293-128.json");
  EXPECT_FALSE(dual.legacy_layout);
  EXPECT_EQ(dual.lidar_profile, OusterProfile::rng19_rfl8_sig16_nir16_dual);
  EXPECT_DOUBLE_EQ(dual.beam_to_lidar[3], 16.721);

  const auto window = load_ouster_metadata(dir / "metadata/2_5_0_os-992146000760-128_legacy.json");
  EXPECT_EQ(window.column_window, (std::array<int, 2>{912, 1022}));
}

// The nominal angles and destaggering are those of a real unit to within its
// unit-to-unit spread.
TEST(OusterMetadataRealData, SimulatorsNominalOs164IsCloseToARealOne) {
  ADIT_REQUIRE_SHARED_DATA(dir, "lidar/ouster/metadata");
  const OusterMetadata real = load_ouster_metadata(dir / "2_1_2_os1-991913000010-64_legacy.json");
  const OusterMetadata m = ouster_os1_64_nominal_metadata();
  ASSERT_EQ(real.pixels_per_column, m.pixels_per_column);
  EXPECT_EQ(real.lidar_mode, m.lidar_mode);
  EXPECT_DOUBLE_EQ(real.lidar_origin_to_beam_origin_mm, m.lidar_origin_to_beam_origin_mm);
  EXPECT_EQ(real.lidar_to_sensor, m.lidar_to_sensor);
  for (std::size_t i = 0; i < m.beam_altitude_deg.size(); ++i) {
    SCOPED_TRACE(i);
    EXPECT_NEAR(m.beam_altitude_deg[i], real.beam_altitude_deg[i], 0.2);
    EXPECT_NEAR(m.beam_azimuth_deg[i], real.beam_azimuth_deg[i], 0.35);
    EXPECT_NEAR(m.pixel_shift_by_row[i], real.pixel_shift_by_row[i], 1);
  }
}

TEST(OusterMetadata, Firmware112DefaultsApplyWhenDataFormatIsMissing) {
  const std::string text = R"({"lidar_mode": "1024x10",
    "beam_altitude_angles": [3, 1, -1, -3], "beam_azimuth_angles": [1, 0, 0, -1]})";
  const auto m = parse_ouster_metadata(text, "mem.json");
  EXPECT_TRUE(m.legacy_layout);
  EXPECT_EQ(m.pixels_per_column, 4);
  EXPECT_EQ(m.columns_per_packet, 16);
  EXPECT_EQ(m.pixel_shift_by_row, (std::vector<int>{18, 12, 6, 0}));
  EXPECT_EQ(m.column_window, (std::array<int, 2>{0, 1023}));
  EXPECT_EQ(m.lidar_profile, OusterProfile::legacy);
}

TEST(OusterMetadata, RejectsBadValuesWithTheirKey) {
  const auto key_of = [](const std::string& text) -> std::string {
    try {
      (void)parse_ouster_metadata(text, "mem.json");
    } catch (const InputError& e) {
      EXPECT_EQ(e.where(), "mem.json");
      return e.key();
    }
    return "accepted";
  };
  EXPECT_EQ(key_of("{"), "");
  EXPECT_EQ(key_of("[]"), "");
  EXPECT_EQ(key_of(R"({"lidar_mode": "999x3", "beam_altitude_angles": [1], "beam_azimuth_angles": [0]})"),
            "lidar_mode");
  EXPECT_EQ(key_of(R"({"lidar_mode": "512x10", "beam_altitude_angles": [1, "x"], "beam_azimuth_angles": [0, 0]})"),
            "beam_altitude_angles[1]");
  EXPECT_EQ(key_of(R"({"lidar_mode": "512x10", "beam_altitude_angles": [1], "beam_azimuth_angles": [0],
                       "lidar_to_sensor_transform": [1, 2, 3]})"),
            "lidar_to_sensor_transform");
  EXPECT_EQ(key_of(R"({"lidar_mode": "512x10", "beam_altitude_angles": [1], "beam_azimuth_angles": [0],
                       "data_format": {"columns_per_frame": 512, "columns_per_packet": 16, "pixels_per_column": 1,
                       "pixel_shift_by_row": [0], "udp_profile_lidar": "FOO"}})"),
            "data_format.udp_profile_lidar");
}

}  // namespace
}  // namespace adit::drivers
