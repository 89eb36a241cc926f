#pragma once
// NMEA 0183 recommended-minimum sentences ($GPRMC / $GNRMC), as LiDARs and
// GNSS receivers send them: UTC time and date, fix status and position.
// Parsing never throws; a sentence with a bad checksum or field is rejected.

#include <cstdint>
#include <optional>
#include <string_view>

namespace adit::drivers {

struct NmeaRmc {
  std::int64_t utc_ns = 0;    // time of the fix, ns since the Unix epoch
  bool valid = false;         // status 'A' (active); 'V' means the receiver has no fix
  double latitude_deg = 0.0;  // north positive
  double longitude_deg = 0.0; // east positive
  double speed_mps = 0.0;
  double course_deg = 0.0;
};

// Parses one sentence (with or without the trailing "\r\n"). The checksum, when
// present ("*hh"), must match. Years are taken as 1980–2079 (NMEA has two digits).
std::optional<NmeaRmc> parse_nmea_rmc(std::string_view sentence);

}  // namespace adit::drivers
