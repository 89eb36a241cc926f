#include "adit/products/occupancy_3d.hpp"

#include <octomap/OcTree.h>

#include "adit/common/error.hpp"

namespace adit::products {

struct Occupancy3d::Tree {
  explicit Tree(double resolution) : octree(resolution) {}
  octomap::OcTree octree;
  octomap::KeySet free, occupied;  // one batch's updates
  octomap::KeyRay ray;
};

Occupancy3d::Occupancy3d(const Occupancy3dOptions& options) : tree_(std::make_unique<Tree>(options.resolution_m)) {
  tree_->octree.setProbHit(options.probability_hit);
  tree_->octree.setProbMiss(options.probability_miss);
}
Occupancy3d::~Occupancy3d() = default;
Occupancy3d::Occupancy3d(Occupancy3d&&) noexcept = default;
Occupancy3d& Occupancy3d::operator=(Occupancy3d&&) noexcept = default;

namespace {
octomap::point3d to_octomap(const Eigen::Vector3f& p) { return {p.x(), p.y(), p.z()}; }
}  // namespace

void Occupancy3d::insert(const Eigen::Vector3f& origin, std::span<const Eigen::Vector3f> hits,
                         std::span<const Eigen::Vector3f> passes) {
  Tree& t = *tree_;
  t.free.clear();
  t.occupied.clear();
  const octomap::point3d o = to_octomap(origin);
  const auto cast = [&](const Eigen::Vector3f& end) {
    // computeRayKeys lists the voxels from the origin's up to, not including, the end's.
    if (t.octree.computeRayKeys(o, to_octomap(end), t.ray)) t.free.insert(t.ray.begin(), t.ray.end());
  };
  for (const Eigen::Vector3f& p : hits) {
    cast(p);
    octomap::OcTreeKey key;
    if (t.octree.coordToKeyChecked(to_octomap(p), key)) t.occupied.insert(key);
  }
  for (const Eigen::Vector3f& p : passes) cast(p);
  for (const octomap::OcTreeKey& k : t.free)
    if (t.occupied.find(k) == t.occupied.end()) t.octree.updateNode(k, false, true);
  for (const octomap::OcTreeKey& k : t.occupied) t.octree.updateNode(k, true, true);
}

Occupancy3d::State Occupancy3d::state_at(const Eigen::Vector3f& p) const {
  const octomap::OcTreeNode* n = tree_->octree.search(to_octomap(p));
  if (n == nullptr) return State::unknown;
  return tree_->octree.isNodeOccupied(n) ? State::occupied : State::free;
}

void Occupancy3d::for_each_leaf(
    const std::function<void(const Eigen::Vector3f& centre, double size, bool occupied)>& f) const {
  const octomap::OcTree& tree = tree_->octree;
  for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it) {
    const octomap::point3d c = it.getCoordinate();
    f(Eigen::Vector3f(c.x(), c.y(), c.z()), it.getSize(), tree.isNodeOccupied(*it));
  }
}

std::size_t Occupancy3d::leaf_count() const { return tree_->octree.getNumLeafNodes(); }

std::uintmax_t Occupancy3d::write_bt(const std::filesystem::path& file) {
  tree_->octree.updateInnerOccupancy();
  tree_->octree.prune();
  if (!tree_->octree.writeBinary(file.string())) throw InputError(file.string(), "", "cannot write the octree");
  return std::filesystem::file_size(file);
}

std::uintmax_t Occupancy3d::write_ot(const std::filesystem::path& file) const {
  if (!tree_->octree.write(file.string())) throw InputError(file.string(), "", "cannot write the octree");
  return std::filesystem::file_size(file);
}

}  // namespace adit::products
