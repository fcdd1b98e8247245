#include "accel/embree_accel.hpp"

#include <limits>
#include <string>

#include "base/errors.hpp"

namespace tracer {

bool EmbreeAccel::monitor(void* user, ssize_t bytes, bool /*post*/) {
  auto* self = static_cast<EmbreeAccel*>(user);
  const int64_t now = self->bytes_.fetch_add(bytes) + bytes;
  int64_t peak = self->peak_bytes_.load();
  while (now > peak && !self->peak_bytes_.compare_exchange_weak(peak, now)) {
  }
  return true;
}

EmbreeAccel::EmbreeAccel(const Scene& scene, CancelFlag cancel, const char* device_config, RTCBuildQuality quality)
    : scene_(&scene) {
  device_ = rtcNewDevice(device_config);
  if (!device_)
    throw InputError("embree: rtcNewDevice failed (error " + std::to_string(rtcGetDeviceError(nullptr)) + ")");
  rtcSetDeviceMemoryMonitorFunction(device_, &EmbreeAccel::monitor, this);
  rtc_scene_ = rtcNewScene(device_);
  rtcSetSceneBuildQuality(rtc_scene_, quality);
  if (!scene.instanced()) {
    // One Embree geometry per scene geometry, attached in order, so geomID and primID coincide.
    add_geometries(rtc_scene_, 0, uint32_t(scene.geometries.size()));
  } else {
    // Embree's two levels: a scene per mesh (its geometries in order, geomID counted from the
    // mesh's first) and an instance geometry per instance, attached in order (instID is ours).
    for (const Mesh& m : scene.meshes) {
      const uint32_t first = m.triangles.count ? scene.tri_geom[m.triangles.first] : 0;
      uint32_t end = first;
      while (end < scene.geometries.size() &&
             scene.geometries[end].first_triangle < m.triangles.first + m.triangles.count) {
        ++end;
      }
      RTCScene mesh_scene = rtcNewScene(device_);
      rtcSetSceneBuildQuality(mesh_scene, quality);
      add_geometries(mesh_scene, first, end);
      rtcCommitScene(mesh_scene);
      mesh_scenes_.push_back(mesh_scene);
      first_geometry_.push_back(first);
    }
    for (const Instance& in : scene.instances) {
      RTCGeometry geom = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_INSTANCE);
      rtcSetGeometryInstancedScene(geom, mesh_scenes_[in.mesh]);
      rtcSetGeometryTransform(geom, 0, RTC_FORMAT_FLOAT3X4_ROW_MAJOR, &in.to_world.m[0][0]);
      rtcCommitGeometry(geom);
      rtcAttachGeometry(rtc_scene_, geom);
      rtcReleaseGeometry(geom);
    }
  }
  // Embree asks this during the build; false cancels it (a Ctrl-C during a long build).
  rtcSetSceneProgressMonitorFunction(
      rtc_scene_, [](void* flag, double) { return !is_cancelled(static_cast<CancelFlag>(flag)); },
      const_cast<std::atomic<bool>*>(cancel));
  rtcCommitScene(rtc_scene_);
  const bool cancelled = is_cancelled(cancel), failed = rtcGetDeviceError(device_) != RTC_ERROR_NONE;
  if (cancelled || failed) {
    // The destructor does not run for a throwing constructor.
    rtcReleaseScene(rtc_scene_);
    for (RTCScene m : mesh_scenes_) rtcReleaseScene(m);
    rtcReleaseDevice(device_);
    if (cancelled) throw Cancelled();
    throw InputError("embree: scene build failed");
  }
}

