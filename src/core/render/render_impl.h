// Render stage driver (paper §6, DESIGN step 9), compiled once per backend: column-top maps
// for empty-space skipping, particle splatting into the temporary density layer, and the
// per-pixel ray cast with AO and shading.
#pragma once
#include "core/exec/atomics.h"
#include "core/exec/parallel_for.h"
#include "core/render/ao_kernels.h"
#include "core/render/raycast_kernels.h"
#include "core/render/renderer.h"

namespace wb::WB_BACKEND_NS {

void render_top_map(RenderVolume v, RenderParams P, int x0, int y0, int w, int h, uint16_t* top, FilmColumn* film) {
  parallel_for(int64_t(w) * h, [=] WB_HD(int64_t i) {
    const int x = x0 + int(i % w), y = y0 + int(i / w);
    // Down the whole column: its top, the integral of density and its densest cell; then, for a
    // column thin enough to be a film, its density-weighted mean paint (thick columns' paint is
    // never read as a film's).
    int t = 0;
    float sum = 0.f, dmax = 0.f;
    const bool tiles_only = !v.has_win && !v.has_splat;
    int64_t a0 = -1;  // tiles only: address of the column's bottom cell, -1 for an empty tile
    int32_t slot = -1;
    if (tiles_only) {
      slot = v.tiles.slot_of_tile[(y / kTileSize) * v.tiles.tiles_x + x / kTileSize];
      if (slot >= 0) a0 = int64_t(slot) * v.tiles.tile_cells() + v.tiles.cell_offset(x % kTileSize, y % kTileSize, 0);
    }
    const int64_t dz = int64_t(kTileSize) * kTileSize;
    if (tiles_only) {
      if (a0 >= 0)
        for (int z = 0; z < v.tiles.depth; ++z) {
          const float d = v.tiles.density[a0 + z * dz];
          if (!(d > 0.f)) continue;
          t = z + 1;
          sum += d;
          dmax = d > dmax ? d : dmax;
        }
    } else {
      for (int z = 0; z < v.tiles.depth; ++z) {
        const float d = cell_density_raw(v, x, y, z);
        if (!(d > 0.f)) continue;
        t = z + 1;
        sum += d;
        dmax = d > dmax ? d : dmax;
      }
    }
    FilmColumn f{sum, 0, 0, 0, 0, 0, 0, 0.f, 0.f};
    const float thin = column_thinness(P, dmax);
    // A thick column: its top thick cell (density at the threshold or more) and the paint above it.
    int kt = -1;
    float above = 0.f, dt = 0.f, dry_top = 0.f;
    if (sum > 0.f && !(thin > 0.f)) {
      for (int z = t - 1; z >= 0; --z) {
        const RenderCell c = tiles_only ? RenderCell{v.tiles.density[a0 + z * dz], 0.f, 0.f, 0.f, 0.f,
                                                     v.tiles.dryness_at(slot, a0 + z * dz)}
                                        : cell_full_raw(v, x, y, z);
        if (c.density >= P.threshold) {
          kt = z;
          dt = c.density;
          dry_top = c.dryness;
          break;
        }
        if (c.density > 0.f) above += c.density;
      }
    }
    // A coat is paint on dried paint: a layer of its own, which the grid keeps in the cells above
    // the dried ones, wet or dried itself (a glaze stays a glaze as it dries). Paint above a wet
    // top is that top's own surface, partly filled cells the threshold surface passes through.
    const bool coat = kt >= 0 && above > 0.f && dry_top >= 0.5f;
    if (sum > 0.f && (thin > 0.f || coat)) {
      // The film's paint (a thin column: all of it) or the coat's (the cells above kt).
      const int z0 = coat ? kt + 1 : 0;
      const float total = coat ? above : sum;
      float r = 0.f, yy = 0.f, b = 0.f, oil = 0.f, dry = 0.f;
      for (int z = z0; z < t; ++z) {
        RenderCell c;
        if (tiles_only) {
          const int64_t a = a0 + z * dz;
          c.density = v.tiles.density[a];
          if (!(c.density > 0.f)) continue;
          c.r = decode_unorm16(v.tiles.pigment_r[a]);
          c.y = decode_unorm16(v.tiles.pigment_y[a]);
          c.b = decode_unorm16(v.tiles.pigment_b[a]);
          c.oil = decode_unorm16(v.tiles.oil[a]);
          c.dryness = v.tiles.dryness_at(slot, a);
        } else {
          c = cell_full_raw(v, x, y, z);
          if (!(c.density > 0.f)) continue;
        }
        r += c.density * c.r;
        yy += c.density * c.y;
        b += c.density * c.b;
        oil += c.density * c.oil;
        dry += c.density * c.dryness;
      }
      // Divided, not multiplied by 1 / total: a trace's total may be subnormal.
      f = FilmColumn{sum,
                     encode_unorm16(r / total),
                     encode_unorm16(yy / total),
                     encode_unorm16(b / total),
                     encode_unorm16(oil / total),
                     encode_unorm16(dry / total),
                     encode_unorm16(thin),
                     0.f,
                     0.f};
      if (coat) f.coat_thick = above;
    }
    // Every thick column's stack (the paint from the bottom of its top thick cell): a coat's
    // neighbours give its edge their own height.
    if (kt >= 0) f.coat = float(kt) + (dt < 1.f ? dt : 1.f) + above;
    // Densities above 1 pack more paint than the cells hold: rays must start above that film.
    const int tf = int(ceilf(sum));
    t = tf > t ? tf : t;
    top[i] = uint16_t(t < 65535 ? t : 65535);
    film[i] = f;
  });
}

void render_block_top(const uint16_t* top, const FilmColumn* film, int w, int h, uint16_t* blocks,
                      uint8_t* block_film, int bw, int bh) {
  parallel_for(int64_t(bw) * bh, [=] WB_HD(int64_t i) {
    const int bx = int(i % bw), by = int(i / bw);
    uint16_t m = 0;
    for (int y = by * kTopBlock; y < (by + 1) * kTopBlock && y < h; ++y)
      for (int x = bx * kTopBlock; x < (bx + 1) * kTopBlock && x < w; ++x) {
        const uint16_t t = top[int64_t(y) * w + x];
        m = t > m ? t : m;
      }
    blocks[i] = m;
    // A film sample at a point reads the columns up to one past the block of its lower corner:
    // the flag (a film or a coat near) looks one column beyond the block on every side.
    uint8_t any = 0;
    for (int y = by * kTopBlock - 1; y <= (by + 1) * kTopBlock && !any; ++y)
      for (int x = bx * kTopBlock - 1; x <= (bx + 1) * kTopBlock; ++x) {
        if (x < 0 || y < 0 || x >= w || y >= h) continue;
        const FilmColumn& f = film[int64_t(y) * w + x];
        if ((f.thin != 0 && f.height > 0.f) || f.coat_thick > 0.f) {
          any = 1;
          break;
        }
      }
    block_film[i] = any;
  });
}

void render_splat(SplatView s, ParticleOverlay p) {
  // Each particle spreads its paint volume over the cells within `radius` with a normalised
  // (1 - d^2/r^2)^2 kernel, so the layer holds exactly the particles' volume (where inside).
  parallel_for(p.n, [=] WB_HD(int64_t k) {
    const Vec3 c = p.x[k];
    const float m = p.mass[k];
    if (!(m > 0.f) || !isfinite3(c)) return;
    const float r = maxf(p.radius, 0.5f), r2 = r * r;
    const int x0 = int(floorf(c.x - r)), x1 = int(floorf(c.x + r));
    const int y0 = int(floorf(c.y - r)), y1 = int(floorf(c.y + r));
    const int z0 = int(floorf(c.z - r)), z1 = int(floorf(c.z + r));
    float wsum = 0.f;
    for (int z = z0; z <= z1; ++z)
      for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x) {
          const Vec3 d = Vec3(x + 0.5f, y + 0.5f, z + 0.5f) - c;
          const float q = 1.f - length2(d) / r2;
          if (q > 0.f) wsum += q * q;
        }
    if (!(wsum > 0.f)) return;
    const float pr = p.r ? p.r[k] : 0.f, py = p.y ? p.y[k] : 0.f, pb = p.b ? p.b[k] : 0.f;
    const float po = p.oil ? p.oil[k] : 0.f;
    for (int z = z0; z <= z1; ++z)
      for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x) {
          if (!in_splat(s, x, y, z)) continue;
          const Vec3 d = Vec3(x + 0.5f, y + 0.5f, z + 0.5f) - c;
          const float q = 1.f - length2(d) / r2;
          if (q <= 0.f) continue;
          const float dm = m * q * q / wsum;
          const int64_t i = s.index(x - s.ox, y - s.oy, z - s.oz);
          atomic_add(&s.density[i], dm);
          atomic_add(&s.pigment_r[i], dm * pr);
          atomic_add(&s.pigment_y[i], dm * py);
          atomic_add(&s.pigment_b[i], dm * pb);
          atomic_add(&s.oil[i], dm * po);
        }
  });
  // Mass-weighted sums to mean pigment and oil.
  parallel_for(s.size(), [=] WB_HD(int64_t i) {
    const float d = s.density[i];
    if (d > 0.f) {
      s.pigment_r[i] /= d;
      s.pigment_y[i] /= d;
      s.pigment_b[i] /= d;
      s.oil[i] /= d;
    }
  });
}

