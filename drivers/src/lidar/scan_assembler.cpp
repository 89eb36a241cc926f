#include "adit/drivers/lidar/scan_assembler.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace adit::drivers {
namespace {
// A scan is cut where the firing azimuth moves forward past the cut azimuth.
// Forward moves of up to kMaxForwardDeg count (a lost cut packet, or a sensor
// limited to a field of view that jumps over the cut inside a packet); larger
// ones are jitter backwards (rot corrections, dual returns). A scan is armed
// for its cut only once its firings reach the far half of the revolution (but
// not the last few degrees before the cut), so jitter across the cut cannot
// cut twice.
constexpr float kArmFromDeg = 180.0F;
constexpr float kArmToDeg = 350.0F;
constexpr float kMaxForwardDeg = 300.0F;

// std::fmod(x, 360) for x within (-360, 720), then one turn added to a
// negative result: [0, 360) as the callers had it, exactly (x - 360 is exact
// there, Sterbenz's lemma), without fmod's loop of FPREM on x86: two calls a
// return were 5 % of `adit products`' CPU on a 30-minute drive (perf; decision
// 063). Farther values take fmod.
float wrap_degrees(float x) {
  if (!(x > -360.0F && x < 720.0F)) x = std::fmod(x, 360.0F);  // NaN stays NaN
  if (x >= 360.0F) return x - 360.0F;
  return x < 0.0F ? x + 360.0F : x;
}
}  // namespace

ScanAssembler::ScanAssembler(const ScanAssemblerConfig& config) : config_(config) {
  if (config_.sequence_modulus < 2) config_.sequence_modulus = std::uint64_t{1} << 32;
  for (LidarScan& scan : scans_) scan.points.reserve(config_.max_points_per_scan);
}

float ScanAssembler::relative_azimuth(float azimuth_deg) const {
  return wrap_degrees(azimuth_deg - config_.cut_azimuth_deg);
}

ScanAssembler::Verdict ScanAssembler::classify(const DecodedPacket& packet) {
  LidarScan& scan = scans_[building_];
  const bool by_sequence = packet.sequence.has_value();
  const std::uint64_t sequence = by_sequence ? *packet.sequence % config_.sequence_modulus : 0;
  Verdict verdict = Verdict::in_order;
  if (have_last_) {
    std::uint64_t gap = 0;
    bool resync = false;
    if (by_sequence) {
      const std::uint64_t diff = (sequence + config_.sequence_modulus - last_sequence_) % config_.sequence_modulus;
      if (diff == 0) {
        verdict = Verdict::duplicate;
      } else if (diff > config_.sequence_modulus / 2) {
        verdict = Verdict::late;
      } else {
        gap = diff - 1;
      }
    } else {
      const std::int64_t dt = packet.sensor_time_ns - last_time_ns_;
      // The next packet is due one period after the last one, or right after its last firing
      // when that came later (a field-of-view gap inside the packet).
      const std::int64_t due = std::max(last_time_ns_ + config_.packet_period_ns, last_firing_ns_);
      if (dt == 0) {
        verdict = Verdict::duplicate;
      } else if (dt < 0) {
        verdict = Verdict::late;
        // Far in the past is a clock step, not a late packet.
        if (config_.packet_period_ns > 0 &&
            static_cast<std::uint64_t>(-dt / config_.packet_period_ns) > kMaxCountedGap) {
          verdict = Verdict::in_order;
          resync = true;
        }
      } else if (config_.packet_period_ns > 0) {
        // Half a period of tolerance, plus 2% of a field-of-view gap, whose length the decoder
        // could only estimate from the rotation rate.
        const std::int64_t period = config_.packet_period_ns;
        const std::int64_t span = last_firing_ns_ - last_time_ns_;
        const std::int64_t tolerance = period / 2 + (span > period ? span / 50 : 0);
        const std::int64_t late_by = packet.sensor_time_ns - due;
        gap = late_by > tolerance ? static_cast<std::uint64_t>(1 + (late_by - tolerance) / period) : 0;
      }
    }
    if (gap > kMaxCountedGap) {
      resync = true;
      gap = 0;
    }
    totals_.resyncs += resync ? 1 : 0;
    scan.stats.missing_packets += static_cast<std::uint32_t>(gap);
    totals_.missing_packets += gap;
  }
  if (verdict == Verdict::duplicate) {
    ++scan.stats.duplicate_packets;
    ++totals_.duplicate_packets;
    return verdict;
  }
  if (verdict == Verdict::late) {
    ++scan.stats.out_of_order_packets;
    ++totals_.out_of_order_packets;
    return verdict;
  }
  have_last_ = true;
  last_sequence_ = sequence;
  last_time_ns_ = packet.sensor_time_ns;
  last_firing_ns_ = packet.points.empty() ? packet.sensor_time_ns : packet.points.back().sensor_time_ns;
  return verdict;
}