void EmbreeAccel::add_geometries(RTCScene target, uint32_t first, uint32_t end) {
  for (uint32_t id = first; id < end; ++id) {
    const Geometry& g = scene_->geometries[id];
    RTCGeometry geom = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                          3 * sizeof(float), 3 * size_t(g.triangle_count)));
    auto* idx = static_cast<unsigned*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                               3 * sizeof(unsigned), g.triangle_count));
    for (uint32_t i = 0; i < g.triangle_count; ++i) {
      const Triangle& t = scene_->triangles[g.first_triangle + i];
      const Vec3 p[3] = {t.v0, t.v1, t.v2};
      for (int k = 0; k < 3; ++k) {
        v[9 * i + 3 * k] = p[k].x;
        v[9 * i + 3 * k + 1] = p[k].y;
        v[9 * i + 3 * k + 2] = p[k].z;
        idx[3 * i + k] = 3 * i + unsigned(k);
      }
    }
    rtcCommitGeometry(geom);
    rtcAttachGeometry(target, geom);
    rtcReleaseGeometry(geom);
  }
}

void EmbreeAccel::name_hit(uint32_t geom, uint32_t prim, uint32_t inst, Hit& hit) const {
  if (inst != RTC_INVALID_GEOMETRY_ID && !first_geometry_.empty()) {
    hit.inst = inst;
    geom += first_geometry_[scene_->instances[inst].mesh];
  }
  hit.geomID = geom;
  hit.primID = prim;
  hit.tri = scene_->geometries[geom].first_triangle + prim;
}

EmbreeAccel::~EmbreeAccel() {
  for (RTCScene m : mesh_scenes_) rtcReleaseScene(m);
  if (rtc_scene_) rtcReleaseScene(rtc_scene_);
  if (device_) rtcReleaseDevice(device_);
}

namespace {

// `ray` as Embree's single ray, its id `id`.
RTCRay rtc_ray(const Ray& ray, unsigned id) {
  RTCRay r;
  r.org_x = ray.org.x;
  r.org_y = ray.org.y;
  r.org_z = ray.org.z;
  r.tnear = ray.tnear;
  r.dir_x = ray.dir.x;
  r.dir_y = ray.dir.y;
  r.dir_z = ray.dir.z;
  r.time = 0.0f;
  r.tfar = ray.tfar;
  r.mask = 0xffffffffu;
  r.id = id;
  r.flags = 0;
  return r;
}

}  // namespace

bool EmbreeAccel::intersect(const Ray& ray, Hit& hit) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRayHit rh;
  rh.ray = rtc_ray(ray, 0);
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(rtc_scene_, &context, &rh);
  hit = Hit{};
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
  hit.t = rh.ray.tfar;
  hit.u = rh.hit.u;
  hit.v = rh.hit.v;
  name_hit(rh.hit.geomID, rh.hit.primID, rh.hit.instID[0], hit);
  return true;
}

bool EmbreeAccel::occluded(const Ray& ray) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRay r = rtc_ray(ray, 0);
  rtcOccluded1(rtc_scene_, &context, &r);
  return r.tfar < 0.0f;  // Embree sets tfar to -inf on a hit
}

