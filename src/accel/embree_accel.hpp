// Intel Embree 3 as a side-by-side reference backend (never the default): the same scene, the same
// rays, through rtcIntersect1/rtcOccluded1 at Embree's default build quality (or HIGH), or with --packets
// through its packet API at its best: rtcIntersect16 per 4x4 pixel block (coherent), rtcOccluded16
// for a block's shadow rays and for each hit's AO rays.
#pragma once

#include <embree3/rtcore.h>

#include <atomic>
#include <vector>

#include "base/errors.hpp"
#include "math/ray.hpp"
#include "math/ray_packet.hpp"
#include "math/ray_stream.hpp"
#include "scene/scene.hpp"

namespace tracer {

class EmbreeAccel {
 public:
  // `device_config`: rtcNewDevice's configuration string (e.g. "isa=avx2"; null: Embree's choice);
  // `quality`: the scene's build quality (MEDIUM, Embree's default; HIGH adds spatial splits).
  explicit EmbreeAccel(const Scene& scene, CancelFlag cancel = nullptr, const char* device_config = nullptr,
                       RTCBuildQuality quality = RTC_BUILD_QUALITY_MEDIUM);
  ~EmbreeAccel();
  EmbreeAccel(const EmbreeAccel&) = delete;
  EmbreeAccel& operator=(const EmbreeAccel&) = delete;

  bool intersect(const Ray& ray, Hit& hit) const;
  bool occluded(const Ray& ray) const;
  // The packet API: the active lanes of `rays` (hits[k] for lane k), and occlusion masks.
  void intersect_packet(const RayPacket& rays, Hit* hits) const;
  uint32_t occluded_packet(const RayPacket& rays) const;
  uint32_t occluded_bundle_from(const RayBundle& rays, uint32_t origin) const;
  // The stream API on the same sorted rays the 8-wide BVH's streams take: rtcOccluded1M over
  // the stream in rays.order, flagged coherent.
  void occluded_stream(const RayStream& rays, StreamMask& occluded) const;
  size_t memory_bytes() const { return static_cast<size_t>(std::max<int64_t>(0, peak_bytes_.load())); }

 private:
  static bool monitor(void* user, ssize_t bytes, bool post);
  // Attaches the scene's geometries [first, end) to `target` in order, one Embree geometry each.
  void add_geometries(RTCScene target, uint32_t first, uint32_t end);
  // Fills hit's names from Embree's geomID, primID and instID (an instanced scene's geomID counts
  // from its mesh's first geometry).
  void name_hit(uint32_t geom, uint32_t prim, uint32_t inst, Hit& hit) const;

  const Scene* scene_;
  RTCDevice device_ = nullptr;
  RTCScene rtc_scene_ = nullptr;
  std::vector<RTCScene> mesh_scenes_;     // an instanced scene's meshes
  std::vector<uint32_t> first_geometry_;  // per mesh, its first geometry's index
  std::atomic<int64_t> bytes_{0}, peak_bytes_{0};
};

}  // namespace tracer
