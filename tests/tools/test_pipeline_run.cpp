// The pieces of `adit replay` that are arithmetic or configuration: resident
// growth measured from when the local map is full, and command-line overrides.

#include <gtest/gtest.h>

#include "adit/common/error.hpp"
#include "pipeline_run.hpp"
#include "temp_file.hpp"

namespace adit::tools {
namespace {

TEST(MemoryGrowth, IsMeasuredFromTheGivenFractionToTheEnd) {
  // Growing while the map fills (poses 0..9), then flat but for one spike.
  std::vector<MemorySample> samples;
  for (std::uint64_t i = 0; i <= 100; ++i) samples.push_back({i, i < 10 ? 50.0 + 5.0 * static_cast<double>(i) : 100.0});
  samples[60].resident_mb = 104.0;
  samples.back().resident_mb = 102.0;
  const auto g = memory_growth(samples, 0.1);
  ASSERT_TRUE(g);
  EXPECT_EQ(g->from_pose, 10U);
  EXPECT_DOUBLE_EQ(g->from_mb, 100.0);
  EXPECT_DOUBLE_EQ(g->end_mb, 102.0);
  EXPECT_DOUBLE_EQ(g->max_mb, 104.0);
  EXPECT_DOUBLE_EQ(g->percent(), 2.0);
  // From the start it would count the filling of the map as growth.
  EXPECT_DOUBLE_EQ(memory_growth(samples, 0.0)->percent(), 104.0);
  EXPECT_FALSE(memory_growth(std::vector<MemorySample>{{3, 10.0}}, 0.1));
}

TEST(MemoryGrowth, SkipsPosesThatWereNotSampled) {
  const std::vector<MemorySample> samples{{0, 10.0}, {4, 20.0}, {30, 21.0}, {40, 22.0}};
  const auto g = memory_growth(samples, 0.5);  // pose 20 was not sampled: the next one counts
  ASSERT_TRUE(g);
  EXPECT_EQ(g->from_pose, 30U);
  EXPECT_NEAR(g->percent(), 100.0 / 21.0, 1e-9);
}

TEST(MemoryGrowth, GivesMallocsBytesInUseFromTheFirstHeapSampleOnAndTheMapsSize) {
  // The heap is walked every few samples only (heap_mb < 0 elsewhere).
  const std::vector<MemorySample> samples{
      {0, 10.0, 5.0, 1.0}, {10, 20.0, -1.0, 2.0}, {12, 21.0, 8.0, 3.0}, {20, 22.0, -1.0, 4.0}, {30, 23.0, 9.0, 6.0}};
  const auto g = memory_growth(samples, 0.3);
  ASSERT_TRUE(g);
  EXPECT_EQ(g->from_pose, 10U);
  EXPECT_DOUBLE_EQ(g->heap_from_mb, 8.0) << "the first heap sample from pose 10 on";
  EXPECT_DOUBLE_EQ(g->heap_end_mb, 9.0);
  EXPECT_DOUBLE_EQ(g->map_from_mb, 2.0);
  EXPECT_DOUBLE_EQ(g->map_end_mb, 6.0);
  // Resident less the tiles, largest from pose 10 on: 20 - 2, 21 - 3, 22 - 4, 23 - 6.
  EXPECT_DOUBLE_EQ(g->max_beyond_map_mb, 18.0);
  const std::string text = figures_text(PipelineFigures{.memory = samples}, 0.3);
  EXPECT_NE(text.find("malloc in use 8.0 -> 9.0 MB, map tiles 2.0 -> 6.0 MB"), std::string::npos) << text;
  EXPECT_NE(text.find("max 18.0 MB beyond the map's tiles"), std::string::npos) << text;
}

TEST(PipelineConfig, CommandLineOverridesTheFile) {
  const test::TempFile file(
      "payload:\n  id: t\nlidar:\n  model: VLP-16\n  source: udp\n  calibration: cal.yaml\n", ".yaml");
  PipelineInputs in;
  in.config_file = file.path().string();
  const config::Config kept = load_pipeline_config(in);
  EXPECT_EQ(kept.lidar.source, config::LidarSource::udp);
  EXPECT_EQ(kept.lidar.calibration, (file.path().parent_path() / "cal.yaml").string());
  EXPECT_FALSE(kept.threads.lock_memory);

  in.pcap = "relative/capture.pcap";
  in.model = "HDL-32E";
  in.calibration = "other.yaml";
  const config::Config changed = load_pipeline_config(in);
  EXPECT_EQ(changed.lidar.source, config::LidarSource::pcap);
  EXPECT_EQ(changed.lidar.pcap, "relative/capture.pcap");  // as typed: relative to the working directory
  EXPECT_EQ(changed.lidar.model, "HDL-32E");
  EXPECT_EQ(changed.lidar.calibration, "other.yaml");

  in.pcap.clear();
  in.scan_dir = "scans";
  EXPECT_EQ(load_pipeline_config(in).lidar.source, config::LidarSource::scan_dir);

  in.config_file = "/nonexistent/adit.yaml";
  EXPECT_THROW(load_pipeline_config(in), InputError);
}

}  // namespace
}  // namespace adit::tools