namespace {

// Lanes of a 16-wide Embree call: -1 where a ray is, 0 where none is.
void valid_lanes(uint32_t active, int* valid) {
  for (int k = 0; k < kPacketSize; ++k) valid[k] = (active >> k) & 1u ? -1 : 0;
}

void fill_ray16(RTCRay16& r, int k, const Ray& ray) {
  r.org_x[k] = ray.org.x;
  r.org_y[k] = ray.org.y;
  r.org_z[k] = ray.org.z;
  r.tnear[k] = ray.tnear;
  r.dir_x[k] = ray.dir.x;
  r.dir_y[k] = ray.dir.y;
  r.dir_z[k] = ray.dir.z;
  r.time[k] = 0.0f;
  r.tfar[k] = ray.tfar;
  r.mask[k] = 0xffffffffu;
  r.id[k] = unsigned(k);
  r.flags[k] = 0;
}

// Every lane of a 16-wide call holds a valid ray: where Embree has no 16-wide kernels (CPUs
// without AVX-512) rtcOccluded16 and rtcIntersect16 hand all sixteen lanes to its ray-stream
// path, which ignores the valid mask, and its assertions stop the process on a lane of garbage.
// Lanes without a ray get this one, which Embree skips as already finished (tfar < 0).
void fill_unused_ray16(RTCRay16& r, int k) {
  r.org_x[k] = r.org_y[k] = r.org_z[k] = 0.0f;
  r.dir_x[k] = r.dir_y[k] = 0.0f;
  r.dir_z[k] = 1.0f;
  r.tnear[k] = 0.0f;
  r.tfar[k] = -std::numeric_limits<float>::infinity();
  r.time[k] = 0.0f;
  r.mask[k] = 0;
  r.id[k] = unsigned(k);
  r.flags[k] = 0;
}

// Lane k of `r` from rays(k) where `active` has it, else unused.
template <class RayOf>
void fill_rays16(RTCRay16& r, uint32_t active, const RayOf& rays) {
  for (int k = 0; k < kPacketSize; ++k) {
    if ((active >> k) & 1u) {
      fill_ray16(r, k, rays(k));
    } else {
      fill_unused_ray16(r, k);
    }
  }
}

uint32_t occluded16(RTCScene scene, uint32_t active, RTCRay16& r, RTCIntersectContextFlags flags) {
  alignas(64) int valid[kPacketSize];
  valid_lanes(active, valid);
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  context.flags = flags;
  rtcOccluded16(valid, scene, &context, &r);
  uint32_t occluded = 0;
  for (uint32_t bits = active; bits; bits &= bits - 1) {
    const int k = __builtin_ctz(bits);
    if (r.tfar[k] < 0.0f) occluded |= 1u << k;  // Embree sets tfar to -inf on a hit
  }
  return occluded;
}

}  // namespace

void EmbreeAccel::intersect_packet(const RayPacket& rays, Hit* hits) const {
  alignas(64) RTCRayHit16 rh;
  alignas(64) int valid[kPacketSize];
  valid_lanes(rays.active, valid);
  fill_rays16(rh.ray, rays.active, [&](int k) { return rays.ray(k); });
  for (int k = 0; k < kPacketSize; ++k) {
    rh.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
    rh.hit.primID[k] = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0][k] = RTC_INVALID_GEOMETRY_ID;
  }
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;  // a 4x4 block of primary rays
  rtcIntersect16(valid, rtc_scene_, &context, &rh);
  for (uint32_t bits = rays.active; bits; bits &= bits - 1) {
    const int k = __builtin_ctz(bits);
    hits[k] = Hit{};
    if (rh.hit.geomID[k] == RTC_INVALID_GEOMETRY_ID) continue;
    hits[k].t = rh.ray.tfar[k];
    hits[k].u = rh.hit.u[k];
    hits[k].v = rh.hit.v[k];
    name_hit(rh.hit.geomID[k], rh.hit.primID[k], rh.hit.instID[0][k], hits[k]);
  }
}

uint32_t EmbreeAccel::occluded_packet(const RayPacket& rays) const {
  alignas(64) RTCRay16 r;
  fill_rays16(r, rays.active, [&](int k) { return rays.ray(k); });
  return occluded16(rtc_scene_, rays.active, r, RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT);
}

uint32_t EmbreeAccel::occluded_bundle_from(const RayBundle& rays, uint32_t) const {
  alignas(64) RTCRay16 r;
  fill_rays16(r, rays.active, [&](int k) { return rays.ray(k); });
  return occluded16(rtc_scene_, rays.active, r, RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT);
}

void EmbreeAccel::occluded_stream(const RayStream& rays, StreamMask& occluded) const {
  static thread_local std::vector<RTCRay> stream;  // grows once per thread to a stream's size
  stream.resize(rays.size);
  for (uint32_t at = 0; at < rays.size; ++at) {
    const uint32_t i = rays.order[at];
    stream[at] = rtc_ray(rays.ray(i), i);
  }
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  rtcOccluded1M(rtc_scene_, &context, stream.data(), rays.size, sizeof(RTCRay));
  for (uint32_t at = 0; at < rays.size; ++at) {
    if (stream[at].tfar < 0.0f) occluded.set(rays.order[at]);  // Embree sets tfar to -inf on a hit
  }
}

}  // namespace tracer
