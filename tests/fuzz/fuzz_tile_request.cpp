// Fuzzes the daemon's answer to tile requests from the network: any bytes on
// ADIT/<id>/TILE_REQUEST are decoded (or refused) and answered from a small
// tile store without a crash, and never with more segments than exist.

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <vector>

#include "adit/daemon/tile_publisher.hpp"
#include "adit/protocol/checked_decode.hpp"

namespace {

struct CountingSink : adit::daemon::TileSink {
  std::size_t chunks = 0;
  void send(const adit::tile_segment_t&) override { ++chunks; }
  void send(const adit::tile_index_t&) override {}
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  adit::tile_request_t request;
  if (!adit::protocol::checked_decode(data, size, request)) return 0;
  CountingSink sink;
  adit::daemon::TilePublisher publisher({"rig1", {}, 1.0, 1.0e9, 0.0, 1, {}}, sink);
  publisher.reset("s1");
  std::vector<adit::protocol::MapPoint> points(64);
  for (std::size_t i = 0; i < points.size(); ++i) points[i] = {0.1 * i, 0.2, 0.3, 1.0f, 0};
  publisher.update({0, 0, 0}, 0, points, 1);
  publisher.update({-1, 2, 0}, 0, points, 1);
  publisher.answer(request);
  auto now = adit::daemon::TilePublisher::Clock::now();
  for (int i = 0; i < 4; ++i) publisher.tick(now += std::chrono::seconds(1));
  // Two one-segment tiles: the broadcast sends each once, an answer at most once more.
  if (sink.chunks > 4) std::abort();
  return 0;
}
