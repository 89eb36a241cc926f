#include "adit/drivers/lidar/ouster_metadata.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "adit/common/error.hpp"

namespace adit::drivers {
namespace {

using nlohmann::json;

// Sections that exist only in the non-legacy layout, and top-level keys that
// exist only in the legacy one. A file holding both is garbled.
constexpr std::array<std::string_view, 7> kNonLegacySections = {
    "sensor_info", "beam_intrinsics", "lidar_intrinsics", "imu_intrinsics",
    "config_params", "lidar_data_format", "calibration_status"};
constexpr std::array<std::string_view, 9> kLegacyKeys = {
    "beam_altitude_angles", "beam_azimuth_angles", "lidar_mode", "data_format",
    "lidar_to_sensor_transform", "imu_to_sensor_transform", "beam_to_lidar_transform",
    "lidar_origin_to_beam_origin_mm", "prod_line"};

// Firmware 1.x metadata carries no beam origin; the SDK's documented default
// for those (OS-1 gen 1) units is 12.163 mm.
constexpr double kDefaultBeamOriginMm = 12.163;
// The SDK's default lidar-to-sensor transform (a 180° turn about z, 36.18 mm up).
constexpr std::array<double, 16> kDefaultLidarToSensor = {-1, 0, 0, 0, 0, -1, 0, 0, 0, 0, 1, 36.18, 0, 0, 0, 1};
constexpr std::array<double, 16> kDefaultImuToSensor = {1, 0, 0, 6.253, 0, 1, 0, -11.775, 0, 0, 1, 7.645, 0, 0, 0, 1};

class Reader {
 public:
  explicit Reader(const std::string& where) : where_(where) {}

  [[noreturn]] void fail(const std::string& key, const std::string& reason) const {
    throw InputError(where_, key, reason);
  }

  const json& require(const json& obj, const std::string& prefix, std::string_view key) const {
    const auto it = obj.find(key);
    if (it == obj.end()) fail(join(prefix, key), "missing key");
    return *it;
  }

  const json& require_object(const json& obj, const std::string& prefix, std::string_view key) const {
    const json& v = require(obj, prefix, key);
    if (!v.is_object()) fail(join(prefix, key), fmt::format("expected an object, got {}", v.type_name()));
    return v;
  }

  double number(const json& v, const std::string& key) const {
    if (!v.is_number()) fail(key, fmt::format("expected a number, got {}", v.type_name()));
    const double d = v.get<double>();
    if (!std::isfinite(d)) fail(key, "not a finite number");
    return d;
  }

  int integer(const json& v, const std::string& key, int lo, int hi) const {
    if (!v.is_number_integer()) fail(key, fmt::format("expected an integer, got {}", v.type_name()));
    const auto i = v.get<std::int64_t>();
    if (i < lo || i > hi) fail(key, fmt::format("{} is outside [{}, {}]", i, lo, hi));
    return static_cast<int>(i);
  }

  std::string string(const json& v, const std::string& key) const {
    if (!v.is_string()) fail(key, fmt::format("expected a string, got {}", v.type_name()));
    return v.get<std::string>();
  }

  std::vector<double> numbers(const json& v, const std::string& key) const {
    if (!v.is_array()) fail(key, fmt::format("expected an array of numbers, got {}", v.type_name()));
    std::vector<double> out;
    out.reserve(v.size());
    for (std::size_t i = 0; i < v.size(); ++i) out.push_back(number(v[i], fmt::format("{}[{}]", key, i)));
    return out;
  }

  std::array<double, 16> transform(const json& v, const std::string& key) const {
    const auto n = numbers(v, key);
    if (n.size() != 16) fail(key, fmt::format("expected 16 numbers (a row-major 4x4 matrix), got {}", n.size()));
    if (n[12] != 0 || n[13] != 0 || n[14] != 0 || n[15] != 1)
      fail(key, "last row must be [0, 0, 0, 1]");
    std::array<double, 16> m{};
    std::copy(n.begin(), n.end(), m.begin());
    return m;
  }

