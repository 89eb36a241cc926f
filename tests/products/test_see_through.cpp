// Moving objects out of the map (see_through.hpp) on small synthetic scenes:
// a 16-ring scanner drives down a corridor; the map is every scan's returns
// kept one per 5 cm voxel, as aditd's map does. Static floors and walls,
// seen at grazing angles far ahead, must stay; a person who stood in the
// corridor and left must go.

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <unordered_set>

#include <gtest/gtest.h>

#include "adit/products/see_through.hpp"

namespace adit::products {
namespace {

constexpr int kRings = 16;
constexpr int kColumns = 900;         // 0.4° azimuth steps
constexpr double kScanS = 0.1;        // one revolution
constexpr double kSpeed = 1.5;        // m/s along x
constexpr double kFloorZ = -0.5;      // the sensor 0.5 m over the floor
constexpr double kHalfWidth = 2.0;    // walls at y = ±2
constexpr double kEndX = 40.0;

struct Person {
  Eigen::Vector2d at;
  double until_s;  // there from t = 0 to this time, gone after
};

// Ring elevations in firing order, interleaved as a VLP-16's (ring index 0 = lowest).
double elevation_deg(int ring) { return -15.0 + 2.0 * ring; }

// The range along `d` from `o` to the corridor (floor, walls, end wall) or the person at time t.
std::optional<double> cast(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double t, const std::optional<Person>& person) {
  double best = 1e9;
  const auto consider = [&](double s) {
    if (s > 0.05 && s < best) best = s;
  };
  if (d.z() < 0) consider((kFloorZ - o.z()) / d.z());
  if (d.y() > 0) consider((kHalfWidth - o.y()) / d.y());
  if (d.y() < 0) consider((-kHalfWidth - o.y()) / d.y());
  if (d.x() > 0) consider((kEndX - o.x()) / d.x());
  if (person && t < person->until_s) {  // a vertical cylinder 0.25 m × 1.75 m standing on the floor
    const Eigen::Vector2d m = o.head<2>() - person->at;
    const Eigen::Vector2d dd = d.head<2>();
    const double a = dd.squaredNorm(), b = m.dot(dd), c = m.squaredNorm() - 0.25 * 0.25;
    const double disc = b * b - a * c;
    if (a > 1e-12 && disc >= 0) {
      const double s = (-b - std::sqrt(disc)) / a;
      const double z = o.z() + s * d.z();
      if (z >= kFloorZ && z <= kFloorZ + 1.75) consider(s);
    }
  }
  if (best > 100.0) return std::nullopt;
  return best;
}

Eigen::Vector3d sensor_at(double t) { return {kSpeed * t, 0.0, 0.0}; }

struct Drive {
  std::vector<Eigen::Vector3f> map;       // one point per 5 cm voxel
  std::vector<std::uint8_t> on_person;    // per map point
  std::vector<std::pair<RangeImage, ScanPoses>> scans;
};

// `scans` revolutions from x = 0; ranges get ±`noise` m of deterministic noise.
Drive drive(int scans, const std::optional<Person>& person, double noise) {
  Drive out;
  std::unordered_set<std::int64_t> voxels;
  for (int s = 0; s < scans; ++s) {
    const double t0 = s * kScanS;
    RangeImage image(kRings, kColumns);
    for (int c = 0; c < kColumns; ++c) {
      const double tc = kScanS * c / kColumns;
      const double az = 2 * M_PI * c / kColumns + 0.001;
      for (int ring = 0; ring < kRings; ++ring) {
        const double el = elevation_deg(ring) * M_PI / 180;
        const Eigen::Vector3d d(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
        const Eigen::Vector3d o = sensor_at(t0 + tc);
        const std::optional<double> r = cast(o, d, t0 + tc, person);
        if (!r || *r > 40.0) continue;
        const double range = *r + noise * std::sin(1.7 * s + 3.1 * c + 5.3 * ring);
        image.add(ring, (range * d).cast<float>(), static_cast<float>(tc));
        const Eigen::Vector3d w = o + range * d;
        const auto k = [](double v) { return static_cast<std::int64_t>(std::floor(v / 0.05)); };
        if (voxels.insert((k(w.x()) * 100003 + k(w.y())) * 100003 + k(w.z())).second) {
          out.map.push_back(w.cast<float>());
          const bool person_hit = person && (w.head<2>() - person->at).norm() < 0.3 && w.z() > kFloorZ + 0.02;
          out.on_person.push_back(person_hit ? 1 : 0);
        }
      }
    }
    image.finish();
    ScanPoses poses;
    poses.step_s = static_cast<float>(kScanS / 15);
    for (int k = 0; k < 16; ++k) {
      Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
      pose.translation() = sensor_at(t0 + k * poses.step_s);
      poses.map_to_sensor.push_back(pose.inverse().cast<float>());
    }
    out.scans.emplace_back(std::move(image), std::move(poses));
  }
  return out;
}

struct Outcome {
  std::size_t person = 0, person_removed = 0, static_points = 0, static_removed = 0;
};

Outcome judge(const Drive& d, const SeeThroughOptions& options) {
  SeeThroughCounter counter(d.map, {}, options);
  for (std::size_t s = 0; s < d.scans.size(); s += static_cast<std::size_t>(options.scan_step))
    counter.add_scan(d.scans[s].first, d.scans[s].second);
  const std::vector<std::uint8_t> dynamic = counter.dynamic();
  Outcome o;
  for (std::size_t i = 0; i < d.map.size(); ++i) {
    (d.on_person[i] ? o.person : o.static_points)++;
    if (dynamic[i]) (d.on_person[i] ? o.person_removed : o.static_removed)++;
  }
  return o;
}

TEST(RangeImage, RowsByElevationAndColumnsByAzimuth) {
  RangeImage image(3, 8);
  // Rings given out of elevation order: ring 0 at +10°, ring 1 at -10°, ring 2 at 0°.
  const auto at = [](double el_deg, double az_deg, double r) {
    const double el = el_deg * M_PI / 180, az = az_deg * M_PI / 180;
    return Eigen::Vector3f(static_cast<float>(r * std::cos(el) * std::cos(az)),
                           static_cast<float>(r * std::cos(el) * std::sin(az)), static_cast<float>(r * std::sin(el)));
  };
  image.add(0, at(10, 10, 5), 0.01F);
  image.add(1, at(-10, 10, 6), 0.01F);
  image.add(2, at(0, 10, 7), 0.01F);
  image.add(2, at(0, 12, 3), 0.03F);  // the same bin, nearer: kept
  image.finish();
  EXPECT_NEAR(image.row_elevation(0), -10 * M_PI / 180, 1e-5);
  EXPECT_NEAR(image.row_elevation(2), 10 * M_PI / 180, 1e-5);
  EXPECT_FLOAT_EQ(image.range(0, 0), 6.0F);
  EXPECT_FLOAT_EQ(image.range(1, 0), 3.0F);
  EXPECT_FLOAT_EQ(image.range(2, 0), 5.0F);
  EXPECT_EQ(image.range(1, 1), 0.0F);  // no return there
  EXPECT_NEAR(image.column_time(0), 0.015F, 1e-6);  // the mean of its four returns'
  EXPECT_TRUE(std::isnan(image.column_time(3)));
  EXPECT_EQ(image.column_of(static_cast<float>(-M_PI / 8)), 7);
  EXPECT_EQ(image.row_below(static_cast<float>(-5 * M_PI / 180)), 0);
  EXPECT_EQ(image.row_below(static_cast<float>(5 * M_PI / 180)), 1);
  EXPECT_EQ(image.row_below(static_cast<float>(20 * M_PI / 180)), -1);
  EXPECT_EQ(image.row_below(static_cast<float>(-20 * M_PI / 180)), -1);
}

TEST(RangeImage, RowByTangentIsTheBinarySearchsAnswer) {
  // 16 rings 2° apart from -15° (a VLP-16), ring 5 without returns (a dead
  // beam: its row sorts last, at +inf), and 3 rings: the looked-up row below
  // each tangent, for tangents over and past the rings and on their own
  // values, is std::upper_bound's over the rows' tangents.
  for (const int rings : {16, 3}) {
    RangeImage image(rings, 64);
    for (int ring = 0; ring < rings; ++ring) {
      if (rings == 16 && ring == 5) continue;
      const double el = (-15.0 + 2.0 * ring) * M_PI / 180;
      for (int k = 0; k < 64; ++k) {
        const double az = 2 * M_PI * (k + 0.5) / 64;
        image.add(ring, Eigen::Vector3f(static_cast<float>(10 * std::cos(el) * std::cos(az)),
                                        static_cast<float>(10 * std::cos(el) * std::sin(az)),
                                        static_cast<float>(10 * std::sin(el))),
                  0.0F);
      }
    }
    image.finish();
    std::vector<float> tangents;
    for (int row = 0; row < rings; ++row) tangents.push_back(image.row_tangent(row));
    const auto expected = [&](float t) {
      const auto above = std::upper_bound(tangents.begin(), tangents.end(), t);
      if (above == tangents.begin() || above == tangents.end() || !std::isfinite(*above)) return -1;
      return static_cast<int>(above - tangents.begin()) - 1;
    };
    std::vector<float> probes = {-1e9F, 1e9F, std::numeric_limits<float>::infinity(),
                                 -std::numeric_limits<float>::infinity(), std::numeric_limits<float>::quiet_NaN()};
    for (const float t : tangents)
      if (std::isfinite(t)) probes.insert(probes.end(), {t, std::nextafter(t, -1.0F), std::nextafter(t, 1.0F)});
    for (int k = 0; k <= 4000; ++k) probes.push_back(-0.4F + 0.8F * static_cast<float>(k) / 4000.0F);
    int inside = 0;
    for (const float t : probes) {
      const int want = std::isnan(t) ? -1 : expected(t);
      EXPECT_EQ(image.row_below_tangent(t), want) << rings << " rings, tangent " << t;
      inside += want >= 0;
    }
    EXPECT_GT(inside, 300);  // the 3 rings span 4° of the probes' 46°
  }
}

TEST(SeeThrough, StaticCorridorStaysAtGrazingAngles) {
  // 60 scans (9 m of driving): floors and walls ahead are seen down to a few
  // degrees of incidence; 2 cm of range noise.
  const Drive d = drive(60, std::nullopt, 0.02);
  const Outcome o = judge(d, SeeThroughOptions{});
  ASSERT_GT(o.static_points, 20000u);
  EXPECT_LT(static_cast<double>(o.static_removed), 0.005 * static_cast<double>(o.static_points))
      << o.static_removed << " of " << o.static_points;
}

TEST(SeeThrough, PersonWhoLeftIsRemoved) {
  // Someone stands 12 m ahead, 0.5 m off the middle, for the first second (seen
  // in 10 scans), then is gone; the sensor drives on to 3 m short of the place.
  const Drive d = drive(60, Person{{12.0, 0.5}, 1.0}, 0.02);
  const Outcome o = judge(d, SeeThroughOptions{});
  ASSERT_GT(o.person, 100u);
  EXPECT_GE(static_cast<double>(o.person_removed), 0.95 * static_cast<double>(o.person))
      << o.person_removed << " of " << o.person;
  EXPECT_LT(static_cast<double>(o.static_removed), 0.005 * static_cast<double>(o.static_points))
      << o.static_removed << " of " << o.static_points;
}

TEST(SeeThrough, PersonWhoStaysIsKept) {
  // Standing there the whole drive: seen every scan, never seen through.
  const Drive d = drive(60, Person{{8.0, 0.5}, 1e9}, 0.02);
  const Outcome o = judge(d, SeeThroughOptions{});
  ASSERT_GT(o.person, 100u);
  EXPECT_LT(static_cast<double>(o.person_removed), 0.02 * static_cast<double>(o.person))
      << o.person_removed << " of " << o.person;
}

TEST(SeeThrough, ARetiringCounterStopsTestingWhatItSawStillFindsWhoLeft) {
  // The coarse pass's counter: a point looked at 8 times, first 40 scans ago
  // or more, and never seen through is tested no more. The person of
  // PersonWhoLeftIsRemoved stood for 10 scans: looked at more than 8 times,
  // but over too short a span to retire before leaving and being seen through.
  const Drive d = drive(60, Person{{12.0, 0.5}, 1.0}, 0.02);
  SeeThroughOptions options;
  options.coarse_retire_after_looks = 8;
  options.coarse_retire_after_scans = 40;
  SeeThroughCounter all(d.map, {}, options);
  SeeThroughCounter retiring(d.map, {}, options, true);
  for (const auto& [image, poses] : d.scans) {
    all.add_scan(image, poses);
    retiring.add_scan(image, poses);
  }
  std::size_t person = 0, person_through = 0, retired = 0, through_differs = 0;
  for (std::size_t i = 0; i < d.map.size(); ++i) {
    EXPECT_LE(retiring.seen(i), all.seen(i)) << i;
    if (retiring.seen(i) < all.seen(i)) ++retired;
    if (d.on_person[i]) {
      ++person;
      person_through += retiring.through(i) > 0;
    }
    through_differs += (all.through(i) > 0) != (retiring.through(i) > 0);
  }
  ASSERT_GT(person, 100u);
  EXPECT_GE(static_cast<double>(person_through), 0.95 * static_cast<double>(person)) << person_through << " of " << person;
  EXPECT_GT(retired, d.map.size() / 4);  // most of the corridor is seen often: retired
  // Whether a point was seen through at all (what makes a suspect) hardly changes.
  EXPECT_LT(static_cast<double>(through_differs), 0.01 * static_cast<double>(d.map.size())) << through_differs;
}

TEST(SeeThrough, APointOnlyEverHiddenRetiresOnItsLooks) {
  // A map point 10 m ahead that the first 48 scans look at but never see
  // (something 5 m ahead hides it: all four returns there, nearer), then 4
  // scans see through it. Its looks retire it in the coarse pass's counter
  // before the four; a sighting it never had could not have.
  const Eigen::Vector3f point(10.0F, 0.0F, 0.0F);
  const auto scan_at = [](float range) {
    RangeImage image(2, 64);
    for (int ring = 0; ring < 2; ++ring)
      for (int c = 0; c < 64; ++c) {
        const float az = 6.2831853F * (static_cast<float>(c) + 0.5F) / 64.0F;
        const float el = (ring == 0 ? -1.0F : 1.0F) * 0.01745F;
        image.add(ring, range * Eigen::Vector3f(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el)),
                  0.0F);
      }
    image.finish();
    return image;
  };
  const RangeImage hidden = scan_at(5.0F), past = scan_at(20.0F);
  ScanPoses poses;
  poses.map_to_sensor.assign(16, Eigen::Isometry3f::Identity());
  SeeThroughOptions options;
  options.coarse_retire_after_looks = 8;
  options.coarse_retire_after_scans = 40;
  const std::vector<Eigen::Vector3f> map = {point};
  SeeThroughCounter all(map, {}, options);
  SeeThroughCounter retiring(map, {}, options, true);
  for (int k = 0; k < 52; ++k) {
    all.add_scan(k < 48 ? hidden : past, poses);
    retiring.add_scan(k < 48 ? hidden : past, poses);
  }
  EXPECT_EQ(all.seen(0), 0U);
  EXPECT_EQ(all.through(0), 4U);
  EXPECT_EQ(retiring.through(0), 0U);
  // Looked at fewer times than asked, it is not retired.
  options.coarse_retire_after_looks = 49;
  SeeThroughCounter patient(map, {}, options, true);
  for (int k = 0; k < 52; ++k) patient.add_scan(k < 48 ? hidden : past, poses);
  EXPECT_EQ(patient.through(0), 4U);
}

TEST(SeeThrough, ExcludedPointsAreNeverRemoved) {
  const Drive d = drive(40, Person{{6.0, 0.0}, 1.0}, 0.0);
  std::vector<std::uint8_t> candidate(d.map.size(), 0);  // none may go
  SeeThroughCounter counter(d.map, candidate, SeeThroughOptions{});
  for (const auto& [image, poses] : d.scans) counter.add_scan(image, poses);
  const std::vector<std::uint8_t> dynamic = counter.dynamic();
  EXPECT_EQ(std::count(dynamic.begin(), dynamic.end(), 1), 0);
  EXPECT_EQ(counter.scans(), d.scans.size());
  EXPECT_THROW(SeeThroughCounter(d.map, std::vector<std::uint8_t>(3, 1), SeeThroughOptions{}), std::exception);
}

}  // namespace
}  // namespace adit::products
