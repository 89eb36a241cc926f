#pragma once
// Hesai Pandar decoding: one decoder class for every supported model, driven
// by a per-model table of packet layout and firing timing (hesai_models.cpp).
//
// Models and UDP protocols (Hesai user manuals):
//   PandarXT16, PandarXT32, PandarXT32M   protocol 6.1  (pre-header 0xEE 0xFF 6 1)
//   PandarQT64                            protocol 3.x  (pre-header 0xEE 0xFF 3 x)
//   PandarQT128 (QT128C2X)                protocol 3.2  (pre-header 0xEE 0xFF 3 2; optional parts by header flags)
//   Pandar64                              legacy: 8-byte header 0xEE 0xFF, no version
//   Pandar40P                             legacy: no header, blocks start with 0xFF 0xEE
// Points come out in our frame (x forward, y left, z up). Hesai's own frame is
// y forward, x right, azimuth clockwise seen from above.

#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "adit/drivers/lidar/decoder.hpp"

namespace adit::drivers {

enum class HesaiModel : std::uint8_t {
  pandar_xt16,
  pandar_xt32,
  pandar_xt32m,
  pandar_qt64,
  pandar_qt128,
  pandar_40p,
  pandar_64,
};

// "PandarXT32", "PandarQT128", "Pandar40P", ... (case-insensitive); nullopt otherwise.
std::optional<HesaiModel> hesai_model_from_name(std::string_view name);
std::string_view hesai_model_name(HesaiModel model);
// The model whose data packet this is (magic, header identity and size), nullopt otherwise.
std::optional<HesaiModel> hesai_model_from_packet(std::span<const std::uint8_t> payload);
// Time between data packets of `model` in the return mode the packet's tail states; 0 if unreadable.
std::int64_t hesai_packet_period_ns(HesaiModel model, std::span<const std::uint8_t> payload);
std::uint16_t hesai_laser_count(HesaiModel model);
std::uint16_t hesai_block_count(HesaiModel model);
// The firing time of (block, channel) relative to the packet's timestamp, ns, for
// packets with `returns` returns per firing, in firing loop `loop` (QT128: 0 or 1).
// From the manuals' "Laser Firing Time"; the decoder and the simulator share it.
std::int32_t hesai_firing_ns(HesaiModel model, std::size_t returns, std::size_t loop, std::size_t block,
                             std::size_t channel);

// Per-channel angle corrections from the unit's angle-correction CSV, in
// packet channel order (row i is channel i of every block).
struct HesaiAngleCorrection {
  std::vector<float> elevation_deg;
  std::vector<float> azimuth_deg;  // added to the block azimuth
};

// Parses "Channel,Elevation,Azimuth" / "Laser id,Elevation,Azimuth" files
// (header optional; CRLF, BOM, blank lines and trailing blanks accepted; ids
// consecutive). Throws adit::InputError naming `source`:line and the column.
HesaiAngleCorrection parse_hesai_angle_csv(std::string_view text, const std::string& source);
HesaiAngleCorrection load_hesai_angle_csv(const std::filesystem::path& file);

// What the last data packet's tail said (exposed for tools and health checks).
struct HesaiPacketInfo {
  std::uint8_t return_mode = 0;  // Hesai code, e.g. 0x37 strongest, 0x39 last+strongest
  std::uint8_t returns = 0;      // returns per firing
  std::uint16_t motor_rpm = 0;
  float distance_unit_m = 0.0F;
};

class HesaiDecoder final : public LidarDecoder {
 public:
  // Throws adit::InputError when the correction has the wrong channel count.
  HesaiDecoder(HesaiModel model, const HesaiAngleCorrection& angles);
  ~HesaiDecoder() override;

  std::string_view model() const override;
  std::uint16_t default_port() const override { return 2368; }
  std::size_t max_points_per_packet() const override { return points_.size(); }
  DecodedPacket decode(std::span<const std::uint8_t> payload, std::int64_t host_time_ns) override;

  const HesaiPacketInfo& last_packet_info() const { return info_; }

  struct Spec;  // the model's layout and timing table (hesai_models.cpp)

 private:
  const Spec& spec_;
  // Per channel: ring (rank by elevation), sin/cos of elevation and of the azimuth offset.
  std::vector<std::uint16_t> ring_;
  std::vector<float> cos_el_, sin_el_, cos_az_off_, sin_az_off_;
  // Per raw azimuth step (0.01 deg): sin/cos, so the hot loop has no trigonometry.
  std::vector<float> cos_az_, sin_az_;
  // Firing offset from the packet time, per [returns-1][loop][block * lasers + channel], ns.
  std::array<std::array<std::vector<std::int32_t>, 2>, 3> firing_ns_;
  std::array<std::array<std::int32_t, 2>, 3> earliest_ns_{};
  std::vector<DecodedPoint> points_;
  HesaiPacketInfo info_;
};

// Factory for the model registry: model name as in configs, angle-correction CSV.
std::unique_ptr<LidarDecoder> make_hesai_decoder(std::string_view model,
                                                 const std::filesystem::path& calibration_csv);

}  // namespace adit::drivers
