#include <gtest/gtest.h>

#include "adit/drivers/lidar/sensor_clock.hpp"
#include "adit/drivers/nmea.hpp"

namespace adit::drivers {
namespace {

TEST(Nmea, ParsesRmcAndChecksChecksums) {
  const auto rmc = parse_nmea_rmc("$GPRMC,220243,A,3708.5809,N,12139.7813,W,028.8,158.3,111212,013.8,E,D*03\r\n");
  ASSERT_TRUE(rmc.has_value());
  EXPECT_EQ(rmc->utc_ns, 1'355'263'363'000'000'000);  // 2012-12-11 22:02:43 UTC
  EXPECT_TRUE(rmc->valid);
  EXPECT_NEAR(rmc->latitude_deg, 37.14301500, 1e-8);
  EXPECT_NEAR(rmc->longitude_deg, -121.66302167, 1e-8);
  EXPECT_NEAR(rmc->course_deg, 158.3, 1e-9);
  EXPECT_FALSE(parse_nmea_rmc("$GPRMC,220243,A,3708.5809,N,12139.7813,W,028.8,158.3,111212,013.8,E,D*04"));
  const auto fraction = parse_nmea_rmc("$GNRMC,000001.25,V,,,,,,,010100,,,N");
  ASSERT_TRUE(fraction.has_value());
  EXPECT_FALSE(fraction->valid);
  EXPECT_EQ(fraction->utc_ns, 946'684'801'250'000'000);  // 2000-01-01 00:00:01.25
  EXPECT_FALSE(parse_nmea_rmc("$GPGGA,220243,3708.5809,N"));
  EXPECT_FALSE(parse_nmea_rmc("$GPRMC,256060,A,,,,,,,111212,,,"));
  EXPECT_FALSE(parse_nmea_rmc("$GPRMC,220243,A,37x8,N,12139.7813,W,0,0,111212,,,"));
  EXPECT_FALSE(parse_nmea_rmc(""));
}

TEST(TopOfHourClock, PinsTheHourNearestTheReferenceAndFollowsRollovers) {
  constexpr std::int64_t kHour = TopOfHourClock::kHourNs;
  TopOfHourClock clock;
  // Sensor 10 minutes behind the host, both just after the top of hour 7.
  EXPECT_EQ(clock.resolve(3'000'000'000u, 7 * kHour + 10 * 60'000'000'000LL), 6 * kHour + 3'000'000'000'000);
  EXPECT_EQ(clock.resolve(3'599'999'000u, 0), 6 * kHour + 3'599'999'000'000);  // the reference matters only once
  EXPECT_EQ(clock.resolve(5'000u, 0), 7 * kHour + 5'000'000);                   // rolled over
  EXPECT_EQ(clock.resolve(3'599'999'500u, 0), 6 * kHour + 3'599'999'500'000);   // a late packet from before
  EXPECT_EQ(clock.resolve(9'000u, 0), 7 * kHour + 9'000'000);
  EXPECT_EQ(clock.rollovers(), 1u);
  // GPS re-pins the hour: NMEA says 09:00:01 when the sensor says 1 s past the hour.
  clock.anchor(1'000'000u, 9 * kHour + 1'000'000'000);
  EXPECT_TRUE(clock.anchored_to_gps());
  EXPECT_EQ(clock.resolve(1'500'000u, 0), 9 * kHour + 1'500'000'000);
}

TEST(ClockOffsetEstimator, FindsOffsetAndDriftUnderJitteryDelays) {
  ClockOffsetEstimator estimator(1'000'000'000, 16);
  EXPECT_FALSE(estimator.estimate().has_value());
  // Host = sensor + 2 s + 50 ppm drift + a delay of 100 µs … 5 ms (deterministic pseudo-random).
  std::uint32_t state = 1;
  const std::int64_t start = 1'000'000'000'000;
  for (std::int64_t i = 0; i < 20'000; ++i) {
    const std::int64_t sensor = start + i * 1'000'000;  // 1 kHz for 20 s
    state = state * 1664525u + 1013904223u;
    const std::int64_t delay = 100'000 + static_cast<std::int64_t>(state % 4'900'000);
    const std::int64_t host = sensor + 2'000'000'000 + (sensor - start) / 20'000 + delay;
    estimator.add(sensor, host);
  }
  const auto e = estimator.estimate();
  ASSERT_TRUE(e.has_value());
  EXPECT_NEAR(e->drift_ppm, 50.0, 2.0);
  const std::int64_t true_offset = 2'000'000'000 + (e->at_sensor_ns - start) / 20'000;
  EXPECT_NEAR(static_cast<double>(e->offset_ns - true_offset), 100'000.0, 50'000.0);  // the minimum delay remains
  EXPECT_EQ(e->windows, 16u);
  // A clock step restarts the estimate.
  estimator.add(start + 30'000'000'000, start + 30'000'000'000 + 10'000'000'000);
  EXPECT_EQ(estimator.resets(), 1u);
  EXPECT_NEAR(static_cast<double>(estimator.estimate()->offset_ns), 10e9, 1.0);
}

}  // namespace
}  // namespace adit::drivers
