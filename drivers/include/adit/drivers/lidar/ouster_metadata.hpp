#pragma once
// Ouster sensor metadata (the JSON the sensor serves and recordings carry),
// firmware 1.12 through 3.x, in both layouts:
//   - non-legacy (fw >= 1.12 from the SDK's client): nested sections
//     sensor_info, beam_intrinsics, lidar_intrinsics, imu_intrinsics,
//     config_params, lidar_data_format, calibration_status;
//   - legacy (flat): beam_altitude_angles, lidar_mode, data_format, ... at the
//     top level, down to Ouster Studio's reduced config (angles + lidar_mode).
// The validation rules are listed in docs/LIDAR-OUSTER.md; anything else is
// rejected with an adit::InputError naming the file, the key and the problem.

#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace adit::drivers {

// The lidar UDP profiles (Ouster firmware manual, "Lidar Data Packet Format").
enum class OusterProfile : std::uint8_t {
  legacy,                 // fw 1.x/2.x default: 16-byte column header, 12-byte pixels
  rng19_rfl8_sig16_nir16, // single return, 12-byte pixels
  rng15_rfl8_nir8,        // low data rate, 4-byte pixels
  rng19_rfl8_sig16_nir16_dual,  // two returns, 16-byte pixels
};

std::optional<OusterProfile> parse_ouster_profile(std::string_view name);
std::string_view to_string(OusterProfile profile);

struct OusterMetadata {
  bool legacy_layout = false;  // which of the two JSON layouts the file used

  std::string prod_line;  // "OS-1-128"; empty when the file does not say
  std::string prod_sn;
  std::string firmware;   // build_rev, e.g. "v2.3.0"
  std::string lidar_mode; // "1024x10"
  int frame_rate_hz = 0;  // from lidar_mode: 5, 10 or 20

  std::vector<double> beam_altitude_deg;  // one per row (pixel of a column)
  std::vector<double> beam_azimuth_deg;
  double lidar_origin_to_beam_origin_mm = 0.0;
  // Row-major 4x4 homogeneous transforms, translations in mm.
  std::array<double, 16> beam_to_lidar{};
  std::array<double, 16> lidar_to_sensor{};
  std::array<double, 16> imu_to_sensor{};

  int columns_per_frame = 0;
  int columns_per_packet = 0;
  int pixels_per_column = 0;
  std::vector<int> pixel_shift_by_row;
  std::array<int, 2> column_window{};  // first and last measurement id sent, inclusive

  OusterProfile lidar_profile = OusterProfile::legacy;
  std::string imu_profile = "LEGACY";
  std::uint16_t udp_port_lidar = 7502;
  std::uint16_t udp_port_imu = 7503;
};

// `where` names the source in errors (the file name).
OusterMetadata parse_ouster_metadata(std::string_view json_text, const std::string& where);
// Reads and parses a file; throws adit::InputError naming it.
OusterMetadata load_ouster_metadata(const std::filesystem::path& file);

}  // namespace adit::drivers
