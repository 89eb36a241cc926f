#pragma once
// Velodyne VLP-16, VLP-32C, HDL-32E and VLS-128: one calibration-driven decoder.
//
// Data packets (UDP 2368, 1206 bytes): 12 blocks of 100 bytes (flag, azimuth
// in 0.01°, 32 × (distance, reflectivity)), a u32 timestamp in µs past the top
// of the hour and two factory bytes (return mode, product id). The models
// differ only in the table built here from the manuals' firing timing: which
// laser each channel slot holds and when it fires. Position packets (UDP 8308,
// 512 bytes) carry the same µs timestamp and an NMEA $GPRMC sentence.
//
// Sources: VLP-16 User Manual rev. E §9 (packet format, "Firing timing",
// "Precision azimuth calculation"); VLP-32C User Manual rev. B §9;
// HDL-32E User Manual §9 and appendix; VLS-128 User Manual (63-9480) §9.
// VLS-128 dual return: one firing sequence per packet, blocks 0-7 = banks
// FFEE, FFDD, FFCC, FFBB each as a (last, strongest) pair, blocks 8-11 padding.

#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "adit/drivers/lidar/decoder.hpp"
#include "adit/drivers/lidar/sensor_clock.hpp"
#include "adit/drivers/nmea.hpp"

namespace adit::drivers {

enum class VelodyneModel : std::uint8_t { vlp16, vlp32c, hdl32e, vls128 };
enum class VelodyneReturnMode : std::uint8_t { strongest = 0x37, last = 0x38, dual = 0x39 };

std::string_view to_string(VelodyneModel model);
// Accepts "VLP-16"/"VLP16"/"Puck", "VLP-32C"/"VLP32C", "HDL-32E"/"HDL32", "VLS-128"/"VLS128" (case-insensitive).
std::optional<VelodyneModel> velodyne_model_from_name(std::string_view name);
// From a data packet's product byte; nullopt when it is not a Velodyne data packet we know.
std::optional<VelodyneModel> velodyne_model_from_packet(std::span<const std::uint8_t> payload);
std::optional<VelodyneReturnMode> velodyne_return_mode_from_packet(std::span<const std::uint8_t> payload);
// Time between data packets (ns) from the firing timing, for scan assembly's loss counting.
std::int64_t velodyne_packet_period_ns(VelodyneModel model, VelodyneReturnMode mode);
std::size_t velodyne_lasers(VelodyneModel model);

// The firing-timing table of the manuals, shared by the decoder and the
// simulator's encoder: channel `channel` of block `block_in_group` of a firing
// group holds laser `laser`, which fires `time_ns` after the group starts.
struct VelodyneFiring {
  std::uint16_t laser = 0;
  std::uint32_t time_ns = 0;
};
VelodyneFiring velodyne_firing(VelodyneModel model, std::size_t block_in_group, std::size_t channel);
std::uint32_t velodyne_group_ns(VelodyneModel model);        // one firing group to the next
std::size_t velodyne_blocks_per_group(VelodyneModel model);  // blocks sharing one azimuth
float velodyne_distance_resolution_m(VelodyneModel model);
std::uint8_t velodyne_product_id(VelodyneModel model);

inline constexpr std::size_t kVelodyneDataPacketSize = 1206;
inline constexpr std::size_t kVelodynePositionPacketSize = 512;
inline constexpr std::uint16_t kVelodyneDataPort = 2368;
inline constexpr std::uint16_t kVelodynePositionPort = 8308;

// One laser of the Velodyne calibration YAML (angles in radians, lengths in metres).
struct VelodyneLaser {
  int laser_id = 0;
  double rot_correction = 0.0;
  double vert_correction = 0.0;
  double dist_correction = 0.0;
  double dist_correction_x = 0.0;
  double dist_correction_y = 0.0;
  double vert_offset_correction = 0.0;
  double horiz_offset_correction = 0.0;
  double focal_distance = 0.0;
  double focal_slope = 0.0;
};

struct VelodyneCalibration {
  std::vector<VelodyneLaser> lasers;   // indexed by laser_id
  double distance_resolution_m = 0.0;  // 0: the model's default
  std::string source;                  // the file it came from, for messages
};

// Parses the YAML text (`lasers:` list, optional `num_lasers`, `distance_resolution`).
// Throws adit::InputError naming `source`, the line and the key of the first problem.
VelodyneCalibration parse_velodyne_calibration(std::string_view yaml, const std::string& source);
VelodyneCalibration load_velodyne_calibration(const std::filesystem::path& file);

struct VelodynePosition {
  std::uint32_t us_past_hour = 0;
  std::uint8_t pps_status = 0;  // 0 absent, 1 synchronising, 2 locked, 3 error
  std::optional<NmeaRmc> rmc;   // nullopt when the sentence is missing or damaged
};

// How each firing gets its azimuth.
enum class VelodyneAzimuthModel : std::uint8_t {
  // As the manuals prescribe ("precision azimuth calculation"): the block
  // azimuth advanced by the share of the rotation to the next firing group
  // elapsed at the firing (its time from the firing-timing table); the last
  // group of a packet reuses the previous advance; both blocks of a dual pair
  // share their azimuth. A VLS-128 dual packet holds a single group: its
  // advance is measured from the previous packet. The rotational correction is
  // applied exactly.
  manual,
  // Reproduces the ROS velodyne_pointcloud / Autoware nebula decoders, to
  // compare against clouds they produced: the last block (dual: the last pair)
  // is not interpolated; in dual mode the second block of a pair takes the
  // next pair's azimuth, uninterpolated; the VLP-32C interpolates per channel
  // (not per firing pair) and quantises the rotational correction to 0.01°.
  // Only the VLP-16 and VLP-32C differ from `manual`.
  reference_decoders,
};

struct VelodyneDecoderConfig {
  float min_range_m = 0.0F;  // returns outside [min, max] are dropped
  float max_range_m = 1000.0F;
  VelodyneAzimuthModel azimuth_model = VelodyneAzimuthModel::manual;
};

class VelodyneDecoder final : public LidarDecoder {
 public:
  // Throws adit::InputError when the calibration does not fit the model.
  VelodyneDecoder(VelodyneModel model, VelodyneCalibration calibration, VelodyneDecoderConfig config = {});

