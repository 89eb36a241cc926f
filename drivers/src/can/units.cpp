#include "adit/drivers/can/units.hpp"

#include <array>
#include <numbers>

namespace adit::drivers::can {
namespace {

struct UnitRow {
  std::string_view unit;
  double scale;
  std::string_view si;
};

constexpr double kPi = std::numbers::pi;
constexpr std::array kUnits{
    UnitRow{"m/s", 1.0, "m/s"},          UnitRow{"km/h", 1.0 / 3.6, "m/s"},
    UnitRow{"kph", 1.0 / 3.6, "m/s"},    UnitRow{"mph", 0.44704, "m/s"},  // 1 mile = 1609.344 m
    UnitRow{"mm/s", 1e-3, "m/s"},        UnitRow{"cm/s", 1e-2, "m/s"},
    UnitRow{"m", 1.0, "m"},              UnitRow{"mm", 1e-3, "m"},
    UnitRow{"cm", 1e-2, "m"},            UnitRow{"rad/s", 1.0, "rad/s"},
    UnitRow{"rpm", 2.0 * kPi / 60.0, "rad/s"}, UnitRow{"deg/s", kPi / 180.0, "rad/s"},
    UnitRow{"rad", 1.0, "rad"},          UnitRow{"deg", kPi / 180.0, "rad"},
    UnitRow{"turns", 2.0 * kPi, "rad"},  UnitRow{"turns/s", 2.0 * kPi, "rad/s"},
    UnitRow{"counts", 1.0, "counts"},    UnitRow{"counts/s", 1.0, "counts/s"},
};

}  // namespace

SiConversion si_conversion(std::string_view unit) {
  for (const UnitRow& row : kUnits) {
    if (row.unit == unit) return {row.scale, row.si, true};
  }
  return {1.0, unit, false};
}

}  // namespace adit::drivers::can
