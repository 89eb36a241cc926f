#pragma once
// Readers written in the tests, independently of the exporters, for the map
// files `adit download` writes: binary little-endian PLY with float x y z
// intensity, and LAS 1.4 (the header fields of ASPRS LAS 1.4 R15 Table 3 and
// point data record format 6, Table 13). PCD is read with drivers' read_pcd.

#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

namespace adit::test {

struct XyzI {
  double x, y, z;
  float intensity;
  double gps_time = 0;
};

inline std::string slurp(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

template <typename T>
T at(const std::string& bytes, std::size_t offset) {
  T v{};
  if (offset + sizeof(T) <= bytes.size()) std::memcpy(&v, bytes.data() + offset, sizeof(T));
  return v;
}

// Returns the points, or fails the calling test (ADD_FAILURE) and returns none.
inline std::vector<XyzI> read_ply(const std::filesystem::path& file) {
  const std::string bytes = slurp(file);
  const std::size_t end = bytes.find("end_header\n");
  if (end == std::string::npos) {
    ADD_FAILURE() << file << ": no end_header";
    return {};
  }
  std::istringstream header(bytes.substr(0, end));
  std::string line;
  std::vector<std::string> lines;
  while (std::getline(header, line)) lines.push_back(line);
  const std::vector<std::string> expected_props{"property float x", "property float y", "property float z",
                                                "property float intensity"};
  std::size_t n = 0;
  std::vector<std::string> props;
  EXPECT_EQ(lines.at(0), "ply");
  EXPECT_EQ(lines.at(1), "format binary_little_endian 1.0");
  for (const auto& l : lines) {
    if (l.rfind("element vertex ", 0) == 0) n = std::stoul(l.substr(15));
    if (l.rfind("property ", 0) == 0) props.push_back(l);
  }
  EXPECT_EQ(props, expected_props);
  const std::size_t body = end + 11;
  if (bytes.size() != body + n * 16) {
    ADD_FAILURE() << file << ": " << bytes.size() - body << " bytes of data for " << n << " vertices";
    return {};
  }
  std::vector<XyzI> points(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t o = body + i * 16;
    points[i] = {at<float>(bytes, o), at<float>(bytes, o + 4), at<float>(bytes, o + 8), at<float>(bytes, o + 12)};
  }
  return points;
}

// Checks every field of the LAS 1.4 public header block for a file of format
// 6 written without VLRs, and returns the points (scaled and offset).
inline std::vector<XyzI> read_las_checked(const std::filesystem::path& file) {
  const std::string b = slurp(file);
  if (b.size() < 375) {
    ADD_FAILURE() << file << ": shorter than a LAS 1.4 header";
    return {};
  }
  EXPECT_EQ(b.substr(0, 4), "LASF");                       // file signature
  EXPECT_EQ(at<std::uint16_t>(b, 4), 0);                    // file source id
  const auto encoding = at<std::uint16_t>(b, 6);            // global encoding
  EXPECT_EQ(encoding & 0x1, 1) << "GPS time is adjusted standard GPS time";
  EXPECT_EQ(encoding & 0x10, 0x10) << "WKT bit must be set for point formats 6-10";
  EXPECT_EQ(encoding & ~0x1f, 0) << "reserved bits must be zero";
  EXPECT_EQ(b.substr(8, 16), std::string(16, '\0'));        // project GUID
  EXPECT_EQ(at<std::uint8_t>(b, 24), 1);                    // version major
  EXPECT_EQ(at<std::uint8_t>(b, 25), 4);                    // version minor
  EXPECT_NE(b[26], '\0');                                   // system identifier
  EXPECT_NE(b[58], '\0');                                   // generating software
  const auto day = at<std::uint16_t>(b, 90);
  const auto year = at<std::uint16_t>(b, 92);
  EXPECT_TRUE(day >= 1 && day <= 366) << day;
  EXPECT_GE(year, 2024);
  EXPECT_EQ(at<std::uint16_t>(b, 94), 375);                 // header size
  const auto offset_to_points = at<std::uint32_t>(b, 96);
  EXPECT_EQ(offset_to_points, 375u);
  EXPECT_EQ(at<std::uint32_t>(b, 100), 0u);                 // number of VLRs
  EXPECT_EQ(at<std::uint8_t>(b, 104), 6);                   // point data record format
  const auto record = at<std::uint16_t>(b, 105);
  EXPECT_EQ(record, 30);                                    // format 6 length
  EXPECT_EQ(at<std::uint32_t>(b, 107), 0u);                 // legacy count: 0 for format 6
  for (int i = 0; i < 5; ++i) EXPECT_EQ(at<std::uint32_t>(b, 111 + 4 * i), 0u);
  const double scale[3] = {at<double>(b, 131), at<double>(b, 139), at<double>(b, 147)};
  const double offset[3] = {at<double>(b, 155), at<double>(b, 163), at<double>(b, 171)};
  const double max[3] = {at<double>(b, 179), at<double>(b, 195), at<double>(b, 211)};
  const double min[3] = {at<double>(b, 187), at<double>(b, 203), at<double>(b, 219)};
  for (double s : scale) EXPECT_GT(s, 0.0);
  EXPECT_EQ(at<std::uint64_t>(b, 227), 0u);  // waveform data start
  EXPECT_EQ(at<std::uint64_t>(b, 235), 0u);  // first EVLR start
  EXPECT_EQ(at<std::uint32_t>(b, 243), 0u);  // number of EVLRs
  const auto n = at<std::uint64_t>(b, 247);
  EXPECT_EQ(at<std::uint64_t>(b, 255), n);   // all returns are first returns
  for (int i = 1; i < 15; ++i) EXPECT_EQ(at<std::uint64_t>(b, 255 + 8 * i), 0u);
  if (b.size() != offset_to_points + n * record) {
    ADD_FAILURE() << file << ": " << b.size() << " bytes, expected " << offset_to_points + n * record;
    return {};
  }
  std::vector<XyzI> points(n);
  double lo[3] = {1e300, 1e300, 1e300};
  double hi[3] = {-1e300, -1e300, -1e300};
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t o = offset_to_points + i * record;
    double v[3];
    for (int a = 0; a < 3; ++a) {
      v[a] = at<std::int32_t>(b, o + 4 * a) * scale[a] + offset[a];
      lo[a] = std::min(lo[a], v[a]);
      hi[a] = std::max(hi[a], v[a]);
    }
    EXPECT_EQ(at<std::uint8_t>(b, o + 14), 0x11) << "return 1 of 1";
    points[i] = {v[0], v[1], v[2], static_cast<float>(at<std::uint16_t>(b, o + 12)), at<double>(b, o + 22)};
  }
  if (n > 0) {
    for (int a = 0; a < 3; ++a) {
      EXPECT_NEAR(min[a], lo[a], scale[a]) << "min of axis " << a;
      EXPECT_NEAR(max[a], hi[a], scale[a]) << "max of axis " << a;
    }
  }
  return points;
}

}  // namespace adit::test
