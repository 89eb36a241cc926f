#pragma once
// Closest-hit ray casting against a TriangleMesh with Embree 3. The BVH is
// built on one thread (the Embree device is configured threads=1) and the
// scene is built robust (no rays slip through shared edges), so a given mesh
// and ray always give the same hit. intersect() is thread-safe after
// construction.

#include <cstdint>
#include <limits>
#include <span>

#include <Eigen/Core>

#include "adit/sim/mesh.hpp"

namespace adit::sim {

struct Hit {
  float distance = std::numeric_limits<float>::infinity();  // along the unit direction
  std::uint32_t triangle = 0;
  Eigen::Vector3f normal = Eigen::Vector3f::Zero();  // unit, not oriented
  bool dynamic = false;           // a moving object (people.hpp), not the mesh: `triangle` is meaningless
  std::uint8_t reflectivity = 0;  // for dynamic hits
  bool valid() const { return distance < std::numeric_limits<float>::infinity(); }
};

class RayCaster {
 public:
  // The mesh must outlive the caster (Embree shares its vertex and index arrays).
  explicit RayCaster(const TriangleMesh& mesh);
  ~RayCaster();
  RayCaster(const RayCaster&) = delete;
  RayCaster& operator=(const RayCaster&) = delete;

  Hit intersect(const Eigen::Vector3f& origin, const Eigen::Vector3f& direction, float near_m, float far_m) const;

  // Many rays, cast kPacket at a time as Embree ray packets, which traverse
  // the BVH together: much faster than one by one for coherent rays (the
  // beams of one firing of a spinning LiDAR). A ray's hit does not depend on
  // the other rays of its packet, but may differ from intersect()'s in the
  // last bits (Embree's packet kernels). hits.size() == origins.size() == directions.size().
  static constexpr std::size_t kPacket = 16;
  void intersect(std::span<const Eigen::Vector3f> origins, std::span<const Eigen::Vector3f> directions, float near_m,
                 float far_m, std::span<Hit> hits) const;

 private:
  void* device_ = nullptr;  // RTCDevice, RTCScene: opaque here to keep Embree out of the header
  void* scene_ = nullptr;
};

}  // namespace adit::sim
