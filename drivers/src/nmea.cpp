#include "adit/drivers/nmea.hpp"

#include <array>
#include <charconv>
#include <cmath>

namespace adit::drivers {
namespace {

constexpr std::int64_t kNsPerSecond = 1'000'000'000;

// Days since 1970-01-01 of a civil date (H. Hinnant, "chrono-Compatible
// Low-Level Date Algorithms", days_from_civil).
std::int64_t days_from_civil(std::int64_t y, unsigned m, unsigned d) {
  y -= m <= 2 ? 1 : 0;
  const std::int64_t era = (y >= 0 ? y : y - 399) / 400;
  const auto yoe = static_cast<unsigned>(y - era * 400);
  const unsigned doy = (153 * (m + (m > 2 ? -3 : 9)) + 2) / 5 + d - 1;
  const unsigned doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
  return era * 146097 + static_cast<std::int64_t>(doe) - 719468;
}

std::optional<int> digits(std::string_view s, std::size_t at, std::size_t n) {
  if (s.size() < at + n) return std::nullopt;
  int value = 0;
  for (std::size_t i = at; i < at + n; ++i) {
    if (s[i] < '0' || s[i] > '9') return std::nullopt;
    value = value * 10 + (s[i] - '0');
  }
  return value;
}

std::optional<double> number(std::string_view s) {
  if (s.empty()) return std::nullopt;
  double value = 0.0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
  if (ec != std::errc{} || end != s.data() + s.size() || !std::isfinite(value)) return std::nullopt;
  return value;
}

// ddmm.mmmm (latitude) or dddmm.mmmm (longitude) with its hemisphere letter.
std::optional<double> angle(std::string_view value, std::string_view hemisphere, char negative, char positive) {
  if (value.empty() && hemisphere.empty()) return 0.0;
  const auto raw = number(value);
  if (!raw || hemisphere.size() != 1 || (hemisphere[0] != negative && hemisphere[0] != positive)) return std::nullopt;
  const double degrees = std::floor(*raw / 100.0);
  const double result = degrees + (*raw - degrees * 100.0) / 60.0;
  return hemisphere[0] == negative ? -result : result;
}

int hex_digit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  return -1;
}

}  // namespace

std::optional<NmeaRmc> parse_nmea_rmc(std::string_view s) {
  while (!s.empty() && (s.back() == '\n' || s.back() == '\r' || s.back() == '\0')) s.remove_suffix(1);
  if (s.size() < 7 || s[0] != '$' || s.substr(3, 4) != "RMC,") return std::nullopt;
  std::string_view body = s.substr(1);
  if (const auto star = body.find('*'); star != std::string_view::npos) {
    if (body.size() != star + 3) return std::nullopt;
    const int hi = hex_digit(body[star + 1]);
    const int lo = hex_digit(body[star + 2]);
    if (hi < 0 || lo < 0) return std::nullopt;
    unsigned sum = 0;
    for (const char c : body.substr(0, star)) sum ^= static_cast<unsigned char>(c);
    if (sum != static_cast<unsigned>(hi * 16 + lo)) return std::nullopt;
    body = body.substr(0, star);
  }
  // Fields: talker+RMC, time, status, lat, N/S, lon, E/W, speed (knots), course, date, ...
  std::array<std::string_view, 10> field{};
  std::size_t count = 0;
  for (std::size_t start = 0; count < field.size();) {
    const auto comma = body.find(',', start);
    field[count++] = body.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start);
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  if (count < field.size()) return std::nullopt;
  const std::string_view time = field[1];
  const std::string_view date = field[9];
  const auto hh = digits(time, 0, 2), mm = digits(time, 2, 2), ss = digits(time, 4, 2);
  const auto day = digits(date, 0, 2), month = digits(date, 2, 2), yy = digits(date, 4, 2);
  if (!hh || !mm || !ss || !day || !month || !yy || date.size() != 6) return std::nullopt;
  if (*hh > 23 || *mm > 59 || *ss > 60 || *day < 1 || *day > 31 || *month < 1 || *month > 12) return std::nullopt;
  std::int64_t fraction_ns = 0;
  if (time.size() > 6) {
    const auto frac = number(time.substr(6));
    if (time[6] != '.' || !frac || *frac < 0.0 || *frac >= 1.0) return std::nullopt;
    fraction_ns = static_cast<std::int64_t>(std::llround(*frac * 1e9));
  }
  if (field[2] != "A" && field[2] != "V") return std::nullopt;
  const auto latitude = angle(field[3], field[4], 'S', 'N');
  const auto longitude = angle(field[5], field[6], 'W', 'E');
  if (!latitude || !longitude) return std::nullopt;

  NmeaRmc out;
  const int year = *yy < 80 ? 2000 + *yy : 1900 + *yy;
  const std::int64_t days = days_from_civil(year, static_cast<unsigned>(*month), static_cast<unsigned>(*day));
  out.utc_ns = ((days * 24 + *hh) * 3600 + std::int64_t{*mm} * 60 + *ss) * kNsPerSecond + fraction_ns;
  out.valid = field[2] == "A";
  out.latitude_deg = *latitude;
  out.longitude_deg = *longitude;
  constexpr double kKnot = 1852.0 / 3600.0;
  out.speed_mps = number(field[7]).value_or(0.0) * kKnot;
  out.course_deg = number(field[8]).value_or(0.0);
  return out;
}

}  // namespace adit::drivers
