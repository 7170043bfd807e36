// Ambient occlusion of the paint surface (paper §6): 64 short rays around the hit point, each
// recording the maximum density it reaches (films as layers of their thickness); occlusion is
// their mean. Rays are marched coarsely (one sample per cell, nearest cell) because AO is the
// renderer's main cost.
#pragma once
#include "core/render/raycast_kernels.h"

namespace wb {

/// Direction k of n cosine-weighted directions on the +z hemisphere (Fibonacci spiral):
/// even coverage without randomness, so images are reproducible and noise-free.
WB_HD WB_INLINE Vec3 ao_direction(int k, int n) {
  const float u = (float(k) + 0.5f) / float(n);
  const float r = sqrtf(u);                  // cosine weighting: radius sqrt(u) on the unit disc
  const float phi = 2.39996323f * float(k);  // golden angle
  return Vec3(r * cosf(phi), r * sinf(phi), sqrtf(maxf(1.f - u, 0.f)));
}

/// Orthonormal tangent frame around unit n (Duff et al. 2017, branch-free).
WB_HD WB_INLINE void tangent_frame(Vec3 n, Vec3& t, Vec3& b) {
  const float s = n.z >= 0.f ? 1.f : -1.f;
  const float a = -1.f / (s + n.z);
  const float c = n.x * n.y * a;
  t = Vec3(1.f + s * n.x * n.x * a, s * c, -s * n.x);
  b = Vec3(c, s + n.y * n.y * a, -n.y);
}

WB_HD WB_INLINE int floor_div(int a, int b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }

/// Highest paint (1 + top cell, in cells) among the columns within `radius` of (x, y), from the
/// coarse block map; the canvas depth where the map does not reach (nothing can be skipped).
WB_HD WB_INLINE int local_top(const RenderVolume& v, float x, float y, float radius) {
  const int bx0 = floor_div(int(floorf(x - radius)) - v.top_x0, kTopBlock);
  const int by0 = floor_div(int(floorf(y - radius)) - v.top_y0, kTopBlock);
  const int bx1 = floor_div(int(floorf(x + radius)) - v.top_x0, kTopBlock);
  const int by1 = floor_div(int(floorf(y + radius)) - v.top_y0, kTopBlock);
  if (bx0 < 0 || by0 < 0 || bx1 >= v.blk_w || by1 >= v.blk_h) return v.tiles.depth;
  int m = 0;
  for (int by = by0; by <= by1; ++by)
    for (int bx = bx0; bx <= bx1; ++bx) {
      const int t = v.block_top[by * v.blk_w + bx];
      m = t > m ? t : m;
    }
  return m;
}

/// Density of cell (x, y, z) as the surface sees it (surface_density per cell): in a thin column
/// the film's share of the cell, min(max(F - z, 0), 1), so that a film occludes as a layer of its
/// thickness and not as the sparse paint it is made of; the volume's density where the paint is
/// thick, blended by thinness between. A cell denser than threshold + film_fade is in a thick
/// column, so the film record is not fetched there, nor above the column's top.
WB_HD WB_INLINE float ao_density(const RenderVolume& v, const RenderParams& P, int x, int y, int z) {
  if (z < 0 || z >= column_top(v, x, y)) return 0.f;  // a column's film lies below its top
  const float rho = cell_density_raw(v, x, y, z);
  if (rho >= P.threshold + P.film_fade || !v.film) return rho;
  const FilmColumn k = column_film(v, x, y);
  if (!(k.height > 0.f) || k.thin == 0) return rho;
  const float thin = decode_unorm16(k.thin);
  return thin * clampf(k.height - float(z), 0.f, 1.f) + (1.f - thin) * rho;
}

/// Ambient visibility in [0, 1] at hit point p with normal n: 1 - strength * mean_k max_s rho.
/// `dirs` holds P.ao_rays directions around +z; they are turned into n's frame.
WB_HD WB_INLINE float ambient_occlusion(const RenderVolume& v, const RenderParams& P, const Vec3* dirs, Vec3 p,
                                        Vec3 n) {
  if (P.ao_rays <= 0 || P.ao_strength <= 0.f) return 1.f;
  const float reach = P.ao_offset + P.ao_length + 1.f;
  // Nothing above this height near p: rising rays stop there, and an empty region is unoccluded.
  const float zloc = float(local_top(v, p.x, p.y, reach));
  if (zloc <= 0.f) return 1.f;
  Vec3 t, b;
  tangent_frame(n, t, b);
  const Vec3 o = p + n * P.ao_offset;
  float occ = 0.f;
  for (int k = 0; k < P.ao_rays; ++k) {
    const Vec3 dl = dirs[k];
    const Vec3 d = t * dl.x + b * dl.y + n * dl.z;
    float m = 0.f;
    for (float s = P.ao_step; s <= P.ao_length + 1e-4f; s += P.ao_step) {
      const Vec3 q = o + d * s;
      if (q.z >= zloc) {
        if (d.z >= 0.f) break;  // above all paint near p and rising: nothing more to meet
        continue;
      }
      if (q.z < 0.f) {
        m = 1.f;  // the canvas itself occludes
        break;
      }
      const float rho = ao_density(v, P, int(floorf(q.x)), int(floorf(q.y)), int(q.z));
      m = maxf(m, rho);
      if (m >= 1.f) break;
    }
    occ += minf(m, 1.f);
  }
  return 1.f - P.ao_strength * occ / float(P.ao_rays);
}

}  // namespace wb
