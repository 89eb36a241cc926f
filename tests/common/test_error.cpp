#include <gtest/gtest.h>

#include "adit/common/error.hpp"
#include "adit/common/main.hpp"

namespace adit {
namespace {

TEST(InputError, MessageNamesWhereKeyAndReason) {
  const InputError e("cfg.yaml:12", "lidar.port", "expected an integer");
  EXPECT_STREQ(e.what(), "cfg.yaml:12: lidar.port: expected an integer");
  EXPECT_EQ(e.where(), "cfg.yaml:12");
  EXPECT_EQ(e.key(), "lidar.port");
  EXPECT_EQ(e.reason(), "expected an integer");
}

TEST(GuardedMain, MapsInputErrorToStatus2AndOtherErrorsTo1) {
  EXPECT_EQ(guarded_main("t", []() -> int { throw InputError("f", "k", "bad"); }), kExitBadInput);
  EXPECT_EQ(guarded_main("t", []() -> int { throw std::runtime_error("boom"); }), kExitFailure);
  EXPECT_EQ(guarded_main("t", []() -> int { return 0; }), kExitOk);
}

}  // namespace
}  // namespace adit
