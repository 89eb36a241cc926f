#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "adit/common/error.hpp"
#include "adit/drivers/can/candump.hpp"

namespace can = adit::drivers::can;

namespace {

can::Frame parse_ok(std::string_view line) {
  can::Frame f;
  EXPECT_EQ(can::parse_candump_line(line, f), can::LineError::none) << line;
  return f;
}

std::filesystem::path temp_file(const std::string& name) {
  return std::filesystem::temp_directory_path() / (name + "-" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()));
}

}  // namespace

TEST(Candump, ParsesClassicStandardFrame) {
  const can::Frame f = parse_ok("(46408.584930) can0 0AA#25B525B525A0258D");
  EXPECT_EQ(f.time_us, 46408584930);
  EXPECT_EQ(f.interface_name(), "can0");
  EXPECT_EQ(f.id, 0xAAU);
  EXPECT_FALSE(f.extended);
  ASSERT_EQ(f.length, 8);
  EXPECT_EQ(f.data[0], 0x25);
  EXPECT_EQ(f.data[7], 0x8D);
}

TEST(Candump, ParsesExtendedRemoteFdErrorAndLen8Dlc) {
  const can::Frame ext = parse_ok("(1.000001) vcan0 1ABCDEF0#0102");
  EXPECT_TRUE(ext.extended);
  EXPECT_EQ(ext.id, 0x1ABCDEF0U);
  EXPECT_EQ(ext.length, 2);

  const can::Frame rtr = parse_ok("(1.5) can1 123#R4");
  EXPECT_TRUE(rtr.remote);
  EXPECT_EQ(rtr.length, 4);
  EXPECT_EQ(rtr.time_us, 1'500'000);

  const can::Frame fd = parse_ok("(2.000000) can0 123##3" + std::string(24, 'A'));
  EXPECT_TRUE(fd.fd);
  EXPECT_EQ(fd.fd_flags, can::kFdBitRateSwitch | can::kFdErrorStateIndicator);
  EXPECT_EQ(fd.length, 12);

  const can::Frame err = parse_ok("(3.000000) can0 20000040#0000000000000000");
  EXPECT_TRUE(err.error);
  EXPECT_FALSE(err.extended);
  EXPECT_EQ(err.id, 0x40U);  // CAN_ERR_BUSOFF

  const can::Frame dlc = parse_ok("(4.000000) can0 123#1122334455667788_C");
  EXPECT_EQ(dlc.len8_dlc, 12);

  const can::Frame dotted = parse_ok("(5.000000) can0 123#11.22.33");
  EXPECT_EQ(dotted.length, 3);
  EXPECT_EQ(dotted.data[2], 0x33);
}

TEST(Candump, RejectsMalformedLinesWithAReason) {
  can::Frame f;
  EXPECT_EQ(can::parse_candump_line("46408.584930 can0 0AA#00", f), can::LineError::timestamp);
  EXPECT_EQ(can::parse_candump_line("(46408.) can0 0AA#00", f), can::LineError::timestamp);
  EXPECT_EQ(can::parse_candump_line("(1.0)", f), can::LineError::interface);
  EXPECT_EQ(can::parse_candump_line("(1.0) averyveryverylongname 0AA#00", f), can::LineError::interface);
  EXPECT_EQ(can::parse_candump_line(std::string_view("(1.0) c\0n 0AA#00", 16), f), can::LineError::interface);
  EXPECT_EQ(can::parse_candump_line("(1.0) can0 0A#00", f), can::LineError::identifier);
  EXPECT_EQ(can::parse_candump_line("(1.0) can0 800#00", f), can::LineError::identifier);
  EXPECT_EQ(can::parse_candump_line("(1.0) can0 0AG#00", f), can::LineError::identifier);
  EXPECT_EQ(can::parse_candump_line("(1.0) can0 0AA", f), can::LineError::separator);
  EXPECT_EQ(can::parse_candump_line("(1.0) can0 0AA#123", f), can::LineError::data);
  EXPECT_EQ(can::parse_candump_line("(1.0) can0 0AA#zz", f), can::LineError::data);
  EXPECT_EQ(can::parse_candump_line("(1.0) can0 0AA#001122334455667788", f), can::LineError::length);
  EXPECT_EQ(can::parse_candump_line("(1.0) can0 0AA##0" + std::string(18, '0'), f), can::LineError::length);
  EXPECT_EQ(can::parse_candump_line("(1.0) can0 20000040#00", f), can::LineError::length);
  EXPECT_EQ(can::parse_candump_line("(1.0) can0 0AA#00 junk", f), can::LineError::trailing);
}

