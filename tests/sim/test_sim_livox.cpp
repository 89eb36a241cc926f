// The simulated Mid-360 read back by the project's own Livox decoder: SDK2
// point packets at 2083.3/s (96 points, 5 µs apart) to port 56301, IMU packets
// at 200 Hz to 56401, detected by the registry; each decoded point lies on the
// scene where the true sensor pose at its own time says (noise off), so a
// wrong time, pose or axis shows up as a residual; the IMU packets carry the
// simulated readings (truth_livox_imu.csv) converted to g and back.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <vector>

#include "adit/drivers/lidar/livox.hpp"
#include "adit/drivers/lidar/registry.hpp"
#include "adit/drivers/pcap_reader.hpp"
#include "adit/sim/livox_lidar.hpp"
#include "adit/sim/ray_caster.hpp"
#include "adit/sim/scene.hpp"
#include "sim_session.hpp"

namespace adit::sim {
namespace {

TEST(SimLivox, Mid360PacketsDecodeOntoTheSceneAtEachPointsTime) {
  SimOptions o = test::short_session("livox-mid360");
  o.sensor = "Mid-360";
  o.wheels = false;
  o.noise_m = 0.0;
  o.dropout = 0.0;
  run_simulation(o);
  ASSERT_FALSE(std::filesystem::exists(o.out / "VLP16.yaml"));
  const Scene scene = simulated_scene(o);
  const BodyTrack body = simulated_path(scene, o);
  const RayCaster caster(scene.mesh);
  const Eigen::Isometry3d extrinsics = simulated_extrinsics(o);

  drivers::LivoxDecoder decoder(drivers::LivoxModel::mid360);
  drivers::PcapReader reader(o.out / "lidar.pcap");
  drivers::UdpDatagram d;
  std::size_t packets = 0, imu_packets = 0, points = 0, off_surface = 0;
  std::int64_t previous_imu_ns = 0;
  while (reader.next(d)) {
    const auto packet = decoder.decode(d.payload, d.capture_time_ns);
    if (d.dst_port == drivers::kLivoxMid360ImuPort) {
      ASSERT_EQ(packet.status, drivers::PacketStatus::auxiliary);
      ASSERT_TRUE(decoder.last_imu());
      if (imu_packets > 0) {
        EXPECT_NEAR(decoder.last_imu()->sensor_time_ns - previous_imu_ns, 5'000'000, 1);
      }
      previous_imu_ns = decoder.last_imu()->sensor_time_ns;
      // Hovering or cruising, the accelerometer reads about 1 g.
      const auto& a = decoder.last_imu()->accel_m_s2;
      EXPECT_NEAR(std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]), 9.81, 3.0);
      ++imu_packets;
      continue;
    }
    ASSERT_EQ(d.dst_port, drivers::kLivoxMid360PointPort);
    ASSERT_EQ(d.payload.size(), 1380u);
    if (packets == 0) {
      const auto detected = drivers::detect_lidar(d.payload, d.dst_port);
      ASSERT_NE(detected.family, nullptr);
      EXPECT_EQ(detected.model, "Mid-360");
    }
    ASSERT_EQ(packet.status, drivers::PacketStatus::ok);
    ASSERT_EQ(*packet.sequence, packets % 65536);
    EXPECT_EQ(packet.sensor_time_ns, o.start_time_ns + static_cast<std::int64_t>(packets) * 480'000);
    for (const auto& p : packet.points) {
      ++points;
      if (points % 7 != 0) continue;  // a sample is enough
      const double t = static_cast<double>(p.sensor_time_ns - o.start_time_ns) * 1e-9;
      const Eigen::Isometry3d sensor = body.pose(t) * extrinsics;
      const Eigen::Vector3d world = sensor * Eigen::Vector3d(p.point.x, p.point.y, p.point.z);
      const Eigen::Vector3d ray = world - sensor.translation();
      const Hit hit = caster.intersect(sensor.translation().cast<float>(), ray.normalized().cast<float>(), 0.0F, 200.0F);
      const double cos_incidence =
          hit.valid() ? std::abs(static_cast<double>(hit.normal.dot(ray.normalized().cast<float>()))) : 0.0;
      // Off the surface along its normal: the mm rounding of the packets, 2 mm allowed.
      if (!hit.valid() || std::abs(ray.norm() - hit.distance) * cos_incidence > 0.002) ++off_surface;
    }
    ++packets;
  }
  EXPECT_EQ(packets, static_cast<std::size_t>(o.duration_s * 1e9 / 480'000));
  EXPECT_NEAR(static_cast<double>(imu_packets), o.duration_s * 200, 2);
  EXPECT_GT(points, packets * 60);  // most rays return in a mine
  EXPECT_LT(off_surface, points / 7 / 200) << off_surface << " of " << points / 7;
}

// Without wheels the Mid-360's own IMU is the one session.yaml reads, inside
// the sensor where drivers::livox_imu_position_m (aditd's mounting) puts it;
// a robot's IMU is on CAN beside its wheels; --imu-on-can asks for the CAN one.
TEST(SimLivox, DronesAndHandheldsReadTheMid360sOwnImu) {
  SimOptions o = test::short_session("livox-imu-source");
  o.sensor = "Mid-360";
  EXPECT_EQ(simulated_imu_source(o), SimImuSource::can);  // the robot
  for (const char* platform : {"drone", "handheld"}) {
    o.platform = platform;
    EXPECT_EQ(simulated_imu_source(o), SimImuSource::livox) << platform;
    const ImuOptions imu = simulated_imu(o, SimImuSource::livox);
    const std::array<double, 3> in_sensor = drivers::livox_imu_position_m(drivers::LivoxModel::mid360);
    const Eigen::Vector3d expected = simulated_extrinsics(o) * Eigen::Vector3d(in_sensor[0], in_sensor[1], in_sensor[2]);
    EXPECT_TRUE((imu.mount.translation() - expected).isZero(1e-12)) << platform;
    EXPECT_EQ(imu.rate_hz, 200.0);
  }
  o.imu_on_can = true;
  EXPECT_EQ(simulated_imu_source(o), SimImuSource::can);
  o.imu = false;
  EXPECT_EQ(simulated_imu_source(o), SimImuSource::none);
}

TEST(SimLivox, PatternCoversTheFieldOfViewWithoutRepeating) {
  const LivoxPattern p;
  double min_el = 90, max_el = -90;
  for (std::uint64_t i = 0; i < 200'000; ++i) {
    const Eigen::Vector3d d = livox_direction(p, i);
    ASSERT_NEAR(d.norm(), 1.0, 1e-12);
    const double el = std::asin(d.z()) * 180.0 / M_PI;
    min_el = std::min(min_el, el);
    max_el = std::max(max_el, el);
  }
  EXPECT_NEAR(min_el, -7.0, 0.05);
  EXPECT_NEAR(max_el, 52.0, 0.05);
  // Not the same direction one turn (or one sweep) later.
  const auto per_turn = static_cast<std::uint64_t>(p.points_per_s / p.turn_hz);
  EXPECT_GT((livox_direction(p, 1000) - livox_direction(p, 1000 + per_turn)).norm(), 1e-3);
}

}  // namespace
}  // namespace adit::sim
