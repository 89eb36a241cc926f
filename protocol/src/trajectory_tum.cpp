#include "adit/protocol/trajectory_tum.hpp"

#include <fmt/format.h>
#include <fmt/ostream.h>

namespace adit::protocol {

void write_tum(std::ostream& out, std::span<const StampedPose> poses) {
  for (const StampedPose& p : poses)
    fmt::print(out, "{:.6f} {:.6f} {:.6f} {:.6f} {:.9f} {:.9f} {:.9f} {:.9f}\n", p.time, p.x, p.y, p.z, p.qx, p.qy,
               p.qz, p.qw);
}

}  // namespace adit::protocol
