#include "adit/protocol/ply_header.hpp"

#include <sstream>

#include <fmt/format.h>

#include "adit/common/error.hpp"

namespace adit::protocol {
namespace {

// A header longer than this is not one of ours nor a sane mesh.
constexpr std::size_t kMaxHeader = 64 * 1024;

}  // namespace

std::optional<Scalar> ply_scalar(std::string_view t) {
  if (t == "char" || t == "int8") return Scalar::i8;
  if (t == "uchar" || t == "uint8") return Scalar::u8;
  if (t == "short" || t == "int16") return Scalar::i16;
  if (t == "ushort" || t == "uint16") return Scalar::u16;
  if (t == "int" || t == "int32") return Scalar::i32;
  if (t == "uint" || t == "uint32") return Scalar::u32;
  if (t == "float" || t == "float32") return Scalar::f32;
  if (t == "double" || t == "float64") return Scalar::f64;
  return std::nullopt;
}

std::size_t ply_type_size(std::string_view t) {
  const std::optional<Scalar> s = ply_scalar(t);
  return s ? scalar_size(*s) : 0;
}

double read_ply_scalar(std::string_view t, const char* p) { return read_scalar(ply_scalar(t).value_or(Scalar::f64), p); }

PlyHeader parse_ply_header(std::string_view bytes, const std::string& file) {
  const std::size_t end = bytes.substr(0, kMaxHeader).find("end_header\n");
  if (bytes.substr(0, 4) != "ply\n" || end == std::string_view::npos)
    throw InputError(file, "", "not a PLY file (no 'ply' line or no 'end_header' in the first 64 KiB)");
  PlyHeader header;
  header.data_offset = end + std::string_view("end_header\n").size();
  std::istringstream lines{std::string(bytes.substr(0, end))};
  std::string line;
  int number = 0;
  bool format_seen = false;
  while (std::getline(lines, line)) {
    ++number;
    const auto bad = [&](const std::string& why) {
      return InputError(fmt::format("{}:{}", file, number), "", fmt::format("'{}': {}", line, why));
    };
    std::istringstream words(line);
    std::string word;
    words >> word;
    if (number == 1 || word == "comment" || word == "obj_info" || word.empty()) continue;
    if (word == "format") {
      std::string kind, version;
      words >> kind >> version;
      if (kind != "binary_little_endian" || version != "1.0")
        throw bad("only 'format binary_little_endian 1.0' is read");
      format_seen = true;
    } else if (word == "element") {
      PlyElement e;
      if (!(words >> e.name >> e.count)) throw bad("expected 'element NAME COUNT'");
      header.elements.push_back(std::move(e));
    } else if (word == "property") {
      if (header.elements.empty()) throw bad("property before any element");
      PlyProperty p;
      words >> p.type;
      if (p.type == "list") words >> p.count_type >> p.type;
      words >> p.name;
      if (p.name.empty() || ply_type_size(p.type) == 0 || (!p.count_type.empty() && ply_type_size(p.count_type) == 0))
        throw bad("expected 'property TYPE NAME' or 'property list COUNT_TYPE TYPE NAME' with PLY types");
      header.elements.back().properties.push_back(std::move(p));
    } else {
      throw bad("unknown header keyword");
    }
  }
  if (!format_seen) throw InputError(file, "format", "the header has no 'format' line");
  return header;
}

}  // namespace adit::protocol
