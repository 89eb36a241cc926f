// adit can-decode, can-info and calibrate-wheels run as a user would, on the
// RAV4 drive and on broken input.

#include <filesystem>
#include <fstream>

#include <unistd.h>

#include <gtest/gtest.h>

#include "run_program.hpp"
#include "shared_data.hpp"

namespace adit::test {
namespace {

std::string adit() { return (binary_dir() / "bin" / "adit").string(); }

// Per process: ctest -j runs this file's tests side by side.
std::filesystem::path temp(const std::string& name) {
  return std::filesystem::temp_directory_path() / (std::to_string(::getpid()) + "-" + name);
}

TEST(CanPrograms, DecodeWritesCsvAndCountsMalformedLines) {
  ADIT_REQUIRE_SHARED_DATA(dir, "can/toyota-rav4-2017");
  const auto log = temp("adit-test-can-decode.log");
  {
    std::ofstream out(log);
    out << "(46408.589503) can0 0AA#25B525B525A0258D\n(46408.59) can0 0AA#25\nnot a line\n(46408.598408) can0 123#00\n";
  }
  const auto csv = temp("adit-test-can-decode.csv");
  const ProgramResult r = run_program({adit(), "can-decode", log.string(), "--dbc", (dir / "toyota_rav4_2017.dbc").string(),
                                       "--signals", "WHEEL_SPEED_FL,WHEEL_SPEEDS.WHEEL_SPEED_RR", "--csv", csv.string()});
  EXPECT_EQ(r.exit_status, 0) << r.err;
  EXPECT_NE(r.err.find(log.string() + ":3: "), std::string::npos) << r.err;  // "not a line"
  EXPECT_NE(r.err.find("1 of unknown id"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("1 of wrong length"), std::string::npos) << r.err;
  std::ifstream in(csv);
  std::string header, row, extra;
  std::getline(in, header);
  std::getline(in, row);
  EXPECT_EQ(header, "t,interface,message,WHEEL_SPEEDS.WHEEL_SPEED_FL[m/s],WHEEL_SPEEDS.WHEEL_SPEED_RR[m/s]");
  EXPECT_TRUE(row.starts_with("46408.589503,can0,WHEEL_SPEEDS,8.01666666666666")) << row;
  EXPECT_FALSE(std::getline(in, extra));
  std::filesystem::remove(log);
  std::filesystem::remove(csv);
}

TEST(CanPrograms, UnknownSignalIsBadInput) {
  ADIT_REQUIRE_SHARED_DATA(dir, "can/toyota-rav4-2017");
  const ProgramResult r = run_program({adit(), "can-decode", (dir / "drive.candump.log").string(), "--dbc",
                                       (dir / "toyota_rav4_2017.dbc").string(), "--signals", "NO_SUCH_SIGNAL"});
  EXPECT_EQ(r.exit_status, 2);
  EXPECT_NE(r.err.find("NO_SUCH_SIGNAL"), std::string::npos) << r.err;
}

TEST(CanPrograms, InfoSummarisesBusesAndIds) {
  ADIT_REQUIRE_SHARED_DATA(dir, "can/toyota-rav4-2017");
  const ProgramResult r = run_program({adit(), "can-info", (dir / "drive.candump.log").string(), "--dbc",
                                       (dir / "toyota_rav4_2017.dbc").string()});
  ASSERT_EQ(r.exit_status, 0) << r.err;
  EXPECT_NE(r.out.find("135468 frames, 0 malformed lines"), std::string::npos) << r.out;
  for (const char* bus : {"bus can0: 53800 frames", "bus can1: 45000 frames", "bus can128: 12434", "bus can129: 24234"})
    EXPECT_NE(r.out.find(bus), std::string::npos) << bus;
  EXPECT_NE(r.out.find("WHEEL_SPEEDS"), std::string::npos);
}

TEST(CanPrograms, CalibrateWheelsReportsFitAndEndpointErrors) {
  ADIT_REQUIRE_SHARED_DATA(dir, "can/toyota-rav4-2017");
  const ProgramResult r = run_program({adit(), "calibrate-wheels", "--log", (dir / "drive.candump.log").string(), "--dbc",
                                       (dir / "toyota_rav4_2017.dbc").string(), "--reference",
                                       (dir / "reference-pose-track-enu.csv").string(), "--bus", "can0"});
  ASSERT_EQ(r.exit_status, 0) << r.err;
  for (const char* line : {"effective track", "time offset", "residual rms", "endpoint error", "converged"})
    EXPECT_NE(r.out.find(line), std::string::npos) << line << "\n" << r.out;
}

}  // namespace
}  // namespace adit::test
