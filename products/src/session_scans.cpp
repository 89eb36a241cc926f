#include "adit/products/session_scans.hpp"

#include <algorithm>
#include <optional>

#include "adit/common/error.hpp"
#include "adit/config/load.hpp"
#include "adit/drivers/lidar/decode_stream.hpp"
#include "adit/drivers/lidar/registry.hpp"
#include "adit/drivers/pcap_reader.hpp"
#include "adit/slam/trajectory_interpolate.hpp"

namespace adit::products {
namespace {

constexpr int kPosesPerScan = 16;  // the sensor's pose over a sweep: 6 ms apart at 10 Hz

// The calibration file as the session's config names it; a relative or moved
// one is looked for in the session folder (where aditd copies it).
std::filesystem::path calibration_of(const std::filesystem::path& session_dir, const std::string& name) {
  if (name.empty()) return {};
  const std::filesystem::path p(name);
  if (p.is_absolute() && std::filesystem::exists(p)) return p;
  if (std::filesystem::exists(session_dir / p)) return session_dir / p;
  if (std::filesystem::exists(session_dir / p.filename())) return session_dir / p.filename();
  return p;  // the decoder names it in its error
}

// Every step-th scan without decoding the others. Once the scan period P is
// known (the median gap between the capture times at which the first
// complete scans came out), decoding starts again 0.3 P before the next
// wanted scan's start: the partial scan before it is incomplete and skipped,
// the wanted one is whole, and when it comes out the datagrams are skipped
// again up to the next window. Each whole scan re-anchors the next window, so
// a motor's slow drift in speed does not carry the windows off the scans; a
// gap in the recording only means decoding on until a whole scan comes out.
// step 1: everything.
class ScanWindows {
 public:
  explicit ScanWindows(std::size_t step) : step_(static_cast<std::int64_t>(step)) {}

  // A complete scan came out at `capture_ns`: whether it is one of the
  // wanted (every step-th by count until the period is known, then the one
  // each window holds).
  bool take(std::int64_t capture_ns) {
    const bool wanted = period_ns_ > 0 || complete_ % step_ == 0;
    ++complete_;
    if (period_ns_ == 0 && step_ > 1) {
      if (last_ns_ > 0 && capture_ns > last_ns_) gaps_.push_back(capture_ns - last_ns_);
      if (gaps_.size() == kCalibrationScans) {
        std::nth_element(gaps_.begin(), gaps_.begin() + kCalibrationScans / 2, gaps_.end());
        period_ns_ = gaps_[kCalibrationScans / 2];
      }
    }
    last_ns_ = capture_ns;  // the first datagram after this scan's end: the next scan's start
    return wanted;
  }

  // Whether a datagram captured at `capture_ns` is decoded.
  bool decode(std::int64_t capture_ns) const {
    if (period_ns_ == 0) return true;
    const std::int64_t start = last_ns_ + (step_ - 1) * period_ns_;  // the wanted scan's start
    const std::int64_t margin = 3 * period_ns_ / 10;
    return capture_ns >= start - margin;
  }

