// Every program rejects a bad configuration the same way: exit status 2 and
// one line on stderr naming the file, the line and the key.

#include <gtest/gtest.h>

#include <fstream>

#include "run_program.hpp"
#include "shared_data.hpp"

namespace adit::test {
namespace {

struct BadConfig {
  const char* name;
  const char* yaml;
  const char* expected;  // "file:line: key: reason" after the file name
};

const BadConfig kBadConfigs[] = {
    {"typo", "payload:\n  id: x\nlidar:\n  model: VLP-16\n  prot: 1\n", ":5: lidar.prot: unknown key (did you mean 'port'?)"},
    {"wrong_type", "payload:\n  id: x\nlidar:\n  model: VLP-16\n  port: abc\n", ":5: lidar.port: expected an integer, got 'abc'"},
    {"missing", "payload:\n  id: x\nlidar:\n  port: 1\n", ":4: lidar.model: required key is missing"},
};

void PrintTo(const BadConfig& config, std::ostream* os) { *os << config.name; }

class ProgramsRejectBadConfig : public ::testing::TestWithParam<BadConfig> {
 protected:
  std::string write_config() const {
    const std::string path = (binary_dir() / (std::string("bad-config-") + GetParam().name + ".yaml")).string();
    std::ofstream(path) << GetParam().yaml;
    return path;
  }
  static void expect_one_line(const ProgramResult& r, const std::string& program, const std::string& expected) {
    EXPECT_EQ(r.exit_status, 2) << r.err;
    EXPECT_EQ(r.err, program + ": error: " + expected + "\n");
  }
};

TEST_P(ProgramsRejectBadConfig, AditdCheckConfig) {
  const std::string file = write_config();
  expect_one_line(run_program({(binary_dir() / "bin/aditd").string(), "--config", file, "--check-config"}), "aditd",
                  file + GetParam().expected);
}

TEST_P(ProgramsRejectBadConfig, AditdStartup) {
  const std::string file = write_config();
  expect_one_line(run_program({(binary_dir() / "bin/aditd").string(), "--config", file}), "aditd",
                  file + GetParam().expected);
}

TEST_P(ProgramsRejectBadConfig, AditConfigCheck) {
  const std::string file = write_config();
  expect_one_line(run_program({(binary_dir() / "bin/adit").string(), "config", "check", file}), "adit",
                  file + GetParam().expected);
}

INSTANTIATE_TEST_SUITE_P(Cases, ProgramsRejectBadConfig, ::testing::ValuesIn(kBadConfigs),
                         [](const auto& info) { return std::string(info.param.name); });

TEST(Programs, CheckConfigAcceptsTheShippedConfigs) {
  for (const char* file : {"firmware-config/default.yaml", "firmware-config/templates/vlp16-diffdrive-robot.yaml"}) {
    const auto r = run_program({(binary_dir() / "bin/aditd").string(), "--config", (source_dir() / file).string(),
                                "--check-config"});
    EXPECT_EQ(r.exit_status, 0) << file << ": " << r.err;
    EXPECT_NE(r.out.find("is valid"), std::string::npos);
  }
}

TEST(Programs, HelpDescribesEveryOptionAndSubcommand) {
  const auto daemon = run_program({(binary_dir() / "bin/aditd").string(), "--help"});
  EXPECT_EQ(daemon.exit_status, 0);
  for (const char* option : {"--config", "--check-config", "--print-config", "--log-level", "--version"})
    EXPECT_NE(daemon.out.find(option), std::string::npos) << option;
  const auto client = run_program({(binary_dir() / "bin/adit").string(), "--help-all"});
  EXPECT_EQ(client.exit_status, 0);
  for (const char* text : {"config", "check", "show", "--log-level"})
    EXPECT_NE(client.out.find(text), std::string::npos) << text;
}

TEST(Programs, UnknownOptionsExitWithStatus2) {
  EXPECT_EQ(run_program({(binary_dir() / "bin/aditd").string(), "--no-such-option"}).exit_status, 2);
  EXPECT_EQ(run_program({(binary_dir() / "bin/adit").string(), "no-such-command"}).exit_status, 2);
}

}  // namespace
}  // namespace adit::test