TEST(Candump, FormatThenParseIsIdentityForEveryKind) {
  std::vector<can::Frame> frames;
  for (const char* line : {"(46408.584930) can0 0AA#25B525B525A0258D", "(0.000001) can1 1FFFFFFF#", "(7.250000) can0 7FF#R",
                           "(7.250001) can0 123#R8", "(9.000000) can129 456##1DEADBEEF", "(9.000001) can0 20000004#0004000000000000",
                           "(10.000000) can0 123#1122334455667788_F",
                           "(10.500000) can0 7FF#R8_F"}) {  // remote with a raw DLC: found by fuzz_candump
    const can::Frame f = parse_ok(line);
    EXPECT_EQ(can::to_candump_line(f), line);  // canonical text survives read + write
    can::Frame back;
    ASSERT_EQ(can::parse_candump_line(can::to_candump_line(f), back), can::LineError::none);
    EXPECT_EQ(back, f);
  }
  can::Frame fd64;
  fd64.fd = true;
  fd64.length = 64;
  fd64.set_interface_name("can2");
  for (std::size_t i = 0; i < 64; ++i) fd64.data[i] = static_cast<std::uint8_t>(i * 7);
  can::Frame back;
  ASSERT_EQ(can::parse_candump_line(can::to_candump_line(fd64), back), can::LineError::none);
  EXPECT_EQ(back, fd64);
}

TEST(Candump, WriterAndReaderRoundTripAndReportLineNumbers) {
  const auto path = temp_file("adit-candump-test.log");
  std::vector<can::Frame> written;
  {
    can::CandumpWriter writer(path);
    for (int i = 0; i < 100; ++i) {
      can::Frame f;
      f.time_us = 1'700'000'000'000'000 + i * 1234;
      f.id = static_cast<std::uint32_t>(i * 97) & 0x7FF;
      f.extended = i % 5 == 0;
      if (f.extended) f.id |= 0x1000000;
      f.fd = i % 7 == 0;
      f.length = static_cast<std::uint8_t>(f.fd ? 16 : i % 9);
      for (std::size_t b = 0; b < f.length; ++b) f.data[b] = static_cast<std::uint8_t>(i + b);
      f.set_interface_name(i % 2 ? "can0" : "can1");
      writer.write(f);
      written.push_back(f);
    }
  }
  {
    std::ofstream append(path, std::ios::app);
    append << "\n(1.0) can0 0AA#1\n(2.0) can0 0AA#11\n";  // lines 101 (blank), 102 (bad), 103 (good)
  }
  can::CandumpReader reader(path);
  std::vector<can::Frame> read;
  can::Frame f;
  while (reader.next(f)) read.push_back(f);
  ASSERT_EQ(read.size(), 101U);
  for (std::size_t i = 0; i < written.size(); ++i) EXPECT_EQ(read[i], written[i]) << i;
  EXPECT_EQ(reader.stats().malformed, 1U);
  EXPECT_EQ(reader.stats().blank, 1U);
  ASSERT_EQ(reader.errors().size(), 1U);
  EXPECT_EQ(reader.errors()[0].line, 102U);
  EXPECT_NE(reader.describe(reader.errors()[0]).find(":102: "), std::string::npos);
  std::filesystem::remove(path);
}

TEST(Candump, MissingFileIsAnInputErrorNamingIt) {
  try {
    can::CandumpReader reader("/nonexistent/drive.log");
    FAIL() << "no error";
  } catch (const adit::InputError& e) {
    EXPECT_EQ(e.where(), "/nonexistent/drive.log");
  }
}
