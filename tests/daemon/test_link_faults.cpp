// A LiDAR link as the field has it: the cable out for 2 s, 5 % of the packets
// lost, 1 % repeated and 1 % arriving late (after the next one). The pipeline
// counts each (summary, status), skips what it must, and the trajectory stays
// on the simulated truth as the clean link's does.
#include <gtest/gtest.h>

#include <fstream>
#include <cstdio>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "adit/config/load.hpp"
#include "adit/daemon/pipeline.hpp"
#include "daemon_process.hpp"
#include "pipeline_run.hpp"
#include "run_program.hpp"
#include "sim_sessions.hpp"
#include "shared_data.hpp"

namespace adit::daemon {
namespace {


struct Faults {
  std::uint64_t packets = 0, cable_out = 0, lost = 0, repeated = 0, late = 0;
};

// `adit faults pcap`: the cable out from 4 s to 6 s, then each packet lost
// (5 %), held back behind the next one (1 %) or repeated (1 %), seeded.
Faults faulty_copy(const std::filesystem::path& in, const std::filesystem::path& out, std::uint32_t seed) {
  const test::CommandRun run = test::run_adit(fmt::format(
      "faults pcap {} {} --cut 4:2 --loss 0.05 --late 0.01 --repeat 0.01 --seed {}", in.string(), out.string(), seed));
  EXPECT_EQ(run.status, 0) << run.output;
  Faults f;
  const std::size_t at = run.output.find(": ", run.output.find(out.filename().string()));
  EXPECT_EQ(std::sscanf(run.output.c_str() + at, ": %lu packets; cable out %lu, lost %lu, repeated %lu, late %lu", &f.packets,
                        &f.cable_out, &f.lost, &f.repeated, &f.late),
            5)
      << run.output;
  return f;
}

struct LinkRun {
  std::uint64_t poses = 0, missing = 0, duplicate = 0, late = 0, silences = 0;
  double ape_rmse_m = 0.0;
  double longest_silence_s = 0.0;
};

LinkRun map_with(const std::filesystem::path& pcap, const std::filesystem::path& work) {
  const test::ScoredRun scored =
      test::run_and_score(test::mine_drive_12s(), work, [&](config::Config& c) { c.lidar.pcap = pcap.string(); });
  const PipelineStats& s = scored.pipeline->stats();
  return {s.poses.load(),    s.missing_packets.load(), s.duplicate_packets.load(),
          s.late_packets.load(), s.silences.load(),     scored.ape_rmse_m,
          1e-9 * static_cast<double>(s.longest_silence_ns.load())};
}

TEST(LinkFaults, LostRepeatedLateAndCutPacketsAreCountedAndTheTrajectoryHolds) {
  const std::filesystem::path work = test::binary_dir() / fmt::format("link-faults-{}", ::getpid());
  std::filesystem::remove_all(work);
  std::filesystem::create_directories(work);
  const std::filesystem::path session = test::mine_drive_12s();
  const LinkRun clean = map_with(session / "lidar.pcap", work / "clean");
  EXPECT_EQ(clean.missing + clean.duplicate + clean.late + clean.silences, 0U);

  std::vector<double> apes;
  for (const std::uint32_t seed : {1U, 2U, 3U}) {
    SCOPED_TRACE(fmt::format("seed {}", seed));
    const std::filesystem::path faulty = work / fmt::format("faulty-{}.pcap", seed);
    const Faults f = faulty_copy(session / "lidar.pcap", faulty, seed);
    const LinkRun r = map_with(faulty, work / fmt::format("faulty-{}", seed));
    // Every fault counted: what the link lost (cable out, lost, held packets
    // counted missing when their slot passes), repeated and late.
    EXPECT_EQ(r.duplicate, f.repeated);
    EXPECT_EQ(r.late, f.late);
    EXPECT_GE(r.missing, f.lost + f.cable_out);
    EXPECT_LE(r.missing, f.lost + f.cable_out + f.late);
    EXPECT_EQ(r.silences, 1U) << "the cable out, once";
    EXPECT_NEAR(r.longest_silence_s, 2.0, 0.01);
    // 2 s without packets: about 20 scans fewer, and no more.
    EXPECT_LT(r.poses, clean.poses - 15);
    EXPECT_GT(r.poses, clean.poses - 30);
    apes.push_back(r.ape_rmse_m);
    EXPECT_LT(r.ape_rmse_m, clean.ape_rmse_m + 0.05) << "clean " << clean.ape_rmse_m;
  }
  std::printf("APE rmse: clean link %.3f m; faulty links %.3f, %.3f, %.3f m\n", clean.ape_rmse_m, apes[0], apes[1],
              apes[2]);
  std::filesystem::remove_all(work);
}

}  // namespace
}  // namespace adit::daemon