LidarScan* ScanAssembler::add(const DecodedPacket& packet, std::int64_t sensor_to_host_ns) {
  if (packet.status != PacketStatus::ok) return nullptr;
  if (classify(packet) != Verdict::in_order) return nullptr;
  ++totals_.packets;
  sensor_to_host_ns_ = sensor_to_host_ns;
  LidarScan* finished = nullptr;
  bool counted_in_building = false;
  for (const DecodedPoint& point : packet.points) {
    const LidarScan& scan = scans_[building_];
    const float rel = relative_azimuth(point.azimuth_deg);
    const float forward = have_rel_ ? wrap_degrees(rel - last_rel_ + 360.0F) : 0.0F;
    const bool passed_cut = have_rel_ && forward < kMaxForwardDeg && last_rel_ + forward >= 360.0F;
    have_rel_ = true;
    last_rel_ = rel;
    if (!scan.points.empty() && finished == nullptr) {
      const bool crossed = armed_ && passed_cut;
      const bool overdue = config_.scan_period_ns > 0 &&
                           point.sensor_time_ns - scan.sensor_start_time_ns > config_.scan_period_ns * 3 / 2;
      if (crossed || overdue) {
        finished = finish(crossed);
        started_at_cut_ = crossed;
        counted_in_building = false;
      }
    }
    if (rel >= kArmFromDeg && rel < kArmToDeg) armed_ = true;
    if (!counted_in_building) {
      ++scans_[building_].stats.packets;
      counted_in_building = true;
    }
    append(point);
  }
  if (!counted_in_building) ++scans_[building_].stats.packets;
  return finished;
}

void ScanAssembler::append(const DecodedPoint& point) {
  LidarScan& scan = scans_[building_];
  if (scan.points.empty()) {
    scan.sensor_start_time_ns = point.sensor_time_ns;
    scan.start_time_ns = point.sensor_time_ns + sensor_to_host_ns_;
  }
  if (scan.points.size() >= config_.max_points_per_scan) {
    ++totals_.dropped_points;
    return;
  }
  LidarPoint out = point.point;
  const std::int64_t offset = point.sensor_time_ns - scan.sensor_start_time_ns;
  out.time_offset_ns = static_cast<std::uint32_t>(
      std::clamp<std::int64_t>(offset, 0, std::numeric_limits<std::uint32_t>::max()));
  scan.points.push_back(out);
}

LidarScan* ScanAssembler::finish(bool reached_cut) {
  LidarScan& done = scans_[building_];
  done.stats.complete = reached_cut && started_at_cut_ && done.stats.missing_packets == 0;
  ++totals_.scans;
  totals_.complete_scans += done.stats.complete ? 1 : 0;
  building_ ^= 1;
  LidarScan& next = scans_[building_];
  next.clear();
  next.points.reserve(config_.max_points_per_scan);  // no-op unless the caller swapped storage in
  armed_ = false;
  started_at_cut_ = false;
  return &done;
}

LidarScan* ScanAssembler::flush() {
  if (scans_[building_].points.empty()) return nullptr;
  LidarScan* done = finish(false);
  have_last_ = false;
  have_rel_ = false;
  return done;
}

}  // namespace adit::drivers
