// The live grid's stream without sockets: changed patches at most once per
// period, every patch again within the refresh cycle, nothing of an old session.
#include <gtest/gtest.h>

#include <map>
#include <vector>

#include "adit/daemon/grid_publisher.hpp"
#include "adit/protocol/grid_mosaic.hpp"

namespace adit::daemon {
namespace {

using namespace std::chrono_literals;

struct RecordingGridSink : GridPatchSink {
  std::vector<grid_patch_t> sent;
  void send(const grid_patch_t& patch) override { sent.push_back(patch); }
};

GridPatchUpdate patch_update(int x, int y, int version) {
  GridPatchUpdate u;
  u.utime = 1;
  u.x = x;
  u.y = y;
  u.version = version;
  u.patches = 1;
  u.resolution_m = 0.05F;
  u.patch_cells = 16;
  u.cells.assign(16 * 16, 0);
  u.cells[static_cast<std::size_t>(version % 256)] = 100;
  return u;
}

TEST(GridPublisher, ChangedPatchesGoOutOncePerPeriodAndEveryPatchAgainWithinTheRefresh) {
  RecordingGridSink sink;
  GridPublisher publisher({"rig1", 1.0, 10.0}, sink);
  publisher.reset("s1");
  for (int i = 0; i < 20; ++i) publisher.update(patch_update(i, -i, 1));
  const auto t0 = GridPublisher::Clock::now();
  publisher.tick(t0);
  ASSERT_EQ(sink.sent.size(), 20U);  // every patch changed
  EXPECT_EQ(publisher.counts().refreshes_sent, 0U);
  for (const grid_patch_t& m : sink.sent) {
    EXPECT_EQ(m.session_id, "s1");
    EXPECT_EQ(m.payload_id, "rig1");
    EXPECT_EQ(m.n_patches, 20);
  }
  publisher.tick(t0 + 500ms);  // within the period: nothing
  EXPECT_EQ(sink.sent.size(), 20U);
  // Ten periods: two refreshed per period (20 patches / 10 s), each once.
  sink.sent.clear();
  std::map<std::pair<int, int>, int> refreshed;
  for (int k = 1; k <= 10; ++k) {
    publisher.tick(t0 + k * 1s);
    EXPECT_EQ(sink.sent.size(), 2U * static_cast<std::size_t>(k));
  }
  for (const grid_patch_t& m : sink.sent) ++refreshed[{m.patch_x, m.patch_y}];
  EXPECT_EQ(refreshed.size(), 20U);
  for (const auto& [key, n] : refreshed) EXPECT_EQ(n, 1);
  // A change goes out in the next period, beside that period's refresh share.
  sink.sent.clear();
  publisher.update(patch_update(3, -3, 2));
  publisher.tick(t0 + 11s);
  ASSERT_EQ(sink.sent.size(), 3U);
  EXPECT_EQ(sink.sent[0].patch_x, 3);
  EXPECT_EQ(sink.sent[0].version, 2);
  EXPECT_NE(sink.sent[1].patch_x, 3);
  EXPECT_NE(sink.sent[2].patch_x, 3);
  EXPECT_GT(publisher.counts().bytes_sent, 0U);
}

TEST(GridPublisher, WhatItSendsIsWhatTheMosaicDrawsAndANewSessionStartsEmpty) {
  RecordingGridSink sink;
  GridPublisher publisher({"rig1", 0.5, 5.0}, sink);
  publisher.reset("s1");
  publisher.update(patch_update(-1, 0, 7));
  publisher.update(patch_update(0, 0, 9));
  publisher.tick(GridPublisher::Clock::now());
  protocol::GridMosaic mosaic;
  for (const grid_patch_t& m : sink.sent) EXPECT_EQ(mosaic.accept(m), "");
  const protocol::GridImage image = mosaic.image();
  ASSERT_EQ(image.width, 32);
  EXPECT_EQ(image.cells[7], 100);        // patch (-1, 0), version 7's mark
  EXPECT_EQ(image.cells[16 + 9], 100);   // patch (0, 0), version 9's
  EXPECT_EQ(image.cells[16 + 7], 0);
  publisher.reset("s2");
  sink.sent.clear();
  publisher.tick(GridPublisher::Clock::now() + 1s);
  EXPECT_TRUE(sink.sent.empty());
  EXPECT_EQ(publisher.patch_count(), 0U);
}

}  // namespace
}  // namespace adit::daemon
