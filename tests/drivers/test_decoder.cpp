#include <cmath>
#include <cstring>
#include <vector>

#include <gtest/gtest.h>

#include "adit/common/error.hpp"
#include "adit/drivers/can/dbc.hpp"
#include "adit/drivers/can/decoder.hpp"
#include "adit/drivers/can/presets.hpp"
#include "adit/drivers/can/units.hpp"

namespace can = adit::drivers::can;

namespace {

can::Frame frame(std::uint32_t id, std::initializer_list<std::uint8_t> bytes, bool extended = false) {
  can::Frame f;
  f.id = id;
  f.extended = extended;
  f.length = static_cast<std::uint8_t>(bytes.size());
  std::copy(bytes.begin(), bytes.end(), f.data.begin());
  return f;
}

can::SignalSpec signal(std::string name, unsigned start, unsigned length, can::ByteOrder order, bool is_signed) {
  can::SignalSpec s;
  s.name = std::move(name);
  s.start_bit = start;
  s.length = length;
  s.byte_order = order;
  s.is_signed = is_signed;
  return s;
}

}  // namespace

TEST(Decoder, IntelAndMotorolaLayoutsSignsAndScaling) {
  can::MessageSpec m;
  m.id = 0x100;
  m.length = 8;
  m.signals.push_back(signal("intel12", 4, 12, can::ByteOrder::intel, false));      // bits 4..15
  m.signals.push_back(signal("moto15", 22, 15, can::ByteOrder::motorola, false));   // bytes 2..3 like RAV4
  m.signals.push_back(signal("intel_neg", 32, 16, can::ByteOrder::intel, true));
  m.signals.push_back(signal("moto_neg", 55, 8, can::ByteOrder::motorola, true));   // byte 6 whole
  m.signals[1].factor = 0.01;
  m.signals[1].offset = -67.67;
  m.signals[1].unit = "km/h";
  const std::vector<can::MessageSpec> messages{m};
  can::SignalDecoder decoder(messages);
  std::vector<double> v(decoder.slot_count());
  const can::Frame f = frame(0x100, {0xA5, 0x3C, 0x25, 0xB5, 0x18, 0xFC, 0x80, 0x00});
  const can::DecodeResult r = decoder.decode(f, v);
  ASSERT_EQ(r.status, can::DecodeStatus::decoded);
  EXPECT_EQ(r.count, 4U);
  EXPECT_DOUBLE_EQ(v[0], 0x3CA);                            // (0x3CA5 >> 4) & 0xFFF
  EXPECT_DOUBLE_EQ(v[1], (0x25B5 * 0.01 - 67.67) / 3.6);    // km/h converted to m/s
  EXPECT_DOUBLE_EQ(v[2], static_cast<std::int16_t>(0xFC18));
  EXPECT_DOUBLE_EQ(v[3], -128);
  EXPECT_EQ(decoder.signals()[1].unit, "m/s");
}

TEST(Decoder, MotorolaSignalAcrossBytesMatchesBitByBitDefinition) {
  // Check the fast path against the DBC definition walked bit by bit: from the
  // MSB at start_bit, go down within a byte, then to bit 7 of the next byte.
  const std::uint8_t bytes[8] = {0x9E, 0x37, 0x79, 0xB9, 0x7F, 0x4A, 0x7C, 0x15};
  for (unsigned start = 0; start < 64; ++start) {
    for (unsigned length = 1; length <= 33; length += 4) {
      unsigned bit = start;
      std::uint64_t expected = 0;
      bool fits = true;
      for (unsigned i = 0; i < length; ++i) {
        if (bit >= 64) {
          fits = false;
          break;
        }
        expected = expected << 1 | ((bytes[bit / 8] >> (bit % 8)) & 1U);
        bit = bit % 8 == 0 ? bit + 15 : bit - 1;
      }
      if (!fits) continue;
      can::MessageSpec m;
      m.id = 1;
      m.signals.push_back(signal("s", start, length, can::ByteOrder::motorola, false));
      const std::vector<can::MessageSpec> messages{m};
      can::SignalDecoder decoder(messages);
      double v = 0;
      can::Frame f = frame(1, {});
      f.length = 8;
      std::memcpy(f.data.data(), bytes, 8);
      ASSERT_EQ(decoder.decode(f, {&v, 1}).status, can::DecodeStatus::decoded);
      EXPECT_EQ(v, static_cast<double>(expected)) << "start " << start << " length " << length;
    }
  }
}

