#pragma once
// Converting a signal's unit to SI: value_si = value * scale. Units we do not
// know are passed through unchanged (scale 1) and keep their name.

#include <string_view>

namespace adit::drivers::can {

struct SiConversion {
  double scale = 1.0;
  std::string_view si_unit;  // e.g. "m/s"; the input unit when unknown
  bool known = false;
};

// km/h, mph, m/s, mm/s, cm/s, m, mm, rpm, rad/s, deg/s, rad, deg, turns, turns/s,
// counts, counts/s; case-sensitive as written in DBC files.
SiConversion si_conversion(std::string_view unit);

}  // namespace adit::drivers::can