  std::string_view model() const override { return to_string(model_); }
  std::uint16_t default_port() const override { return kVelodyneDataPort; }
  std::size_t max_points_per_packet() const override { return kMaxPoints; }
  std::int64_t min_packet_period_ns() const override;  // dual return: twice the packets
  std::size_t max_packet_bytes() const override;
  // Data packets come back `ok`; position packets `auxiliary` (see last_position()).
  DecodedPacket decode(std::span<const std::uint8_t> payload, std::int64_t host_time_ns) override;

  VelodyneModel velodyne_model() const { return model_; }
  std::optional<VelodyneReturnMode> last_return_mode() const { return return_mode_; }
  const std::optional<VelodynePosition>& last_position() const { return position_; }
  const TopOfHourClock& clock() const { return clock_; }
  // Packets whose product byte names another model (decoded with this model's table).
  std::uint64_t model_mismatches() const { return model_mismatches_; }
  // Field-of-view gaps met inside packets (sensors set to send only a sector).
  std::uint64_t fov_gaps() const { return fov_gaps_; }

  static constexpr std::size_t kBlocks = 12;
  static constexpr std::size_t kChannels = 32;
  static constexpr std::size_t kMaxPoints = kBlocks * kChannels;

 private:
  struct Slot {  // one channel slot of a block: which laser, and when it fires
    std::uint16_t laser = 0;
    std::uint32_t time_ns = 0;      // after the block's sequence start
    float azimuth_fraction = 0.0F;  // of the azimuth step to the next sequence
  };
  struct Laser {  // precomputed from the calibration
    float cos_vert, sin_vert, cos_rot, sin_rot;
    double rot_centideg;
    float dist_correction, vert_offset, horiz_offset;
    std::uint16_t ring;
  };

  DecodedPacket decode_data(std::span<const std::uint8_t> payload, std::int64_t host_time_ns);
  DecodedPacket decode_position(std::span<const std::uint8_t> payload);
  // The azimuth index (0.01°) of channel `c` of block `b` in reference_decoders mode,
  // with `rot_applied` set when the rotational correction is already in it.
  int reference_azimuth(const std::array<int, 12>& azimuth, std::size_t b, std::size_t c, bool dual, const Laser& laser,
                        bool& rot_applied) const;
  // For packets holding one firing group (VLS-128 dual): the azimuth advance per
  // group (0.01°) measured from the previous such packet; the last good one
  // when that packet is too old or the step is a gap; 0 before any.
  int advance_from_previous_packet(std::uint32_t us_past_hour, int azimuth);

  VelodyneModel model_;
  VelodyneCalibration calibration_;
  VelodyneDecoderConfig config_;
  float distance_resolution_m_ = 0.002F;
  std::vector<Laser> lasers_;
  std::vector<Slot> slots_;              // [block within its firing group][channel]
  std::size_t blocks_per_group_ = 1;     // blocks sharing one azimuth (VLS-128: its 4 banks)
  std::uint32_t group_ns_ = 0;           // time from one firing group to the next
  std::vector<float> cos_table_, sin_table_;  // per 0.01° of azimuth
  std::vector<DecodedPoint> points_;
  std::optional<VelodyneReturnMode> return_mode_;
  std::optional<VelodynePosition> position_;
  TopOfHourClock clock_;
  std::uint64_t model_mismatches_ = 0;
  std::uint64_t fov_gaps_ = 0;
  std::optional<std::pair<std::uint32_t, int>> previous_group_;  // µs past the hour, azimuth
  int carried_advance_ = 0;
};

}  // namespace adit::drivers
