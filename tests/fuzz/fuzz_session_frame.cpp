// Fuzzes what places a session in the map frame: prior_frame.json's text (read
// back at the session's end and on recovery after a crash), and the frame_t
// graph_path_t and loop_status_t a client receives. A bad file must throw
// adit::InputError, a bad message be refused; whatever is accepted must be a
// finite rigid transform, a graph path as many x y z triples as it says, and a
// loop status what its bytes hold, whole (encoded again, the same bytes).

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <string_view>
#include <vector>

#include "adit/common/error.hpp"
#include "adit/daemon/session_frame.hpp"
#include "adit/frame_t.hpp"
#include "adit/graph_path_t.hpp"
#include "adit/loop_status_t.hpp"
#include "adit/protocol/checked_decode.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const Eigen::Isometry3d t =
        adit::daemon::parse_prior_frame(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.json");
    const double error = (t.linear().transpose() * t.linear() - Eigen::Matrix3d::Identity()).norm();
    if (!t.matrix().allFinite() || !(error < 1e-5)) std::abort();  // accepted, yet not rigid
  } catch (const adit::InputError&) {
  }
  adit::frame_t frame;
  (void)adit::protocol::checked_decode(data, size, frame);
  adit::graph_path_t path;
  if (adit::protocol::checked_decode(data, size, path)) {
    if (path.n < 0 || path.positions.size() != static_cast<std::size_t>(path.n)) std::abort();
    for (const auto& p : path.positions)
      if (p.size() != 3) std::abort();
  }
  adit::loop_status_t loops;
  if (adit::protocol::checked_decode(data, size, loops)) {
    const int n = loops.getEncodedSize();
    if (n != static_cast<int>(size)) std::abort();
    std::vector<std::uint8_t> again(size);
    if (loops.encode(again.data(), 0, n) != n || std::memcmp(again.data(), data, size) != 0) std::abort();
  }
  return 0;
}
