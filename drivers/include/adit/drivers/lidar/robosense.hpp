#pragma once
// RoboSense RS-16 and Helios 16P decoding (RS-LiDAR-16 and RS-Helios-16P user
// manuals): 1248-byte big-endian MSOP packets on UDP 6699, 12 blocks of
// (0xFFEE, azimuth, 32 x (distance, reflectivity)). 16 lasers: in single-return
// mode a block holds two firing sequences of 16, in dual-return mode one
// sequence with both returns (channels 0-15 first, 16-31 second). DIFOP
// packets (UDP 7788) carry the angle calibration and return mode; without them
// the calibration CSV and the configured return mode apply.

#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "adit/drivers/lidar/decoder.hpp"

namespace adit::drivers {

enum class RoboSenseModel : std::uint8_t { rs16, helios16p };
enum class RoboSenseReturnMode : std::uint8_t { single, dual };
// Which angles win when a DIFOP packet arrives: the sensor's (default), or the CSV given
// (to reproduce a pipeline calibrated from the file; the return mode still follows DIFOP).
enum class RoboSenseAngleSource : std::uint8_t { difop_when_present, csv_only };

// "RS-16"/"RS16", "Helios16P"/"Helios-16P" (case-insensitive); nullopt otherwise.
std::optional<RoboSenseModel> robosense_model_from_name(std::string_view name);
std::string_view robosense_model_name(RoboSenseModel model);
// The model whose MSOP data packet this is (magic and size), nullopt otherwise (DIFOP included).
std::optional<RoboSenseModel> robosense_model_from_packet(std::span<const std::uint8_t> payload);

inline constexpr std::size_t kRoboSenseMsopSize = 1248;
// The models' firing timing (user manuals' tables), shared by the decoder and
// the simulator's encoder: channel c (0..31) of a single-return block fires
// firing_us[c] after the block starts (laser c % 16); blocks are two sequences.
std::span<const float, 32> robosense_firing_us(RoboSenseModel model);
float robosense_sequence_us(RoboSenseModel model);
double robosense_lens_offset_m(RoboSenseModel model);  // RX: receiving lens ahead of the axis
std::span<const std::uint8_t> robosense_magic(RoboSenseModel model);

// Per-laser angles in laser order (16 rows), degrees.
struct RoboSenseAngles {
  std::vector<float> elevation_deg;
  std::vector<float> azimuth_deg;  // horizontal offset added to the firing azimuth
};

// The calibration CSV: one row per laser, "elevation[,azimuth]" in degrees
// (blanks and tabs ignored). Throws adit::InputError naming `source`:line.
RoboSenseAngles parse_robosense_angle_csv(std::string_view text, const std::string& source);
RoboSenseAngles load_robosense_angle_csv(const std::filesystem::path& file);

struct RoboSenseCounters {
  std::uint64_t difop_packets = 0;
  std::uint64_t difop_calibrations_applied = 0;
};

class RoboSenseDecoder final : public LidarDecoder {
 public:
  // `angles` from the CSV; DIFOP packets, when they arrive, replace them and the return mode.
  RoboSenseDecoder(RoboSenseModel model, const RoboSenseAngles& angles, RoboSenseReturnMode mode,
                   RoboSenseAngleSource source = RoboSenseAngleSource::difop_when_present);

  std::string_view model() const override;
  std::uint16_t default_port() const override { return 6699; }
  std::uint16_t difop_port() const { return 7788; }
  std::size_t max_points_per_packet() const override { return points_.size(); }
  // MSOP packets decode to points; DIFOP packets come back as `auxiliary`.
  DecodedPacket decode(std::span<const std::uint8_t> payload, std::int64_t host_time_ns) override;

  RoboSenseReturnMode return_mode() const { return mode_; }
  const RoboSenseCounters& counters() const { return counters_; }

 private:
  void set_angles(const std::array<std::int32_t, 16>& vertical, const std::array<std::int32_t, 16>& horizontal);
  void set_mode(RoboSenseReturnMode mode);
  DecodedPacket decode_difop(std::span<const std::uint8_t> p);

  RoboSenseModel model_;
  RoboSenseReturnMode mode_;
  RoboSenseAngleSource angle_source_;
  // Angles in the SDK's 0.01 degree integer steps, as the sensor reports them.
  std::array<std::int32_t, 16> vertical_{};
  std::array<std::int32_t, 16> horizontal_{};
  std::array<std::uint16_t, 16> ring_{};
  // Per channel 0..31 for the current return mode: firing time after the block's, and
  // the fraction of the block-to-block azimuth step travelled by then.
  std::array<std::int32_t, 32> firing_ns_{};
  std::array<float, 32> azimuth_fraction_{};
  std::int32_t block_period_ns_ = 0;
  std::int32_t nominal_step_ = 0;  // azimuth steps per firing sequence at the DIFOP motor speed
  std::vector<float> cos_, sin_;  // per 0.01 degree
  std::vector<DecodedPoint> points_;
  RoboSenseCounters counters_;
};

std::unique_ptr<LidarDecoder> make_robosense_decoder(
    std::string_view model, const std::filesystem::path& calibration_csv, RoboSenseReturnMode mode,
    RoboSenseAngleSource source = RoboSenseAngleSource::difop_when_present);

}  // namespace adit::drivers