TEST(Decoder, CountsUnknownIdsWrongLengthsAndNonData) {
  const can::Database db = can::parse_dbc("BO_ 170 W: 8 X\n SG_ A : 7|8@0+ (1,0) [0|0] \"\" X\n", "t.dbc");
  can::SignalDecoder decoder(db.messages);
  std::vector<double> v(decoder.slot_count());
  EXPECT_EQ(decoder.decode(frame(0x171, {1, 2, 3, 4, 5, 6, 7, 8}), v).status, can::DecodeStatus::unknown_id);
  EXPECT_EQ(decoder.decode(frame(0xAA, {1, 2, 3, 4, 5, 6, 7, 8}, true), v).status, can::DecodeStatus::unknown_id);
  EXPECT_EQ(decoder.decode(frame(0xAA, {1, 2, 3}), v).status, can::DecodeStatus::wrong_length);
  can::Frame err = frame(0xAA, {0, 0, 0, 0, 0, 0, 0, 0});
  err.error = true;
  EXPECT_EQ(decoder.decode(err, v).status, can::DecodeStatus::not_data);
  EXPECT_EQ(decoder.decode(frame(0xAA, {9, 2, 3, 4, 5, 6, 7, 8}), v).status, can::DecodeStatus::decoded);
  EXPECT_EQ(v[0], 9);
  EXPECT_EQ(decoder.stats().unknown_id, 2U);
  EXPECT_EQ(decoder.stats().wrong_length, 1U);
  EXPECT_EQ(decoder.stats().not_data, 1U);
  EXPECT_EQ(decoder.stats().decoded, 1U);
}

TEST(Decoder, SelectsSignalsByNameAndRejectsUnknownNames) {
  const can::Database db = can::parse_dbc(
      "BO_ 1 M: 2 X\n SG_ A : 0|8@1+ (1,0) [0|0] \"\" X\n SG_ B : 8|8@1+ (1,0) [0|0] \"\" X\n", "t.dbc");
  const std::vector<std::string> wanted{"M.B"};
  can::SignalDecoder decoder(db.messages, wanted);
  ASSERT_EQ(decoder.slot_count(), 1U);
  EXPECT_EQ(decoder.slot("B"), 0);
  double v = 0;
  decoder.decode(frame(1, {3, 4}), {&v, 1});
  EXPECT_EQ(v, 4);
  const std::vector<std::string> bad{"C"};
  EXPECT_THROW(can::SignalDecoder(db.messages, bad), adit::InputError);
}

TEST(Decoder, MultiplexedSignalsOnlyWhenTheSelectorMatches) {
  const can::Database db = can::parse_dbc(
      "BO_ 5 M: 3 X\n SG_ SEL M : 0|8@1+ (1,0) [0|0] \"\" X\n SG_ P m1 : 8|16@1+ (1,0) [0|0] \"\" X\n"
      " SG_ Q m2 : 8|16@1- (1,0) [0|0] \"\" X\n",
      "t.dbc");
  can::SignalDecoder decoder(db.messages);
  std::vector<double> v(3);
  decoder.decode(frame(5, {1, 0x10, 0x00}), v);
  EXPECT_EQ(v[1], 16);
  EXPECT_TRUE(std::isnan(v[2]));
  decoder.decode(frame(5, {2, 0xFF, 0xFF}), v);
  EXPECT_TRUE(std::isnan(v[1]));
  EXPECT_EQ(v[2], -1);
}