void render_pixels(RenderVolume v, RenderParams P, CameraBasis cam, const Vec3* ao_dirs, const int32_t* tiles,
                   int ntiles, int tile_px, int img_w, int img_h, int mode, uint32_t* rgba, float* fout) {
  const int64_t per_tile = int64_t(tile_px) * tile_px;
  const int tiles_x = (img_w + tile_px - 1) / tile_px;
  parallel_for(int64_t(ntiles) * per_tile, [=] WB_HD(int64_t i) {
    const int tile = tiles[i / per_tile];
    const int local = int(i % per_tile);
    const int px = (tile % tiles_x) * tile_px + local % tile_px;
    const int py = (tile / tiles_x) * tile_px + local / tile_px;
    if (px >= img_w || py >= img_h) return;
    const int64_t o = i;  // tile-major output: the host places the tiles
    const Vec3 start = ray_start(v, cam, px + 0.5f, py + 0.5f);
    const RayHit h = cast_ray(v, P, start, cam.dir);
    if (mode == int(RenderOutput::Shaded)) {
      const float ao = h.kind == 0 ? 1.f : ambient_occlusion(v, P, ao_dirs, h.pos, h.normal);
      rgba[o] = pack_rgba8(shade(P, h, cam.dir, ao));
    } else if (mode == int(RenderOutput::Height)) {
      fout[o * 4] = h.kind == 2 ? h.pos.z : 0.f;
    } else if (mode == int(RenderOutput::Normal)) {
      fout[o * 4] = h.normal.x;
      fout[o * 4 + 1] = h.normal.y;
      fout[o * 4 + 2] = h.normal.z;
    } else if (mode == int(RenderOutput::Pigment)) {
      fout[o * 4] = h.ryb.x;
      fout[o * 4 + 1] = h.ryb.y;
      fout[o * 4 + 2] = h.ryb.z;
      fout[o * 4 + 3] = float(h.kind);
    } else {
      fout[o * 4] = h.albedo.x;
      fout[o * 4 + 1] = h.albedo.y;
      fout[o * 4 + 2] = h.albedo.z;
    }
  });
}

}  // namespace wb::WB_BACKEND_NS
