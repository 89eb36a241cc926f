#pragma once
// A small PCD (v0.7) reader for tests: ascii and binary data, any scalar
// field types, COUNT 1. Every field comes back as a column of doubles.
// Throws std::runtime_error naming the file on anything it does not handle.

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace adit::test {

struct PcdCloud {
  std::vector<std::string> fields;
  std::map<std::string, std::vector<double>> columns;
  std::size_t size() const { return columns.empty() ? 0 : columns.begin()->second.size(); }
  const std::vector<double>& at(const std::string& field) const { return columns.at(field); }
};

inline PcdCloud read_pcd(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw std::runtime_error(file.string() + ": cannot open");
  PcdCloud cloud;
  std::vector<int> sizes;
  std::vector<char> types;
  std::size_t points = 0;
  std::string data;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream words(line);
    std::string key;
    words >> key;
    if (key == "FIELDS") {
      for (std::string f; words >> f;) cloud.fields.push_back(f);
    } else if (key == "SIZE") {
      for (int s = 0; words >> s;) sizes.push_back(s);
    } else if (key == "TYPE") {
      for (char t = 0; words >> t;) types.push_back(t);
    } else if (key == "COUNT") {
      for (int c = 0; words >> c;) {
        if (c != 1) throw std::runtime_error(file.string() + ": COUNT other than 1");
      }
    } else if (key == "POINTS") {
      words >> points;
    } else if (key == "DATA") {
      words >> data;
      break;
    }
  }
  if (sizes.size() != cloud.fields.size() || types.size() != cloud.fields.size()) {
    throw std::runtime_error(file.string() + ": FIELDS, SIZE and TYPE disagree");
  }
  for (const auto& f : cloud.fields) cloud.columns[f].reserve(points);
  if (data == "ascii") {
    for (std::size_t i = 0; i < points; ++i) {
      for (const auto& f : cloud.fields) {
        double v = 0;
        if (!(in >> v)) throw std::runtime_error(file.string() + ": short ascii data");
        cloud.columns[f].push_back(v);
      }
    }
  } else if (data == "binary") {
    std::size_t stride = 0;
    for (int s : sizes) stride += static_cast<std::size_t>(s);
    std::vector<char> buf(stride * points);
    if (!in.read(buf.data(), static_cast<std::streamsize>(buf.size()))) {
      throw std::runtime_error(file.string() + ": short binary data");
    }
    for (std::size_t i = 0; i < points; ++i) {
      const char* p = buf.data() + i * stride;
      for (std::size_t k = 0; k < cloud.fields.size(); ++k) {
        double v = 0;
        const char t = types[k];
        const int s = sizes[k];
        if (t == 'F' && s == 4) { float x; std::memcpy(&x, p, 4); v = x; }
        else if (t == 'F' && s == 8) { std::memcpy(&v, p, 8); }
        else if (t == 'U' && s == 1) { v = static_cast<std::uint8_t>(*p); }
        else if (t == 'U' && s == 2) { std::uint16_t x; std::memcpy(&x, p, 2); v = x; }
        else if (t == 'U' && s == 4) { std::uint32_t x; std::memcpy(&x, p, 4); v = x; }
        else if (t == 'I' && s == 1) { v = static_cast<std::int8_t>(*p); }
        else if (t == 'I' && s == 2) { std::int16_t x; std::memcpy(&x, p, 2); v = x; }
        else if (t == 'I' && s == 4) { std::int32_t x; std::memcpy(&x, p, 4); v = x; }
        else throw std::runtime_error(file.string() + ": unsupported field type");
        cloud.columns[cloud.fields[k]].push_back(v);
        p += s;
      }
    }
  } else {
    throw std::runtime_error(file.string() + ": DATA " + data + " not supported");
  }
  return cloud;
}

}  // namespace adit::test
