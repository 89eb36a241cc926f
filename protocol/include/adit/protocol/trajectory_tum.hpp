#pragma once
// TUM RGB-D trajectory files ("timestamp tx ty tz qx qy qz qw" per line, as
// read by evo and the TUM benchmark tools). A small writer of our own: the
// eval branch's trajectory writer had not been merged into main yet.

#include <ostream>
#include <span>

namespace adit::protocol {

struct StampedPose {
  double time = 0;  // s
  double x = 0, y = 0, z = 0;
  double qw = 1, qx = 0, qy = 0, qz = 0;
};

void write_tum(std::ostream& out, std::span<const StampedPose> poses);

}  // namespace adit::protocol
