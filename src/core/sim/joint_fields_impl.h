// Joint-field kernels (§4.3), compiled once per backend.
#pragma once
#include "core/exec/error.h"
#include "core/exec/parallel_for.h"
#include "core/sim/joint_fields.h"

namespace wb::WB_BACKEND_NS {

/// out[i] = in[i] * scale (kg to cell-volume fractions and back).
void joint_scale(const float* in, float* out, int64_t n, float scale) {
  parallel_for(n, [=] WB_HD(int64_t i) { out[i] = in[i] * scale; });
}

/// The particles' raster as densities: density[i] = cell[i].first * scale and, where oil is
/// not null, oil[i] = cell[i].second * scale (scale 1 / cell_mass: kg to cell-volume fractions),
/// at the cells `list` holds (elsewhere both are 0: joint_clear_raster).
void joint_raster_density(const FloatPair* cell, float* density, float* oil, TouchList list, int64_t n, float scale) {
  WB_REQUIRE(n == 0 || (cell && density && list.on()), "joint_raster_density: a field or the list is null");
  parallel_for_count(list.count, n, [=] WB_HD(int64_t t) {
    const int64_t i = list.items[t];
    const FloatPair c = cell[i];
    density[i] = c.first * scale;
    if (oil) oil[i] = c.second * scale;
  });
}

/// The elements `list` holds (of n) back to zero in the raster's pairs and, where not null, its
/// density and oil, and unlisted: the raster is then zero everywhere (the caller clears the
/// list's count after).
void joint_clear_raster(TouchList list, int64_t n, FloatPair* pairs, float* density, float* oil) {
  parallel_for_count(list.count, n, [=] WB_HD(int64_t t) {
    const int64_t i = list.items[t];
    pairs[i] = FloatPair{0.f, 0.f};
    if (density) density[i] = 0.f;
    if (oil) oil[i] = 0.f;
    list.listed[i] = 0;
  });
}

/// Per window column: the dried paint's top (column_solid_tops) where the column's centre lies
/// within r of (cx, cy) and the top is above floor_z, else 0 (their maximum is the ground under a
/// brush footprint). Only the columns under the footprint are scanned.
void joint_ground_under(PaintWindowView pw, float dry_threshold, float cx, float cy, float r, float floor_z,
                        float* out) {
  parallel_for(int64_t(pw.nx) * pw.ny, [=] WB_HD(int64_t c) {
    out[c] = 0.f;
    const float dx = float(pw.ox + int(c % pw.nx)) + 0.5f - cx, dy = float(pw.oy + int(c / pw.nx)) + 0.5f - cy;
    if (!(dx * dx + dy * dy <= r * r)) return;
    int above = 0;
    float h = floor_z;
    column_solid_tops(pw, c, 1, dry_threshold, floor_z, &h, &above);
    if (h > floor_z) out[c] = h;
  });
}

/// Per sample below height z_top: x, -x, y and -y into out[0..n), [n..2n), [2n..3n), [3n..4n)
/// (-inf above z_top); their maxima are the horizontal box of the samples that reach the window.
void joint_sample_extent(const Vec3* x, int64_t n, float z_top, float* out) {
  parallel_for(n, [=] WB_HD(int64_t i) {
    const Vec3 p = x[i];
    const bool in = p.z < z_top;
    const float none = -INFINITY;
    out[i] = in ? p.x : none;
    out[n + i] = in ? -p.x : none;
    out[2 * n + i] = in ? p.y : none;
    out[3 * n + i] = in ? -p.y : none;
  });
}

/// Blends the particles' face momentum into the grid's face velocity, per face:
/// u = (w_g u + P) / (w_g + W), w_g = cell_mass * mean density of the two cells (Eq. 11's u).
void joint_blend_velocity(GridView g, PaintWindowView paint, ParticleRasterView raster, float cell_mass) {
  WB_REQUIRE(raster.nx == g.d.nx && raster.ny == g.d.ny && raster.nz == g.d.nz,
             "joint_blend_velocity: particle raster and grid differ in size");
  for (int c = 0; c < 3; ++c)
    WB_REQUIRE(raster.face[c] && raster.face_list[c].on(), "joint_blend_velocity: the raster has no listed faces");
  const GridDims d = g.d;
  for (int c = 0; c < 3; ++c) {
    float* u = g.vel[c];
    const FloatPair* face = raster.face[c];
    const float* rho = paint.density;
    const int ex = d.nx + (c == 0), ey = d.ny + (c == 1);
    const int64_t faces = int64_t(ex) * ey * (d.nz + (c == 2));
    // The faces the raster reached, which it listed (no other face has weight).
    const TouchList list = raster.face_list[c];
    parallel_for_count(list.count, faces, [=] WB_HD(int64_t t) {
      const int64_t f = list.items[t];
      const FloatPair pf = face[f];
      const float wp = pf.first;
      if (!(wp > 0.f)) return;
      const int i = int(f % ex), j = int((f / ex) % ey), k = int(f / (int64_t(ex) * ey));
      // Grid paint on the two sides of the face, as mass.
      const int ia = i - (c == 0), ja = j - (c == 1), ka = k - (c == 2);
      float rg = 0.f;
      int n = 0;
      if (ia >= 0 && ja >= 0 && ka >= 0) rg += rho[(int64_t(ka) * d.ny + ja) * d.nx + ia], ++n;
      if (i < d.nx && j < d.ny && k < d.nz) rg += rho[(int64_t(k) * d.ny + j) * d.nx + i], ++n;
      const float wg = n ? cell_mass * rg / float(n) : 0.f;
      u[f] = (wg * u[f] + pf.second) / (wg + wp);
    });
  }
}

/// Replaces non-finite values by 0 in [n] floats; returns nothing (count them first).
void joint_zero_nonfinite(float* v, int64_t n) {
  parallel_for(n, [=] WB_HD(int64_t i) {
    if (!isfinite(v[i])) v[i] = 0.f;
  });
}

/// Keeps particles inside the canvas box: its sides and floor are walls, so paint never leaves
/// the canvas (and is never deposited into off-canvas window cells, which are not stored).
void joint_clamp_to_canvas(ParticleView p, Vec3 lo, Vec3 hi) {
  parallel_for(p.count, [=] WB_HD(int64_t k) {
    const Vec3 x = p.x[k];
    const Vec3 c(clampf(x.x, lo.x, hi.x), clampf(x.y, lo.y, hi.y), clampf(x.z, lo.z, hi.z));
    if (c.x != x.x || c.y != x.y || c.z != x.z) {
      p.x[k] = c;
      // The wall stops the motion into it.
      Vec3 v = p.v[k];
      if (c.x != x.x) v.x = 0.f;
      if (c.y != x.y) v.y = 0.f;
      if (c.z != x.z) v.z = 0.f;
      p.v[k] = v;
    }
  });
}

/// Flags particles with any non-finite state as dead.
void joint_kill_nonfinite(ParticleView p) {
  parallel_for(p.count, [=] WB_HD(int64_t k) {
    const bool ok = isfinite3(p.x[k]) && isfinite3(p.v[k]) && isfinite(p.m[k]) && isfinite(p.pigment_r[k]) &&
                    isfinite(p.pigment_y[k]) && isfinite(p.pigment_b[k]) && isfinite(p.oil[k]) &&
                    isfinite(p.dryness[k]);
    if (!ok) p.dead[k] = 1u;
  });
}

}  // namespace wb::WB_BACKEND_NS
