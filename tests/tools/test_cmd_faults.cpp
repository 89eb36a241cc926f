// adit faults: the schedule lands where it says, and bad arguments are named.
// (Its effect through aditd: tests/daemon/test_link_faults.cpp, test_sensor_faults.cpp.)
#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include <fmt/format.h>
#include <unistd.h>

#include "run_program.hpp"
#include "shared_data.hpp"

namespace {

using adit::test::CommandRun;
using adit::test::run_adit;

std::filesystem::path log_of(double seconds) {  // wheels at 100 Hz
  const std::filesystem::path file = adit::test::binary_dir() / fmt::format("faults-in-{}.log", ::getpid());
  std::ofstream out(file);
  for (int i = 0; i < static_cast<int>(seconds * 100); ++i)
    out << fmt::format("({:.6f}) can0 {}#0102\n", 1000.0 + 0.01 * i, i % 2 ? "190" : "181");
  return file;
}

TEST(CmdFaults, BusOffAndDropWindowsRepeatEveryPeriod) {
  const std::filesystem::path in = log_of(20.0);
  const std::filesystem::path out = adit::test::binary_dir() / fmt::format("faults-out-{}.log", ::getpid());
  const CommandRun run = run_adit(fmt::format("faults can {} {} --bus-off 2:1 --drop 5:2 --drop-ids 0x190 --every 10",
                                              in.string(), out.string()));
  ASSERT_EQ(run.status, 0) << run.output;
  // Twice bus-off (2-3 s, 12-13 s): 100 frames each; 0x190 (every other frame) missing 5-7 s and 15-17 s.
  EXPECT_NE(run.output.find("2000 frames; bus off 2 times (200 frames silenced), 200 frames of the dropped ids"),
            std::string::npos)
      << run.output;
  std::ifstream written(out);
  int error_frames = 0, lines = 0;
  for (std::string line; std::getline(written, line); ++lines)
    if (line.find(" 20000040#") != std::string::npos || line.find(" 20000100#") != std::string::npos) ++error_frames;
  EXPECT_EQ(error_frames, 4);
  EXPECT_EQ(lines, 2000 - 200 - 200 + 4);
  std::filesystem::remove(in);
  std::filesystem::remove(out);
}

TEST(CmdFaults, BadArgumentsAreNamed) {
  const std::filesystem::path in = log_of(1.0);
  const std::string out = (adit::test::binary_dir() / "faults-never.log").string();
  CommandRun run = run_adit(fmt::format("faults can {} {} --drop 1:1 --drop-ids 0xZZ", in.string(), out));
  EXPECT_EQ(run.status, 2);
  EXPECT_NE(run.output.find("--drop-ids: not a CAN id: '0xZZ'"), std::string::npos) << run.output;
  run = run_adit(fmt::format("faults can {} {} --bus-off 5", in.string(), out));
  EXPECT_EQ(run.status, 2);
  EXPECT_NE(run.output.find("--bus-off: expected AT:FOR"), std::string::npos) << run.output;
  run = run_adit(fmt::format("faults pcap {} {} --loss 0.6 --late 0.6", in.string(), out));
  EXPECT_NE(run.status, 0);
  EXPECT_NE(run.output.find("--loss"), std::string::npos) << run.output;
  std::filesystem::remove(in);
}

}  // namespace
