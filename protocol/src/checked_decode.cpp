#include "adit/protocol/checked_decode.hpp"

#include <array>
#include <vector>

namespace adit::protocol {
namespace {

enum class Kind { i8, i16, i32, i64, f32, f64, string, nested };

struct Field {
  Kind kind;
  int fixed = 1;     // a fixed-size array (e.g. double position[3])
  int count_of = -1; // or: index of the int32 field of this struct holding the count
  const std::vector<Field>* nested = nullptr;
};

std::size_t width(Kind kind) {
  switch (kind) {
    case Kind::i8: return 1;
    case Kind::i16: return 2;
    case Kind::i32: case Kind::f32: return 4;
    case Kind::i64: case Kind::f64: return 8;
    case Kind::string: return 5;  // length + NUL at least
    case Kind::nested: return 1;
  }
  return 1;
}

// Booleans and bytes are one byte like int8 for the layout.
const Field I8{Kind::i8}, I16{Kind::i16}, I32{Kind::i32}, I64{Kind::i64}, F32{Kind::f32},
    STR{Kind::string};
Field counted(Kind kind, int count_field) { return Field{kind, 1, count_field}; }

// Walks `fields` from `pos`; false when the bytes do not fit the layout.
class Walker {
 public:
  explicit Walker(std::span<const std::uint8_t> bytes) : bytes_(bytes) {}

  bool walk(const std::vector<Field>& fields) {
    std::vector<std::int64_t> values(fields.size(), 0);
    for (std::size_t f = 0; f < fields.size(); ++f) {
      const Field& field = fields[f];
      std::int64_t count = field.fixed;
      if (field.count_of >= 0) count = values[static_cast<std::size_t>(field.count_of)];
      // Every element takes at least width() bytes: a count beyond what is
      // left is a lie, whatever the element type.
      if (count < 0 || static_cast<std::size_t>(count) > remaining() / width(field.kind)) return false;
      for (std::int64_t i = 0; i < count; ++i) {
        if (field.kind == Kind::nested) {
          if (!walk(*field.nested)) return false;
        } else if (field.kind == Kind::string) {
          std::int64_t length = 0;
          if (!read(4, length) || length < 1 || static_cast<std::size_t>(length) > remaining()) return false;
          if (bytes_[pos_ + static_cast<std::size_t>(length) - 1] != 0) return false;
          pos_ += static_cast<std::size_t>(length);
        } else {
          std::int64_t value = 0;
          if (!read(width(field.kind), value)) return false;
          if (count == 1) values[f] = value;
        }
      }
    }
    return true;
  }
  bool at_end() const { return pos_ == bytes_.size(); }
  bool skip(std::size_t n) {
    if (remaining() < n) return false;
    pos_ += n;
    return true;
  }

 private:
  std::size_t remaining() const { return bytes_.size() - pos_; }
  // LCM is big-endian; only int32 values are used (as counts).
  bool read(std::size_t n, std::int64_t& value) {
    if (remaining() < n) return false;
    if (n == 4) {
      const std::uint32_t u = (std::uint32_t{bytes_[pos_]} << 24) | (std::uint32_t{bytes_[pos_ + 1]} << 16) |
                              (std::uint32_t{bytes_[pos_ + 2]} << 8) | std::uint32_t{bytes_[pos_ + 3]};
      value = static_cast<std::int32_t>(u);
    }
    pos_ += n;
    return true;
  }

  std::span<const std::uint8_t> bytes_;
  std::size_t pos_ = 0;
};

const std::vector<Field> kSensorHealth{STR, F32, I64, I64, F32};
const std::vector<Field> kThreadLoad{STR, F32, I32, I32};
const std::vector<Field> kXyz{{Kind::f32, 3}};

const std::vector<Field>& layout(LcmType type) {
  static const std::vector<Field> pose{I64, I16, STR, I64, {Kind::f64, 3}, {Kind::f64, 4}, {Kind::f64, 36}, I32};
  static const std::vector<Field> status{I64, I16, STR, I8, STR, I32, {Kind::nested, 1, 5, &kSensorHealth},
                                         I32, {Kind::nested, 1, 7, &kThreadLoad}, I64, I64, I32, STR};
  static const std::vector<Field> command{I64, I16, I64, STR, STR, I32, counted(Kind::string, 5),
                                          I32, counted(Kind::i8, 7)};
  static const std::vector<Field> ack{I64, I16, I64, STR, I8, STR, I8, STR, STR};
  static const std::vector<Field> index{I64, I16, STR, STR, I64, STR, F32, I8, I32, I32, I32,
                                        counted(Kind::i64, 10), counted(Kind::i32, 10), counted(Kind::i32, 10),
                                        counted(Kind::i32, 10), I64, {Kind::f32, 3}, {Kind::f32, 3}};
  static const std::vector<Field> segment{I64, I16, STR, STR, I64, I32, I32, I32, I32, I32, I32, F32, F32, I32,
                                          counted(Kind::i8, 13)};
  static const std::vector<Field> request{I64, I16, I64, STR, STR, I8, I32,
                                          counted(Kind::i64, 6), counted(Kind::i32, 6), counted(Kind::i32, 6)};
  static const std::vector<Field> file_request{I64, I16, I64, STR, STR, STR, I32, I32};
  static const std::vector<Field> file_chunk{I64, I16, I64, STR, STR, STR, STR, I64, I32, I32, I32, counted(Kind::i8, 10)};
  static const std::vector<Field> grid_patch{I64, I16, STR, STR, F32, I32, I32, I32, I32, I32, I32,
                                             counted(Kind::i8, 10)};
  static const std::vector<Field> frame{I64,           I16,           STR,           STR,          I8,
                                        {Kind::f64, 3}, {Kind::f64, 4}, {Kind::f64, 3}, {Kind::f64, 4}};
  static const std::vector<Field> graph_path{I64, I16, STR, STR, I32, I32, I32, {Kind::nested, 1, 6, &kXyz}};
  static const std::vector<Field> loop_status{I64, I16, STR, STR, I32, I32, I32, I32, I64, F32, F32, I8};
  switch (type) {
    case LcmType::pose: return pose;
    case LcmType::status: return status;
    case LcmType::command: return command;
    case LcmType::command_ack: return ack;
    case LcmType::tile_index: return index;
    case LcmType::tile_segment: return segment;
    case LcmType::tile_request: return request;
    case LcmType::file_request: return file_request;
    case LcmType::file_chunk: return file_chunk;
    case LcmType::grid_patch: return grid_patch;
    case LcmType::frame: return frame;
    case LcmType::graph_path: return graph_path;
    case LcmType::loop_status: return loop_status;
  }
  return pose;
}

}  // namespace

bool lcm_layout_ok(LcmType type, std::span<const std::uint8_t> bytes) {
  Walker walker(bytes);
  return walker.skip(8) && walker.walk(layout(type)) && walker.at_end();  // 8: the type's hash
}

}  // namespace adit::protocol
