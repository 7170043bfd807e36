// Scenes of the transfer tests: synthetic bristle samples, a paint window with a layer of
// paint, particles from host arrays, and host sums for the books.
#pragma once
#include <math.h>

#include <cmath>
#include <functional>
#include <vector>

#include "backend_fixture.h"
#include "core/canvas/window.h"
#include "core/particles/sample_grid.h"
#include "core/particles/particle_store.h"
#include "core/transfer/bristle_load.h"
#include "core/transfer/paint_books.h"
#include "core/transfer/transfer.h"
#include "particles/sample_fixture.h"

namespace wb::test {

/// Window fields on the host, in WB_PAINT_FIELDS order.
using WindowFields = std::vector<std::vector<float>>;

/// Particles from host arrays: positions, one mass, colour, oil, velocity.
inline ParticleHost particles_at(const std::vector<Vec3>& x, float m, Vec3 ryb, float oil = 0.3f,
                                 Vec3 v = Vec3(0.f, 0.f, 0.f)) {
  ParticleHost h;
  h.resize(x.size());
  for (size_t i = 0; i < x.size(); ++i) {
    h.x[i] = x[i];
    h.v[i] = v;
    h.m[i] = m;
    h.pigment_r[i] = ryb.x;
    h.pigment_y[i] = ryb.y;
    h.pigment_b[i] = ryb.z;
    h.oil[i] = oil;
    h.dryness[i] = 0.f;
  }
  return h;
}

class TransferTest : public BackendTest {
 protected:
  /// A window of `dims` at `origin` painted by fn(i, j, k) -> density with colour ryb, oil, dryness.
  PaintWindow make_window(Int3 dims, Int3 origin, const std::function<float(int, int, int)>& fn, Vec3 ryb,
                          float oil = 0.2f, float dryness = 0.f) {
    PaintWindow w(device_, dims);
    w.set_origin(origin);
    WindowFields f(kPaintFieldCount, std::vector<float>(size_t(w.cell_count()), 0.f));
    for (int k = 0; k < dims.z; ++k)
      for (int j = 0; j < dims.y; ++j)
        for (int i = 0; i < dims.x; ++i) {
          const size_t c = (size_t(k) * dims.y + j) * dims.x + i;
          const float rho = fn(i, j, k);
          f[0][c] = rho;
          if (rho > 0.f) {
            f[1][c] = ryb.x;
            f[2][c] = ryb.y;
            f[3][c] = ryb.z;
            f[4][c] = oil;
            f[5][c] = dryness;
          }
        }
    w.from_host(f);
    return w;
  }

  /// Sets every particle's nearest sample (range `range`) with the sample grid.
  void query_nearest(DeviceSamples& s, ParticleStore& p, float range) {
    SampleGrid grid(device_);
    const Region r = region_around(p.to_host().x, range);
    grid.build(s.view(), 2.f, r.lo, r.hi, ws_);
    grid.query_nearest(p.view(), range);
  }

  static TransferEnv env_for(PaintWindow& w, float D0 = 50.f) {
    TransferEnv env;
    env.paint = w.view();
    env.D0 = D0;
    return env;
  }

  static double sum(const std::vector<float>& v) {
    double s = 0;
    for (float x : v) s += x;
    return s;
  }
};

/// `bristles` vertical bristles of `per` samples, gap `gap` cells, roots at z = z_top, tips
/// going down, spread on a line along x with spacing `spread` around (cx, cy).
inline HostSamples vertical_brush(int bristles, int per, float gap, float cx, float cy, float z_tip, float spread,
                                  Vec3 vel = Vec3(0.f, 0.f, 0.f)) {
  HostSamples h;
  h.resize(bristles, per);
  for (int b = 0; b < bristles; ++b) {
    const float x = cx + (float(b) - 0.5f * float(bristles - 1)) * spread;
    const Vec3 tip(x, cy, z_tip);
    // Sample 0 at the tip, going up: the tip is the lowest sample.
    straight_bristle(h, b, tip, Vec3(0.f, 0.f, 1.f), Vec3(1.f, 0.f, 0.f), gap, vel, Vec3(0.f, 0.f, 0.f));
  }
  return h;
}

}  // namespace wb::test
