#include <gtest/gtest.h>

#include "adit/common/error.hpp"
#include "adit/drivers/can/dbc.hpp"

namespace can = adit::drivers::can;

namespace {
constexpr std::string_view kDbc = R"(VERSION ""
BU_: A B
BO_ 170 WHEEL_SPEEDS: 8 XXX
 SG_ WHEEL_SPEED_FR : 6|15@0+ (0.01,-67.67) [0|250] "km/h" A,B
 SG_ TEMP : 48|8@1- (0.5,+10) [-50|100] "degC" B
BO_ 2566844926 ODO: 8 B
 SG_ MUX M : 0|4@1+ (1,0) [0|0] "" A
 SG_ POS m1 : 32|32@1- (1,0) [0|0] "counts" A
 SG_ VEL m2 : 32|32@1+ (1,0) [0|0] "turns/s" A
BO_ 3221225472 VECTOR__INDEPENDENT_SIG_MSG: 0 Vector__XXX
 SG_ ORPHAN : 0|8@1+ (1,0) [0|0] "" A
CM_ SG_ 170 WHEEL_SPEED_FR "comment";
SIG_VALTYPE_ 2566844926 VEL : 1;
)";
}

TEST(Dbc, ReadsMessagesSignalsAndFloatTypes) {
  const can::Database db = can::parse_dbc(kDbc, "test.dbc");
  ASSERT_EQ(db.messages.size(), 2U);
  const can::MessageSpec* ws = db.find("WHEEL_SPEEDS");
  ASSERT_NE(ws, nullptr);
  EXPECT_EQ(ws->id, 170U);
  EXPECT_FALSE(ws->extended);
  ASSERT_EQ(ws->signals.size(), 2U);
  const can::SignalSpec& fr = ws->signals[0];
  EXPECT_EQ(fr.start_bit, 6U);
  EXPECT_EQ(fr.length, 15U);
  EXPECT_EQ(fr.byte_order, can::ByteOrder::motorola);
  EXPECT_FALSE(fr.is_signed);
  EXPECT_DOUBLE_EQ(fr.factor, 0.01);
  EXPECT_DOUBLE_EQ(fr.offset, -67.67);
  EXPECT_DOUBLE_EQ(fr.maximum, 250);
  EXPECT_EQ(fr.unit, "km/h");
  EXPECT_TRUE(ws->signals[1].is_signed);
  EXPECT_DOUBLE_EQ(ws->signals[1].offset, 10);
  EXPECT_DOUBLE_EQ(ws->signals[1].minimum, -50);

  const can::MessageSpec* odo = db.find(0x18FEF1FE, true);
  ASSERT_NE(odo, nullptr);
  EXPECT_EQ(odo->signals[0].multiplex, can::Multiplex::selector);
  EXPECT_EQ(odo->signals[1].multiplex, can::Multiplex::multiplexed);
  EXPECT_EQ(odo->signals[2].multiplex_value, 2U);
  EXPECT_EQ(odo->signals[2].type, can::ValueType::float32);
  EXPECT_EQ(db.find("VECTOR__INDEPENDENT_SIG_MSG"), nullptr);
}

TEST(Dbc, MalformedLinesNameFileAndLine) {
  const auto where = [](std::string_view text) {
    try {
      can::parse_dbc(text, "bad.dbc");
    } catch (const adit::InputError& e) {
      return e.where() + " " + e.key();
    }
    return std::string("no error");
  };
  EXPECT_EQ(where("BO_ 1 A: 8 X\n SG_ S : 0|8@2+ (1,0) [0|0] \"\" X\n"), "bad.dbc:2 SG_");
  EXPECT_EQ(where("BO_ 1 A: 8 X\n SG_ S : 0|8@1+ (1,0 [0|0] \"\" X\n"), "bad.dbc:2 SG_");
  EXPECT_EQ(where("\n\nBO_ x A: 8 X\n"), "bad.dbc:3 BO_");
  EXPECT_EQ(where(" SG_ S : 0|8@1+ (1,0) [0|0] \"\" X\n"), "bad.dbc:1 SG_");
  EXPECT_EQ(where("BO_ 1 A: 2 X\n SG_ S : 8|16@1+ (1,0) [0|0] \"\" X\n"), "bad.dbc:2 SG_");  // does not fit
  EXPECT_EQ(where("BO_ 1 A: 8 X\n SG_ S : 0|0@1+ (1,0) [0|0] \"\" X\n"), "bad.dbc:2 SG_");
  EXPECT_EQ(where("BO_ 1 A: 8 X\n SG_ S : 0|8@1+ (1,0) [0|0] \"\" X\nSIG_VALTYPE_ 1 S : 1;\n"), "bad.dbc:3 SIG_VALTYPE_");
}
