// Fuzzes the control-point reader (`adit georef --control FILE`: a
// total-station CSV the user gives) and, on what parses, the georeferencing
// fit against a fixed set of map targets (matching by id or by geometry, the
// unit, swap and fit checks). Bad input must end in adit::InputError, nothing else.

#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>

#include "adit/common/error.hpp"
#include "adit/eval/control_points.hpp"
#include "adit/eval/georeference.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size > 512) return 0;  // a dozen points: the geometric match grows as n^3 m^3
  std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
  try {
    const adit::eval::ControlFile file = adit::eval::read_control_points(in, "fuzz.csv", adit::eval::LengthUnit::metre);
    const std::vector<adit::eval::Target> targets{{"1", {3.0, 2.1, 1.2}},   {"2", {14.0, -2.0, 1.6}},
                                                  {"3", {27.0, 2.2, 0.9}},  {"4", {38.5, -1.9, 1.4}},
                                                  {"5", {44.0, 9.0, 1.1}},  {"6", {47.8, 22.0, 1.7}}};
    (void)adit::eval::georeference(file, targets, {});
  } catch (const adit::InputError&) {
  }
  return 0;
}
