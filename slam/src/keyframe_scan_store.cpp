// The loop closer's keyframes, in RAM and on disk (keyframe_scan_store.hpp).
#include "adit/slam/keyframe_scan_store.hpp"

#include <array>
#include <fstream>

#include <fmt/format.h>

namespace adit::slam {
namespace {

constexpr std::array<char, 8> kTag{'A', 'D', 'I', 'T', 'K', 'F', 'S', '2'};
// The points go to the file as they lie in memory: three floats each, no padding.
static_assert(sizeof(Eigen::Vector3f) == 3 * sizeof(float));
constexpr std::uint64_t kMaxPoints = std::uint64_t{1} << 26;  // far above any keyframe: a count beyond is damage
constexpr std::size_t kHeaderBytes = kTag.size() + sizeof(std::uint64_t) + 2 * sizeof(std::uint32_t);

// FNV-1a, 64 bit (Fowler, Noll, Vo), continued from `h`: enough to tell a
// damaged file, not a cryptographic check.
std::uint64_t fnv1a(const void* data, std::size_t size, std::uint64_t h = 0xcbf29ce484222325ULL) {
  const auto* bytes = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < size; ++i) {
    h ^= bytes[i];
    h *= 0x100000001b3ULL;
  }
  return h;
}

std::size_t bytes_of(const std::vector<Eigen::Vector3f>& points, const Eigen::MatrixXf& descriptor) {
  return points.capacity() * sizeof(Eigen::Vector3f) + static_cast<std::size_t>(descriptor.size()) * sizeof(float);
}

}  // namespace

std::filesystem::path KeyframeScanStore::file_of(std::size_t k) const {
  return folder_ / fmt::format("{:06}.kfs", k);
}

void KeyframeScanStore::add(std::vector<Eigen::Vector3f> points, Eigen::MatrixXf descriptor) {
  points.shrink_to_fit();  // a downsampled scan keeps its input's capacity otherwise (1.5× on the mine drives)
  bytes_in_ram_ += bytes_of(points, descriptor);
  keyframes_.push_back({std::move(points), std::move(descriptor), false});
  if (folder_.empty()) return;
  while (next_to_spill_ + in_ram_ < keyframes_.size()) spill(next_to_spill_++);
}

void KeyframeScanStore::spill(std::size_t k) {
  Slot& slot = keyframes_[k];
  std::error_code ec;
  std::filesystem::create_directories(folder_, ec);
  const std::filesystem::path file = file_of(k);
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  const std::uint64_t n = slot.points.size();
  const auto rows = static_cast<std::uint32_t>(slot.descriptor.rows());
  const auto cols = static_cast<std::uint32_t>(slot.descriptor.cols());
  const std::size_t bins = static_cast<std::size_t>(slot.descriptor.size()) * sizeof(float);
  const std::size_t payload = n * sizeof(Eigen::Vector3f);
  const std::uint64_t hash = fnv1a(slot.points.data(), payload, fnv1a(slot.descriptor.data(), bins));
  out.write(kTag.data(), kTag.size());
  out.write(reinterpret_cast<const char*>(&n), sizeof n);
  out.write(reinterpret_cast<const char*>(&rows), sizeof rows);
  out.write(reinterpret_cast<const char*>(&cols), sizeof cols);
  out.write(reinterpret_cast<const char*>(slot.descriptor.data()), static_cast<std::streamsize>(bins));
  out.write(reinterpret_cast<const char*>(slot.points.data()), static_cast<std::streamsize>(payload));
  out.write(reinterpret_cast<const char*>(&hash), sizeof hash);
  out.close();
  if (!out) {
    ++write_errors_;
    last_error_ = fmt::format("{}: cannot write the keyframe (kept in RAM)", file.string());
    return;
  }
  bytes_in_ram_ -= bytes_of(slot.points, slot.descriptor);
  std::vector<Eigen::Vector3f>().swap(slot.points);
  slot.descriptor = Eigen::MatrixXf();
  slot.on_disk = true;
  ++spilled_;
}

bool KeyframeScanStore::read(std::size_t k, std::vector<Eigen::Vector3f>& out) {
  if (k < keyframes_.size() && !keyframes_[k].on_disk) {
    out = keyframes_[k].points;
    return true;
  }
  return read_file(k, out, scratch_descriptor_);
}

bool KeyframeScanStore::read_descriptor(std::size_t k, Eigen::MatrixXf& out) {
  if (k < keyframes_.size() && !keyframes_[k].on_disk) {
    out = keyframes_[k].descriptor;
    return true;
  }
  return read_file(k, scratch_points_, out);
}

bool KeyframeScanStore::read_file(std::size_t k, std::vector<Eigen::Vector3f>& points, Eigen::MatrixXf& descriptor) {
  points.clear();
  descriptor.resize(0, 0);
  if (k >= keyframes_.size()) {
    ++read_errors_;
    last_error_ = fmt::format("keyframe {} is not stored", k);
    return false;
  }
  const std::filesystem::path file = file_of(k);
  const auto fail = [&](std::string_view why) {
    ++read_errors_;
    last_error_ = fmt::format("{}: {}", file.string(), why);
    points.clear();
    descriptor.resize(0, 0);
    return false;
  };
  std::ifstream in(file, std::ios::binary);
  if (!in) return fail("cannot open the keyframe's file");
  std::array<char, 8> tag{};
  std::uint64_t n = 0;
  std::uint32_t rows = 0, cols = 0;
  if (!in.read(tag.data(), tag.size()) || tag != kTag) return fail("not a keyframe file (tag)");
  if (!in.read(reinterpret_cast<char*>(&n), sizeof n) || n > kMaxPoints) return fail("damaged (point count)");
  if (!in.read(reinterpret_cast<char*>(&rows), sizeof rows) || !in.read(reinterpret_cast<char*>(&cols), sizeof cols) ||
      std::uint64_t{rows} * cols > kMaxPoints)
    return fail("damaged (descriptor size)");
  // The file's size must be what its header says before anything is
  // allocated for it: a damaged count must not cost the payload its RAM.
  const std::size_t bins = std::size_t{rows} * cols * sizeof(float);
  const std::size_t payload = n * sizeof(Eigen::Vector3f);
  const std::size_t expected = kHeaderBytes + bins + payload + sizeof(std::uint64_t);
  std::error_code error;
  const std::uintmax_t size = std::filesystem::file_size(file, error);
  if (error) return fail("cannot size the keyframe's file");
  if (size < expected) return fail("damaged (short)");
  if (size > expected) return fail("damaged (longer than its header says)");
  descriptor.resize(rows, cols);
  points.resize(n);
  std::uint64_t hash = 0;
  if (!in.read(reinterpret_cast<char*>(descriptor.data()), static_cast<std::streamsize>(bins)) ||
      !in.read(reinterpret_cast<char*>(points.data()), static_cast<std::streamsize>(payload)) ||
      !in.read(reinterpret_cast<char*>(&hash), sizeof hash))
    return fail("damaged (short)");
  if (hash != fnv1a(points.data(), payload, fnv1a(descriptor.data(), bins))) return fail("damaged (hash)");
  return true;
}

}  // namespace adit::slam
