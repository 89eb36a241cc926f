#include "adit/drivers/lidar/robosense_encoder.hpp"

#include <algorithm>

#include <fmt/format.h>

#include "adit/common/error.hpp"
#include "civil_time.hpp"

namespace adit::drivers {
namespace {

void put16(std::uint8_t* p, std::uint32_t v) {
  p[0] = static_cast<std::uint8_t>(v >> 8);
  p[1] = static_cast<std::uint8_t>(v);
}

}  // namespace

float robosense_distance_unit_m(RoboSenseModel model) { return model == RoboSenseModel::rs16 ? 0.005F : 0.0025F; }

void encode_robosense_msop(RoboSenseModel model, const RoboSenseMsop& packet,
                           std::span<std::uint8_t, kRoboSenseMsopSize> out) {
  std::fill(out.begin(), out.end(), std::uint8_t{0});
  const auto magic = robosense_magic(model);
  std::copy(magic.begin(), magic.end(), out.begin());
  const std::int64_t seconds = packet.time_ns / 1'000'000'000;
  const std::int64_t micros = packet.time_ns / 1000 % 1'000'000;
  if (model == RoboSenseModel::rs16) {
    const CivilTime t = civil_from_seconds(seconds);
    out[20] = static_cast<std::uint8_t>(t.year - 2000);
    out[21] = static_cast<std::uint8_t>(t.month);
    out[22] = static_cast<std::uint8_t>(t.day);
    out[23] = static_cast<std::uint8_t>(t.hour);
    out[24] = static_cast<std::uint8_t>(t.minute);
    out[25] = static_cast<std::uint8_t>(t.second);
    put16(out.data() + 26, static_cast<std::uint32_t>(micros / 1000));
    put16(out.data() + 28, static_cast<std::uint32_t>(micros % 1000));
  } else {
    out[17] = 0x01;  // 0.25 cm range resolution
    for (int i = 0; i < 6; ++i) out[20 + static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(seconds >> (8 * (5 - i)));
    for (int i = 0; i < 4; ++i) out[26 + static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(micros >> (8 * (3 - i)));
  }
  for (std::size_t b = 0; b < packet.blocks.size(); ++b) {
    std::uint8_t* block = out.data() + 42 + b * 100;
    block[0] = 0xFF;
    block[1] = 0xEE;
    const RoboSenseBlock& in = packet.blocks[b];
    put16(block + 2, in.azimuth);
    for (std::size_t c = 0; c < 32; ++c) {
      put16(block + 4 + 3 * c, in.distance[c]);
      block[4 + 3 * c + 2] = in.reflectivity[c];
    }
  }
  out[kRoboSenseMsopSize - 2] = 0x00;  // tail
  out[kRoboSenseMsopSize - 1] = 0xFF;
}

RoboSenseAngles robosense_nominal_angles(RoboSenseModel model) {
  if (model != RoboSenseModel::rs16) throw InputError("", "model", "no nominal angles tabulated for the Helios 16P");
  RoboSenseAngles a;
  for (int laser = 0; laser < 16; ++laser) {
    a.elevation_deg.push_back(laser < 8 ? -15.0F + 2.0F * static_cast<float>(laser)
                                        : 15.0F - 2.0F * static_cast<float>(laser - 8));
    a.azimuth_deg.push_back(0.0F);
  }
  return a;
}

std::string format_robosense_angle_csv(const RoboSenseAngles& angles) {
  std::string out;
  for (std::size_t i = 0; i < angles.elevation_deg.size(); ++i) {
    out += fmt::format("{:.2f},{:.2f}\n", angles.elevation_deg[i], angles.azimuth_deg[i]);
  }
  return out;
}

}  // namespace adit::drivers