  static std::string join(const std::string& prefix, std::string_view key) {
    return prefix.empty() ? std::string(key) : prefix + "." + std::string(key);
  }

 private:
  const std::string& where_;
};

std::string optional_string(const Reader& r, const json& obj, const std::string& prefix, std::string_view key) {
  const auto it = obj.find(key);
  return it == obj.end() ? std::string() : r.string(*it, Reader::join(prefix, key));
}

// "1024x10" -> 1024 columns at 10 Hz; the modes the firmware manual lists.
int columns_of_mode(const Reader& r, const std::string& mode, const std::string& key, int& rate_hz) {
  const auto x = mode.find('x');
  int cols = 0;
  int hz = 0;
  const bool parsed = x != std::string::npos &&
                      std::from_chars(mode.data(), mode.data() + x, cols).ec == std::errc() &&
                      std::from_chars(mode.data() + x + 1, mode.data() + mode.size(), hz).ec == std::errc();
  const bool known = (cols == 512 || cols == 1024 || cols == 2048 || cols == 4096) && (hz == 5 || hz == 10 || hz == 20);
  if (!parsed || !known)
    r.fail(key, fmt::format("unknown lidar_mode '{}' (expected 512x10, 1024x10, 2048x10, ...)", mode));
  rate_hz = hz;
  return cols;
}

// The firmware's default staggering when data_format is absent (fw < 1.14):
// OS-1 64-beam offsets of 3/2/1/0 per 4 beams, scaled by the mode's width
// (SDK default_data_format / firmware 1.13 manual).
std::vector<int> default_pixel_shift(int rows, int cols) {
  const int step = cols / 512 * 3;  // 3, 6, 12 px for 512, 1024, 2048
  std::vector<int> shift(static_cast<std::size_t>(rows));
  for (int i = 0; i < rows; ++i) shift[static_cast<std::size_t>(i)] = step * (3 - i % 4);
  return shift;
}

void parse_data_format(const Reader& r, const json& df, const std::string& prefix, OusterMetadata& m) {
  const int mode_cols = m.columns_per_frame;
  m.columns_per_frame = r.integer(r.require(df, prefix, "columns_per_frame"), prefix + ".columns_per_frame", 1, 8192);
  if (m.columns_per_frame != mode_cols)
    r.fail(prefix + ".columns_per_frame",
           fmt::format("{} disagrees with lidar_mode '{}'", m.columns_per_frame, m.lidar_mode));
  m.columns_per_packet =
      r.integer(r.require(df, prefix, "columns_per_packet"), prefix + ".columns_per_packet", 1, m.columns_per_frame);
  m.pixels_per_column = r.integer(r.require(df, prefix, "pixels_per_column"), prefix + ".pixels_per_column", 1, 512);
  const auto shifts = r.numbers(r.require(df, prefix, "pixel_shift_by_row"), prefix + ".pixel_shift_by_row");
  m.pixel_shift_by_row.clear();
  for (const double s : shifts) {
    if (s != std::floor(s) || std::abs(s) >= m.columns_per_frame)
      r.fail(prefix + ".pixel_shift_by_row", fmt::format("{} is not a column shift", s));
    m.pixel_shift_by_row.push_back(static_cast<int>(s));
  }
  if (const auto it = df.find("column_window"); it != df.end()) {
    const auto w = r.numbers(*it, prefix + ".column_window");
    if (w.size() != 2) r.fail(prefix + ".column_window", fmt::format("expected 2 numbers, got {}", w.size()));
    for (std::size_t i = 0; i < 2; ++i) {
      if (w[i] != std::floor(w[i]) || w[i] < 0 || w[i] >= m.columns_per_frame)
        r.fail(prefix + ".column_window", fmt::format("{} is not a column of a {}-column frame", w[i], m.columns_per_frame));
      m.column_window[i] = static_cast<int>(w[i]);
    }
  }
  if (const auto it = df.find("udp_profile_lidar"); it != df.end()) {
    const std::string name = r.string(*it, prefix + ".udp_profile_lidar");
    const auto profile = parse_ouster_profile(name);
    if (!profile) r.fail(prefix + ".udp_profile_lidar", fmt::format("unsupported profile '{}'", name));
    m.lidar_profile = *profile;
  }
  if (const auto it = df.find("udp_profile_imu"); it != df.end()) {
    m.imu_profile = r.string(*it, prefix + ".udp_profile_imu");
    if (m.imu_profile != "LEGACY") r.fail(prefix + ".udp_profile_imu", fmt::format("unsupported profile '{}'", m.imu_profile));
  }
}

void check_angles(const Reader& r, const std::string& prefix, OusterMetadata& m) {
  const std::string alt_key = Reader::join(prefix, "beam_altitude_angles");
  const std::string az_key = Reader::join(prefix, "beam_azimuth_angles");
  if (m.beam_altitude_deg.empty()) r.fail(alt_key, "no beam angles");
  if (m.beam_altitude_deg.size() != m.beam_azimuth_deg.size())
    r.fail(alt_key, fmt::format("{} altitude angles but {} azimuth angles ({})", m.beam_altitude_deg.size(),
                                m.beam_azimuth_deg.size(), az_key));
  if (static_cast<int>(m.beam_altitude_deg.size()) != m.pixels_per_column)
    r.fail(alt_key, fmt::format("{} beam angles but pixels_per_column is {}", m.beam_altitude_deg.size(),
                                m.pixels_per_column));
  const auto zero = [](double a) { return a == 0.0; };
  if (std::all_of(m.beam_altitude_deg.begin(), m.beam_altitude_deg.end(), zero))
    r.fail(alt_key, "all zeros: the sensor was not calibrated or the file was blanked");
  for (std::size_t i = 0; i < m.beam_altitude_deg.size(); ++i) {
    if (std::abs(m.beam_altitude_deg[i]) > 90.0) r.fail(fmt::format("{}[{}]", alt_key, i), "beyond ±90°");
    if (std::abs(m.beam_azimuth_deg[i]) > 45.0) r.fail(fmt::format("{}[{}]", az_key, i), "beyond ±45°");
  }
  if (m.pixel_shift_by_row.size() != m.beam_altitude_deg.size())
    r.fail(Reader::join(prefix, "pixel_shift_by_row"),
           fmt::format("{} shifts for {} beams", m.pixel_shift_by_row.size(), m.beam_altitude_deg.size()));
}

// Fills what a file may omit (fw 1.x, reduced configs) from the documented defaults.
void apply_defaults(OusterMetadata& m) {
  if (m.pixels_per_column == 0) m.pixels_per_column = static_cast<int>(m.beam_altitude_deg.size());
  if (m.columns_per_packet == 0) m.columns_per_packet = 16;
  if (m.pixel_shift_by_row.empty()) m.pixel_shift_by_row = default_pixel_shift(m.pixels_per_column, m.columns_per_frame);
  if (m.column_window == std::array<int, 2>{0, 0}) m.column_window = {0, m.columns_per_frame - 1};
}

std::uint16_t port(const Reader& r, const json& obj, const std::string& prefix, std::string_view key, std::uint16_t fallback) {
  const auto it = obj.find(key);
  if (it == obj.end()) return fallback;
  // 0 means "not configured" in the sensor's API: keep the default.
  const int p = r.integer(*it, Reader::join(prefix, key), 0, 65535);
  return p == 0 ? fallback : static_cast<std::uint16_t>(p);
}

void parse_beam_origin(const Reader& r, const json& obj, const std::string& prefix, OusterMetadata& m) {
  m.lidar_origin_to_beam_origin_mm = kDefaultBeamOriginMm;
  if (const auto it = obj.find("lidar_origin_to_beam_origin_mm"); it != obj.end()) {
    m.lidar_origin_to_beam_origin_mm = r.number(*it, Reader::join(prefix, "lidar_origin_to_beam_origin_mm"));
    if (m.lidar_origin_to_beam_origin_mm < 0 || m.lidar_origin_to_beam_origin_mm > 100)
      r.fail(Reader::join(prefix, "lidar_origin_to_beam_origin_mm"), "outside [0, 100] mm");
  }
  if (const auto it = obj.find("beam_to_lidar_transform"); it != obj.end()) {
    m.beam_to_lidar = r.transform(*it, Reader::join(prefix, "beam_to_lidar_transform"));
  } else {
    // Before fw 2.5 the beam origin is a pure radial offset (SDK default).
    m.beam_to_lidar = {1, 0, 0, m.lidar_origin_to_beam_origin_mm, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  }
}

OusterMetadata parse_legacy(const Reader& r, const json& root) {
  OusterMetadata m;
  m.legacy_layout = true;
  m.lidar_mode = r.string(r.require(root, "", "lidar_mode"), "lidar_mode");
  m.columns_per_frame = columns_of_mode(r, m.lidar_mode, "lidar_mode", m.frame_rate_hz);
  m.prod_line = optional_string(r, root, "", "prod_line");
  m.prod_sn = optional_string(r, root, "", "prod_sn");
  m.firmware = optional_string(r, root, "", "build_rev");
  m.beam_altitude_deg = r.numbers(r.require(root, "", "beam_altitude_angles"), "beam_altitude_angles");
  m.beam_azimuth_deg = r.numbers(r.require(root, "", "beam_azimuth_angles"), "beam_azimuth_angles");
  parse_beam_origin(r, root, "", m);
  const auto l2s = root.find("lidar_to_sensor_transform");
  m.lidar_to_sensor = l2s == root.end() ? kDefaultLidarToSensor : r.transform(*l2s, "lidar_to_sensor_transform");
  const auto i2s = root.find("imu_to_sensor_transform");
  m.imu_to_sensor = i2s == root.end() ? kDefaultImuToSensor : r.transform(*i2s, "imu_to_sensor_transform");
  if (const auto it = root.find("data_format"); it != root.end()) {
    if (!it->is_object()) r.fail("data_format", fmt::format("expected an object, got {}", it->type_name()));
    parse_data_format(r, *it, "data_format", m);
  }
  m.udp_port_lidar = port(r, root, "", "udp_port_lidar", 7502);
  m.udp_port_imu = port(r, root, "", "udp_port_imu", 7503);
  apply_defaults(m);
  check_angles(r, "", m);
  return m;
}

OusterMetadata parse_non_legacy(const Reader& r, const json& root) {
  OusterMetadata m;
  const json& info = r.require_object(root, "", "sensor_info");
  const json& beams = r.require_object(root, "", "beam_intrinsics");
  const json& lidar = r.require_object(root, "", "lidar_intrinsics");
  const json& config = r.require_object(root, "", "config_params");
  // calibration_status is a string ("error: Command not recognized.") on fw
  // 1.12/1.13 and an object since; its absence means a truncated dump.
  r.require(root, "", "calibration_status");
  const json& data_format = r.require(root, "", "lidar_data_format");

  m.prod_line = r.string(r.require(info, "sensor_info", "prod_line"), "sensor_info.prod_line");
  m.prod_sn = r.string(r.require(info, "sensor_info", "prod_sn"), "sensor_info.prod_sn");
  m.firmware = r.string(r.require(info, "sensor_info", "build_rev"), "sensor_info.build_rev");
  m.lidar_mode = r.string(r.require(config, "config_params", "lidar_mode"), "config_params.lidar_mode");
  m.columns_per_frame = columns_of_mode(r, m.lidar_mode, "config_params.lidar_mode", m.frame_rate_hz);
  m.beam_altitude_deg = r.numbers(r.require(beams, "beam_intrinsics", "beam_altitude_angles"),
                                  "beam_intrinsics.beam_altitude_angles");
  m.beam_azimuth_deg = r.numbers(r.require(beams, "beam_intrinsics", "beam_azimuth_angles"),
                                 "beam_intrinsics.beam_azimuth_angles");
  parse_beam_origin(r, beams, "beam_intrinsics", m);
  m.lidar_to_sensor = r.transform(r.require(lidar, "lidar_intrinsics", "lidar_to_sensor_transform"),
                                  "lidar_intrinsics.lidar_to_sensor_transform");
  m.imu_to_sensor = kDefaultImuToSensor;
  if (const auto it = root.find("imu_intrinsics"); it != root.end() && it->is_object())
    m.imu_to_sensor = r.transform(r.require(*it, "imu_intrinsics", "imu_to_sensor_transform"),
                                  "imu_intrinsics.imu_to_sensor_transform");
  // Firmware 1.12/1.13 answers the data-format query with an error string:
  // the documented defaults apply. An object must be complete.
  if (data_format.is_object()) parse_data_format(r, data_format, "lidar_data_format", m);
  m.udp_port_lidar = port(r, config, "config_params", "udp_port_lidar", 7502);
  m.udp_port_imu = port(r, config, "config_params", "udp_port_imu", 7503);
  apply_defaults(m);
  check_angles(r, "beam_intrinsics", m);
  return m;
}

}  // namespace

std::optional<OusterProfile> parse_ouster_profile(std::string_view name) {
  if (name == "LEGACY") return OusterProfile::legacy;
  if (name == "RNG19_RFL8_SIG16_NIR16") return OusterProfile::rng19_rfl8_sig16_nir16;
  if (name == "RNG15_RFL8_NIR8") return OusterProfile::rng15_rfl8_nir8;
  if (name == "RNG19_RFL8_SIG16_NIR16_DUAL") return OusterProfile::rng19_rfl8_sig16_nir16_dual;
  return std::nullopt;
}

std::string_view to_string(OusterProfile profile) {
  switch (profile) {
    case OusterProfile::legacy: return "LEGACY";
    case OusterProfile::rng19_rfl8_sig16_nir16: return "RNG19_RFL8_SIG16_NIR16";
    case OusterProfile::rng15_rfl8_nir8: return "RNG15_RFL8_NIR8";
    case OusterProfile::rng19_rfl8_sig16_nir16_dual: return "RNG19_RFL8_SIG16_NIR16_DUAL";
  }
  return "?";
}

OusterMetadata parse_ouster_metadata(std::string_view json_text, const std::string& where) {
  const Reader r(where);
  const json root = json::parse(json_text, nullptr, /*allow_exceptions=*/false);
  if (root.is_discarded()) r.fail("", "not valid JSON");
  if (!root.is_object()) r.fail("", fmt::format("expected a JSON object at the top, got {}", root.type_name()));

  const auto first_of = [&root](const auto& keys) -> std::string_view {
    for (const auto k : keys)
      if (root.contains(k)) return k;
    return {};
  };
  const std::string_view nested = first_of(kNonLegacySections);
  const std::string_view flat = first_of(kLegacyKeys);
  if (!nested.empty() && !flat.empty())
    r.fail(std::string(nested), fmt::format("mixes the non-legacy layout (section '{}') with the legacy flat layout "
                                            "(key '{}'); the file is garbled",
                                            nested, flat));
  return nested.empty() ? parse_legacy(r, root) : parse_non_legacy(r, root);
}

OusterMetadata load_ouster_metadata(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file.string(), "", "cannot open the metadata file");
  std::ostringstream text;
  text << in.rdbuf();
  return parse_ouster_metadata(text.str(), file.string());
}

}  // namespace adit::drivers
