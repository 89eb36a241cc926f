#include "adit/sim/ray_caster.hpp"

#include <embree3/rtcore.h>

#include <algorithm>
#include <stdexcept>

namespace adit::sim {

RayCaster::RayCaster(const TriangleMesh& mesh) {
  RTCDevice device = rtcNewDevice("threads=1");
  if (device == nullptr) throw std::runtime_error("Embree: cannot create a device");
  device_ = device;
  RTCScene scene = rtcNewScene(device);
  scene_ = scene;
  rtcSetSceneFlags(scene, RTC_SCENE_FLAG_ROBUST);
  RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
  // Embree reads 16 bytes at the last vertex: Vector3f is 12, so the shared
  // buffer would overrun; copy into Embree's own padded buffers instead.
  auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                               3 * sizeof(float), mesh.vertices.size()));
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    vertices[3 * i] = mesh.vertices[i].x();
    vertices[3 * i + 1] = mesh.vertices[i].y();
    vertices[3 * i + 2] = mesh.vertices[i].z();
  }
  auto* indices = static_cast<unsigned*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                                 3 * sizeof(unsigned), mesh.triangles.size()));
  for (std::size_t i = 0; i < mesh.triangles.size(); ++i) {
    for (int k = 0; k < 3; ++k) indices[3 * i + k] = mesh.triangles[i][k];
  }
  rtcCommitGeometry(geometry);
  rtcAttachGeometry(scene, geometry);
  rtcReleaseGeometry(geometry);
  rtcCommitScene(scene);
  if (rtcGetDeviceError(device) != RTC_ERROR_NONE) throw std::runtime_error("Embree: scene build failed");
}

RayCaster::~RayCaster() {
  rtcReleaseScene(static_cast<RTCScene>(scene_));
  rtcReleaseDevice(static_cast<RTCDevice>(device_));
}

Hit RayCaster::intersect(const Eigen::Vector3f& origin, const Eigen::Vector3f& direction, float near_m,
                         float far_m) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRayHit rh{};
  rh.ray.org_x = origin.x();
  rh.ray.org_y = origin.y();
  rh.ray.org_z = origin.z();
  rh.ray.dir_x = direction.x();
  rh.ray.dir_y = direction.y();
  rh.ray.dir_z = direction.z();
  rh.ray.tnear = near_m;
  rh.ray.tfar = far_m;
  rh.ray.mask = 0xFFFFFFFFu;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(static_cast<RTCScene>(scene_), &context, &rh);
  Hit hit;
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return hit;
  hit.distance = rh.ray.tfar;
  hit.triangle = rh.hit.primID;
  hit.normal = Eigen::Vector3f(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z).normalized();
  return hit;
}

void RayCaster::intersect(std::span<const Eigen::Vector3f> origins, std::span<const Eigen::Vector3f> directions,
                          float near_m, float far_m, std::span<Hit> hits) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  RTCRayHit16 rh;
  alignas(64) int valid[kPacket];
  for (std::size_t first = 0; first < origins.size(); first += kPacket) {
    const std::size_t n = std::min(kPacket, origins.size() - first);
    for (std::size_t i = 0; i < kPacket; ++i) {
      valid[i] = i < n ? -1 : 0;
      const std::size_t k = first + std::min(i, n - 1);  // inactive lanes copy a valid ray
      rh.ray.org_x[i] = origins[k].x();
      rh.ray.org_y[i] = origins[k].y();
      rh.ray.org_z[i] = origins[k].z();
      rh.ray.dir_x[i] = directions[k].x();
      rh.ray.dir_y[i] = directions[k].y();
      rh.ray.dir_z[i] = directions[k].z();
      rh.ray.tnear[i] = near_m;
      rh.ray.tfar[i] = far_m;
      rh.ray.time[i] = 0.0F;
      rh.ray.mask[i] = 0xFFFFFFFFu;
      rh.ray.id[i] = static_cast<unsigned>(i);
      rh.ray.flags[i] = 0;
      rh.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
      rh.hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
    }
    rtcIntersect16(valid, static_cast<RTCScene>(scene_), &context, &rh);
    for (std::size_t i = 0; i < n; ++i) {
      Hit& hit = hits[first + i];
      hit = Hit{};
      if (rh.hit.geomID[i] == RTC_INVALID_GEOMETRY_ID) continue;
      hit.distance = rh.ray.tfar[i];
      hit.triangle = rh.hit.primID[i];
      hit.normal = Eigen::Vector3f(rh.hit.Ng_x[i], rh.hit.Ng_y[i], rh.hit.Ng_z[i]).normalized();
    }
  }
}

}  // namespace adit::sim
