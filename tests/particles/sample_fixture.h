// Synthetic bristle samples for the particle tests and benchmarks: host arrays of every
// sample field, uploaded to device buffers that a SampleView points into.
#pragma once
#include <math.h>

#include <vector>

#include "core/brush/bristle_fields.h"
#include "core/exec/buffer.h"

namespace wb::test {

/// The box of `points` grown by `range`: the region a sample grid is built for when its queries
/// of that range start from those points (SampleGrid::build).
struct Region {
  Vec3 lo, hi;
};
inline Region region_around(const std::vector<Vec3>& points, float range) {
  if (points.empty()) return Region{Vec3(-range, -range, -range), Vec3(range, range, range)};
  Region r{Vec3(1e30f, 1e30f, 1e30f), Vec3(-1e30f, -1e30f, -1e30f)};
  for (const Vec3& p : points) {
    r.lo = Vec3(fminf(r.lo.x, p.x), fminf(r.lo.y, p.y), fminf(r.lo.z, p.z));
    r.hi = Vec3(fmaxf(r.hi.x, p.x), fmaxf(r.hi.y, p.y), fmaxf(r.hi.z, p.z));
  }
  r.lo = r.lo - Vec3(range, range, range);
  r.hi = r.hi + Vec3(range, range, range);
  return r;
}

struct HostSamples {
#define WB_X(type, name, doc) std::vector<type> name;
  WB_SAMPLE_FIELDS(WB_X)
#undef WB_X
  int bristles = 0, per_bristle = 0;
  void resize(int n_bristles, int per) {
    bristles = n_bristles;
    per_bristle = per;
#define WB_X(type, name, doc) name.assign(size_t(n_bristles) * per, Vec3());
    WB_SAMPLE_FIELDS(WB_X)
#undef WB_X
  }
};

struct DeviceSamples {
#define WB_X(type, name, doc) DeviceBuffer<type> name;
  WB_SAMPLE_FIELDS(WB_X)
#undef WB_X
  int bristles = 0, per_bristle = 0;
  explicit DeviceSamples(const Device& d) {
#define WB_X(type, name, doc) name.set_device(d);
    WB_SAMPLE_FIELDS(WB_X)
#undef WB_X
  }
  void upload(const HostSamples& h) {
#define WB_X(type, name, doc) name.copy_from_host(h.name);
    WB_SAMPLE_FIELDS(WB_X)
#undef WB_X
    bristles = h.bristles;
    per_bristle = h.per_bristle;
  }
  SampleView view() {
    SampleView out;
#define WB_X(type, name, doc) out.name = name.data();
    WB_SAMPLE_FIELDS(WB_X)
#undef WB_X
    out.bristles = bristles;
    out.per_bristle = per_bristle;
    return out;
  }
};

/// One straight bristle of `per` samples spaced `gap` cells from `root` along `dir`, frame
/// t = dir, n, b = t x n, moving with velocity `vel` and acceleration `acc` (no rotation).
inline void straight_bristle(HostSamples& h, int bristle, Vec3 root, Vec3 dir, Vec3 normal, float gap, Vec3 vel,
                             Vec3 acc) {
  const Vec3 binormal = cross(dir, normal);
  for (int j = 0; j < h.per_bristle; ++j) {
    const size_t i = size_t(bristle) * h.per_bristle + j;
    h.x[i] = root + dir * (gap * float(j));
    h.t[i] = dir;
    h.n[i] = normal;
    h.b[i] = binormal;
    h.v[i] = vel;
    h.a[i] = acc;
    h.omega[i] = Vec3();
    h.alpha[i] = Vec3();
  }
}

}  // namespace wb::test
