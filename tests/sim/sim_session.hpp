#pragma once
// A short simulated session shared by the simulator tests, generated once per
// test binary into the build tree.

#include <filesystem>
#include <string>

#include "adit/sim/session.hpp"
#include "shared_data.hpp"

namespace adit::sim::test {

inline SimOptions short_session(const std::string& name) {
  SimOptions o;
  o.scene = "mine";
  o.duration_s = 11.0;  // the robot's shortest: 1 s still, two legs with ramps, the turn
  o.seed = 7;
  o.out = ::adit::test::binary_dir() / "test-sessions" / name;
  return o;
}

}  // namespace adit::sim::test
