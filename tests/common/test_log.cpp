#include <gtest/gtest.h>

#include "adit/common/log.hpp"

namespace adit::log {
namespace {

TEST(Log, ParsesEveryLevelNameAndRoundTrips) {
  for (const char* name : {"trace", "debug", "info", "warn", "error", "off"}) {
    const auto level = parse_level(name);
    ASSERT_TRUE(level.has_value()) << name;
    EXPECT_EQ(level_name(*level), name);
  }
}

TEST(Log, RejectsUnknownLevelNames) {
  EXPECT_FALSE(parse_level("verbose").has_value());
  EXPECT_FALSE(parse_level("INFO").has_value());
  EXPECT_FALSE(parse_level("").has_value());
}

TEST(Log, SetLevelIsObserved) {
  init("test", Level::warn);
  EXPECT_EQ(level(), Level::warn);
  set_level(Level::debug);
  EXPECT_EQ(level(), Level::debug);
}

}  // namespace
}  // namespace adit::log
