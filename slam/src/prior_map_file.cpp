#include "adit/slam/prior_map_file.hpp"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>
#include <string_view>

#include "adit/common/error.hpp"

namespace adit::slam {
namespace {

constexpr std::string_view kMagic = "ADIT-PRIOR-MAP 1\n";

template <typename T>
void put(std::ofstream& out, const T& value) {
  out.write(reinterpret_cast<const char*>(&value), sizeof(T));
}

template <typename T>
void put_all(std::ofstream& out, const std::vector<T>& values) {
  put(out, static_cast<std::uint64_t>(values.size()));
  out.write(reinterpret_cast<const char*>(values.data()), static_cast<std::streamsize>(values.size() * sizeof(T)));
}

class Reader {
 public:
  Reader(std::string bytes, std::string name) : bytes_(std::move(bytes)), name_(std::move(name)) {}
  template <typename T>
  T get(const char* what) {
    T value{};
    need(sizeof(T), what);
    std::memcpy(static_cast<void*>(&value), bytes_.data() + at_, sizeof(T));
    at_ += sizeof(T);
    return value;
  }
  template <typename T>
  std::vector<T> get_all(const char* what, std::uint64_t expected = ~std::uint64_t{0}) {
    const auto n = get<std::uint64_t>(what);
    if (expected != ~std::uint64_t{0} && n != expected)
      throw InputError(name_, what, "holds " + std::to_string(n) + " values where " + std::to_string(expected) + " belong");
    if (n > (bytes_.size() - at_) / sizeof(T)) need(bytes_.size() + 1, what);
    std::vector<T> values(n);
    std::memcpy(static_cast<void*>(values.data()), bytes_.data() + at_, n * sizeof(T));
    at_ += n * sizeof(T);
    return values;
  }
  void need(std::size_t n, const char* what) const {
    if (n > bytes_.size() - at_) throw InputError(name_, what, "truncated file (at byte " + std::to_string(at_) + ")");
  }
  bool done() const { return at_ == bytes_.size(); }
  std::size_t at() const { return at_; }
  const std::string& bytes() const { return bytes_; }
  void skip(std::size_t n) { at_ += n; }

 private:
  std::string bytes_;
  std::string name_;
  std::size_t at_ = 0;
};

}  // namespace

void write_prior_map(const std::filesystem::path& dir, const PriorMap& prior) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  const std::filesystem::path file = dir / kPriorMapFile;
  std::ofstream out(file, std::ios::binary);
  if (!out) throw InputError(file.string(), "", "cannot be written");
  out.write(kMagic.data(), static_cast<std::streamsize>(kMagic.size()));
  put(out, prior.point_spacing_m);
  put_all(out, prior.points);
  put_all(out, prior.normals);
  put(out, prior.plan.origin);
  put(out, prior.plan.cell_m);
  put(out, static_cast<std::int32_t>(prior.plan.width));
  put(out, static_cast<std::int32_t>(prior.plan.height));
  put_all(out, prior.plan.likelihood);
  put_all(out, prior.plan.floor_z);
  put_all(out, prior.plan.wall_distance);
  put(out, static_cast<std::uint64_t>(prior.vertical_points));
  put(out, static_cast<std::uint64_t>(prior.horizontal_points));
  if (!out.flush()) throw InputError(file.string(), "", "write failed (disk full?)");
}

PriorMap read_prior_map(const std::filesystem::path& path) {
  const std::filesystem::path file = std::filesystem::is_directory(path) ? path / kPriorMapFile : path;
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file.string(), "", "cannot be read (prepare it with `adit prior-map prepare`)");
  Reader r(std::string(std::istreambuf_iterator<char>(in), {}), file.string());
  r.need(kMagic.size(), "magic");
  if (r.bytes().compare(0, kMagic.size(), kMagic) != 0)
    throw InputError(file.string(), "magic", "not a prepared prior map (prepare it with `adit prior-map prepare`)");
  r.skip(kMagic.size());
  PriorMap prior;
  prior.point_spacing_m = r.get<float>("point_spacing_m");
  if (!(prior.point_spacing_m > 0.0F)) throw InputError(file.string(), "point_spacing_m", "must be > 0");
  prior.points = r.get_all<Eigen::Vector3f>("points");
  prior.normals = r.get_all<Eigen::Vector3f>("normals", prior.points.size());
  prior.plan.origin = r.get<Eigen::Vector2f>("plan.origin");
  prior.plan.cell_m = r.get<float>("plan.cell_m");
  prior.plan.width = r.get<std::int32_t>("plan.width");
  prior.plan.height = r.get<std::int32_t>("plan.height");
  if (!(prior.plan.cell_m > 0.0F) || prior.plan.width <= 0 || prior.plan.height <= 0 ||
      static_cast<std::uint64_t>(prior.plan.width) * static_cast<std::uint64_t>(prior.plan.height) > (std::uint64_t{1} << 32))
    throw InputError(file.string(), "plan", "bad grid size");
  const auto cells = static_cast<std::uint64_t>(prior.plan.width) * static_cast<std::uint64_t>(prior.plan.height);
  prior.plan.likelihood = r.get_all<float>("plan.likelihood", cells);
  prior.plan.floor_z = r.get_all<float>("plan.floor_z", cells);
  prior.plan.wall_distance = r.get_all<float>("plan.wall_distance", cells);
  prior.vertical_points = r.get<std::uint64_t>("vertical_points");
  prior.horizontal_points = r.get<std::uint64_t>("horizontal_points");
  if (!r.done()) throw InputError(file.string(), "", "trailing bytes after the prior map");
  for (const auto& p : prior.points)
    if (!p.allFinite()) throw InputError(file.string(), "points", "a point is not finite");
  return prior;
}

}  // namespace adit::slam