TEST(Presets, CanopenTpdoPositionVelocity) {
  const std::vector<can::MessageSpec> messages{can::canopen_tpdo_position_velocity(3, 2, "left_", "rpm")};
  EXPECT_EQ(messages[0].id, 0x283U);
  can::SignalDecoder decoder(messages);
  std::vector<double> v(2);
  // position -2 counts, velocity 60 rpm, little endian
  ASSERT_EQ(decoder.decode(frame(0x283, {0xFE, 0xFF, 0xFF, 0xFF, 60, 0, 0, 0}), v).status, can::DecodeStatus::decoded);
  EXPECT_EQ(v[decoder.slot("left_position")], -2);
  EXPECT_DOUBLE_EQ(v[decoder.slot("left_velocity")], 2 * M_PI);
  EXPECT_THROW(can::canopen_tpdo_position_velocity(0), std::invalid_argument);
}

TEST(Presets, OdriveEncoderEstimates) {
  const std::vector<can::MessageSpec> messages{can::odrive_encoder_estimates(4)};
  EXPECT_EQ(messages[0].id, (4U << 5) | 0x9U);
  can::SignalDecoder decoder(messages);
  can::Frame f = frame(0x89, {0, 0, 0, 0, 0, 0, 0, 0});
  const float pos = 1.5F;
  const float vel = -0.25F;
  std::memcpy(&f.data[0], &pos, 4);  // the test host is little endian, as ODrive
  std::memcpy(&f.data[4], &vel, 4);
  std::vector<double> v(2);
  ASSERT_EQ(decoder.decode(f, v).status, can::DecodeStatus::decoded);
  EXPECT_DOUBLE_EQ(v[0], 1.5 * 2 * M_PI);
  EXPECT_DOUBLE_EQ(v[1], -0.25 * 2 * M_PI);
  EXPECT_EQ(decoder.signals()[1].unit, "rad/s");
}

TEST(Units, ConvertsKnownUnitsAndPassesOthersThrough) {
  EXPECT_DOUBLE_EQ(can::si_conversion("km/h").scale, 1 / 3.6);
  EXPECT_DOUBLE_EQ(can::si_conversion("rpm").scale, M_PI / 30);
  EXPECT_EQ(can::si_conversion("rpm").si_unit, "rad/s");
  EXPECT_FALSE(can::si_conversion("furlong").known);
  EXPECT_EQ(can::si_conversion("furlong").si_unit, "furlong");
}

TEST(InlineSignals, GroupByIdWithAMinimumLength) {
  std::vector<can::MessageSpec> messages;
  can::add_inline_signal(messages, 0x201, false, signal("left", 0, 16, can::ByteOrder::intel, true));
  can::add_inline_signal(messages, 0x201, false, signal("right", 16, 16, can::ByteOrder::intel, true));
  can::add_inline_signal(messages, 0x18FF0001, true, signal("odo", 7, 32, can::ByteOrder::motorola, false));
  ASSERT_EQ(messages.size(), 2U);
  EXPECT_EQ(messages[0].length, 4U);
  EXPECT_FALSE(messages[0].exact_length);
  EXPECT_EQ(messages[1].length, 4U);
  EXPECT_THROW(can::add_inline_signal(messages, 0x800, false, signal("x", 0, 8, can::ByteOrder::intel, false)),
               std::invalid_argument);
  EXPECT_THROW(can::add_inline_signal(messages, 1, false, signal("x", 510, 8, can::ByteOrder::intel, false)),
               std::invalid_argument);
  can::SignalDecoder decoder(messages);
  std::vector<double> v(decoder.slot_count());
  EXPECT_EQ(decoder.decode(frame(0x201, {0xFF, 0xFF, 0x02, 0x00, 0xAA, 0xBB}), v).status, can::DecodeStatus::decoded);
  EXPECT_EQ(v[decoder.slot("left")], -1);
  EXPECT_EQ(v[decoder.slot("right")], 2);
  EXPECT_EQ(decoder.decode(frame(0x201, {0xFF, 0xFF, 0x02}), v).status, can::DecodeStatus::wrong_length);
}
