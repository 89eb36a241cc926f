#pragma once
// HINT's arguments (docs/PROTOCOL.md, "Commands"): where the crew says the
// payload is in the prior map's frame, to narrow the live search against the
// prior (docs/PRIOR-MAP.md). Text key=value arguments, as every command's:
//   x=M y=M [radius=M] [heading=DEG] [heading_tolerance=DEG]
// x, y: the sensor's position in the prior's frame (m); radius: how far off it
// may be (default 5 m, 0.5-100); heading: the direction the payload faces,
// counter-clockwise from the prior's x axis (degrees; absent: any heading);
// heading_tolerance: ± round it (default 20°, 1-180).

#include <optional>
#include <string>
#include <vector>

namespace adit::protocol {

struct LocaliseHint {
  double x_m = 0.0;
  double y_m = 0.0;
  double radius_m = 5.0;
  std::optional<double> heading_deg;
  double heading_tolerance_deg = 20.0;
};

// The hint in `args`, or nullopt with `error` saying which argument is wrong.
std::optional<LocaliseHint> parse_localise_hint(const std::vector<std::string>& args, std::string& error);

// The arguments that parse back to `hint` (for clients).
std::vector<std::string> localise_hint_args(const LocaliseHint& hint);

}  // namespace adit::protocol