 private:
  static constexpr std::size_t kCalibrationScans = 5;
  std::int64_t step_;
  std::int64_t complete_ = 0;
  std::int64_t period_ns_ = 0;
  std::int64_t last_ns_ = 0;
  std::vector<std::int64_t> gaps_;
};

}  // namespace

SessionScanStats for_each_session_scan(const std::filesystem::path& session_dir, const slam::Trajectory& body_poses,
                                       const Eigen::Isometry3d& body_to_sensor, int scan_step,
                                       const std::function<void(const RangeImage&, const ScanPoses&)>& on_scan) {
  SessionScanStats stats;
  const std::filesystem::path pcap = session_dir / "lidar.pcap";
  const std::filesystem::path config_file = session_dir / "config.yaml";
  if (!std::filesystem::exists(pcap)) {
    stats.skipped_because = "no raw recording (lidar.pcap)";
    return stats;
  }
  if (!std::filesystem::exists(config_file)) {
    stats.skipped_because = "no config.yaml to decode lidar.pcap with";
    return stats;
  }
  const config::Config config = config::load_config(config_file);
  const drivers::LidarFamily* family = drivers::lidar_family_of_model(config.lidar.model);
  if (family == nullptr) throw InputError(config_file.string(), "lidar.model", "unknown model '" + config.lidar.model + "'");
  if (family->name == "livox") {  // its lines wander over the field of view: no rows of a range image
    stats.skipped_because = "a Livox scans in a non-repetitive pattern, without rings for a range image";
    return stats;
  }
  const auto decoder = family->make_decoder(config.lidar.model, calibration_of(session_dir, config.lidar.calibration));
  drivers::ScanAssembler assembler(
      drivers::assembler_config_for(*decoder, 0, static_cast<float>(config.lidar.scan_cut_azimuth_deg)));
  const std::uint16_t port = config.lidar.port > 0 ? static_cast<std::uint16_t>(config.lidar.port) : decoder->default_port();
  const auto min_range = static_cast<float>(config.lidar.min_range_m);
  const auto max_range = static_cast<float>(config.lidar.max_range_m);

  std::optional<RangeImage> image;  // sized by the first complete scan
  ScanPoses poses;
  poses.map_to_sensor.resize(kPosesPerScan);
  ScanWindows windows(static_cast<std::size_t>(std::max(scan_step, 1)));
  std::int64_t now_ns = 0;  // the capture time of the datagram being decoded
  drivers::DecodeStream stream(*decoder, assembler, [&](drivers::LidarScan& scan) {
    if (!scan.stats.complete || scan.points.empty()) return;
    ++stats.scans;
    if (!windows.take(now_ns)) return;
    if (!image) {
      // Rings from the data; columns: a little coarser than the firings of a
      // ring, so that each bin holds a return (an empty bin blocks the test).
      int rings = 0;
      for (const drivers::LidarPoint& p : scan.points) rings = std::max(rings, p.ring + 1);
      if (rings < 2) {
        stats.skipped_because = "the LiDAR has no rings (a range image needs them)";
        return;
      }
      const auto per_ring = static_cast<int>(scan.points.size() / static_cast<std::size_t>(rings));
      image.emplace(rings, std::clamp(per_ring * 2 / 3, 64, 8192));
    }
    std::uint32_t span_ns = 0;
    for (const drivers::LidarPoint& p : scan.points) span_ns = std::max(span_ns, p.time_offset_ns);
    const double t0 = 1e-9 * static_cast<double>(scan.start_time_ns);
    poses.step_s = static_cast<float>(1e-9 * span_ns / (kPosesPerScan - 1));
    for (int k = 0; k < kPosesPerScan; ++k) {
      const std::optional<slam::Pose> body = slam::interpolate_pose(body_poses, t0 + k * static_cast<double>(poses.step_s));
      if (!body) return;  // not mapped (before the first pose, after the last)
      poses.map_to_sensor[static_cast<std::size_t>(k)] = ((*body) * body_to_sensor).inverse().cast<float>();
    }
    image->clear();
    for (const drivers::LidarPoint& p : scan.points)
      if (p.return_index == 0 && p.range_m >= min_range && p.range_m <= max_range)
        image->add(p.ring, Eigen::Vector3f(p.x, p.y, p.z), 1e-9F * static_cast<float>(p.time_offset_ns));
    image->finish();
    ++stats.used;
    on_scan(*image, poses);
  });
  drivers::PcapReader reader(pcap);
  drivers::UdpDatagram d;
  bool decoding = true;
  while (reader.next(d) && stats.skipped_because.empty()) {
    if (d.dst_port != port) continue;
    if (!windows.decode(d.capture_time_ns)) {
      // The scan begun after the wanted one is cut off: emitted now as
      // incomplete, so that it does not join the next window's datagrams.
      if (decoding) stream.finish();
      decoding = false;
      continue;
    }
    decoding = true;
    now_ns = d.capture_time_ns;
    stream.push(d.payload, d.capture_time_ns);
  }
  stream.finish();
  return stats;
}

}  // namespace adit::products
