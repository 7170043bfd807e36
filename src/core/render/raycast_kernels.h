// Ray casting of the paint volume (paper §6 "Liquid rendering"): march the density at a
// quarter-cell step, find the surface at a density threshold (refined between the two
// bracketing samples), normal from the density gradient, pigment and oil there, and gather
// pigment below the surface over an oil-dependent penetration distance. Paint too thin to reach
// the threshold is a film as thick as the paint in its column (docs/RENDERING.md "Films").
// Backend-free WB_HD code.
#pragma once
#include <math.h>

#include <cstdint>

#include "core/canvas/tile_store.h"
#include "core/canvas/window.h"
#include "core/color/ryb.h"
#include "core/math/vec.h"
#include "core/render/camera.h"
#include "core/render/render_params.h"

namespace wb {

/// Temporary density layer of splatted particles (same layout as a PaintWindowView).
struct SplatView {
  float* density;  ///< particle paint volume per cell, cell volumes
  float *pigment_r, *pigment_y, *pigment_b, *oil;  ///< mass-weighted sums, then normalised
  int nx, ny, nz, ox, oy, oz;
  WB_HD int64_t index(int x, int y, int z) const { return (int64_t(z) * ny + y) * nx + x; }
  WB_HD int64_t size() const { return int64_t(nx) * ny * nz; }
};

inline constexpr int kTopBlock = 8;  ///< cells per side of a block of the coarse top map

/// The paint of one column taken as a film lying on the canvas: its thickness is the column
/// integral of density (paint volume per unit area), its paint the density-weighted mean (for
/// thin columns, thin > 0). A thick column's paint above its densest top, too thin to reach the
/// threshold on its own (a scumble on dried paint, a glaze on a stroke), is a coat lying on it:
/// `coat` is the height of the column's paint stacked from the bottom of its top thick cell, and
/// the colour fields hold the coat's paint.
struct FilmColumn {
  float height;                    ///< sum of the column's densities, cells
  uint16_t r, y, b, oil, dryness;  ///< unorm16, as in the tiles: the film's paint, or the coat's
  uint16_t thin;                   ///< column_thinness of its densest cell, unorm16
  float coat;                      ///< thick columns: the paint stacked from the bottom of the top thick cell, cells
  float coat_thick;                ///< a coat's own paint, cells (0: no coat)
};

/// Everything the ray caster reads: tiles, the optional live window and particle splat
/// (which replace resp. add to the tiles' cells), and the column-top maps that let empty
/// space be skipped without touching the tiles.
struct RenderVolume {
  TileStoreView tiles;
  PaintWindowView win;
  int has_win;
  SplatView splat;
  int has_splat;
  const uint16_t* top;  ///< per column: 1 + highest z holding paint (and >= its film), 0 = empty
  int top_x0, top_y0, top_w, top_h;
  const uint16_t* block_top;  ///< max of `top` over kTopBlock^2 columns
  int blk_w, blk_h;
  int z_top_max;  ///< max of `top` over the map (tops count films: top >= film height)
  const FilmColumn* film;  ///< per column of the top map: the column's paint as a film
  const uint8_t* block_film;  ///< per block: 1 if a column in it or next to it is thin (has a film)
};

/// One cell's paint, as rendered (window replaces tiles; splat adds, density-weighted).
struct RenderCell {
  float density, r, y, b, oil, dryness;
};

/// 1 + highest z holding paint in column (x, y); the canvas depth where the map does not reach.
WB_HD WB_INLINE int column_top(const RenderVolume& v, int x, int y) {
  if (x < 0 || y < 0 || x >= v.tiles.width || y >= v.tiles.height) {
    // Off-canvas columns hold only splatted particles, if any.
    return v.has_splat ? v.tiles.depth : 0;
  }
  const int lx = x - v.top_x0, ly = y - v.top_y0;
  if (lx < 0 || ly < 0 || lx >= v.top_w || ly >= v.top_h) return v.tiles.depth;
  return v.top[int64_t(ly) * v.top_w + lx];
}

WB_HD WB_INLINE bool in_window(const PaintWindowView& w, int x, int y, int z) {
  return x >= w.ox && y >= w.oy && z >= w.oz && x < w.ox + w.nx && y < w.oy + w.ny && z < w.oz + w.nz;
}
WB_HD WB_INLINE bool in_splat(const SplatView& s, int x, int y, int z) {
  return x >= s.ox && y >= s.oy && z >= s.oz && x < s.ox + s.nx && y < s.oy + s.ny && z < s.oz + s.nz;
}

/// Density of cell (x, y, z), without the column-top shortcut.
WB_HD WB_INLINE float cell_density_raw(const RenderVolume& v, int x, int y, int z) {
  float d = 0.f;
  if (v.has_win && in_window(v.win, x, y, z)) {
    d = v.win.density[v.win.index(x - v.win.ox, y - v.win.oy, z - v.win.oz)];
  } else if (v.tiles.inside(x, y, z)) {
    const int32_t slot = v.tiles.slot_of_tile[(y / kTileSize) * v.tiles.tiles_x + x / kTileSize];
    if (slot >= 0) d = v.tiles.density[int64_t(slot) * v.tiles.tile_cells() + v.tiles.cell_offset(x % kTileSize, y % kTileSize, z)];
  }
  if (v.has_splat && in_splat(v.splat, x, y, z)) d += v.splat.density[v.splat.index(x - v.splat.ox, y - v.splat.oy, z - v.splat.oz)];
  return d;
}

/// Density of cell (x, y, z); cells at or above their column's top are empty without a fetch.
WB_HD WB_INLINE float cell_density(const RenderVolume& v, int x, int y, int z) {
  if (z < 0 || z >= column_top(v, x, y)) return 0.f;
  return cell_density_raw(v, x, y, z);
}

/// All fields of cell (x, y, z), without the column-top shortcut.
WB_HD WB_INLINE RenderCell cell_full_raw(const RenderVolume& v, int x, int y, int z) {
  RenderCell c{0.f, 0.f, 0.f, 0.f, 0.f, 0.f};
  if (v.has_win && in_window(v.win, x, y, z)) {
    const int64_t i = v.win.index(x - v.win.ox, y - v.win.oy, z - v.win.oz);
    c = RenderCell{v.win.density[i], v.win.pigment_r[i], v.win.pigment_y[i], v.win.pigment_b[i], v.win.oil[i],
                   v.win.dryness[i]};
  } else if (v.tiles.inside(x, y, z)) {
    const int32_t slot = v.tiles.slot_of_tile[(y / kTileSize) * v.tiles.tiles_x + x / kTileSize];
    if (slot >= 0) {
      const int64_t a = int64_t(slot) * v.tiles.tile_cells() + v.tiles.cell_offset(x % kTileSize, y % kTileSize, z);
      c = RenderCell{v.tiles.density[a], decode_unorm16(v.tiles.pigment_r[a]), decode_unorm16(v.tiles.pigment_y[a]),
                     decode_unorm16(v.tiles.pigment_b[a]), decode_unorm16(v.tiles.oil[a]),
                     v.tiles.dryness_at(slot, a)};
    }
  }
  if (v.has_splat && in_splat(v.splat, x, y, z)) {
    // Particles are wet paint: their density adds, their pigment and oil mix by density.
    const int64_t i = v.splat.index(x - v.splat.ox, y - v.splat.oy, z - v.splat.oz);
    const float ds = v.splat.density[i];
    if (ds > 0.f) {
      const float dt = c.density + ds;
      const float wg = c.density / dt, wsp = ds / dt;
      c.r = c.r * wg + v.splat.pigment_r[i] * wsp;
      c.y = c.y * wg + v.splat.pigment_y[i] * wsp;
      c.b = c.b * wg + v.splat.pigment_b[i] * wsp;
      c.oil = c.oil * wg + v.splat.oil[i] * wsp;
      c.dryness = c.dryness * wg;
      c.density = dt;
    }
  }
  return c;
}

/// All fields of cell (x, y, z); cells at or above their column's top are empty without a fetch.
WB_HD WB_INLINE RenderCell cell_full(const RenderVolume& v, int x, int y, int z) {
  if (z < 0 || z >= column_top(v, x, y)) return RenderCell{0.f, 0.f, 0.f, 0.f, 0.f, 0.f};
  return cell_full_raw(v, x, y, z);
}

/// Trilinear density at a continuous point (cell centres at integer + 0.5); corners with
/// zero weight are not fetched, so axis-aligned rays through cell centres cost two fetches.
WB_HD WB_INLINE float sample_density(const RenderVolume& v, Vec3 p) {
  const float fx = p.x - 0.5f, fy = p.y - 0.5f, fz = p.z - 0.5f;
  const float flx = floorf(fx), fly = floorf(fy), flz = floorf(fz);
  const int ix = int(flx), iy = int(fly), iz = int(flz);
  const float ax = fx - flx, ay = fy - fly, az = fz - flz;
  float s = 0.f;
  for (int c = 0; c < 8; ++c) {
    const float wx = (c & 1) ? ax : 1.f - ax;
    const float wy = (c & 2) ? ay : 1.f - ay;
    const float wz = (c & 4) ? az : 1.f - az;
    const float w = wx * wy * wz;
    if (w <= 0.f) continue;
    s += w * cell_density(v, ix + (c & 1), iy + ((c >> 1) & 1), iz + ((c >> 2) & 1));
  }
  return s;
}

/// Density-weighted trilinear paint at a point: pigment, oil and dryness of the paint there
/// (empty cells have no pigment, which would otherwise read as white).
struct PaintSample {
  Vec3 ryb;
  float oil, dryness, density;
};
WB_HD WB_INLINE PaintSample sample_paint(const RenderVolume& v, Vec3 p) {
  const float fx = p.x - 0.5f, fy = p.y - 0.5f, fz = p.z - 0.5f;
  const float flx = floorf(fx), fly = floorf(fy), flz = floorf(fz);
  const int ix = int(flx), iy = int(fly), iz = int(flz);
  const float ax = fx - flx, ay = fy - fly, az = fz - flz;
  PaintSample s{Vec3(0.f, 0.f, 0.f), 0.f, 0.f, 0.f};
  float wsum = 0.f;
  for (int c = 0; c < 8; ++c) {
    const float w = ((c & 1) ? ax : 1.f - ax) * ((c & 2) ? ay : 1.f - ay) * ((c & 4) ? az : 1.f - az);
    if (w <= 0.f) continue;
    const RenderCell k = cell_full(v, ix + (c & 1), iy + ((c >> 1) & 1), iz + ((c >> 2) & 1));
    s.density += w * k.density;
    const float wd = w * k.density;
    if (wd <= 0.f) continue;
    s.ryb += Vec3(k.r, k.y, k.b) * wd;
    s.oil += k.oil * wd;
    s.dryness += k.dryness * wd;
    wsum += wd;
  }
  if (wsum > 0.f) {
    s.ryb = s.ryb / wsum;
    s.oil /= wsum;
    s.dryness /= wsum;
  }
  return s;
}

// --- films ---------------------------------------------------------------------------------
// Paint too thin to reach the threshold lies on the canvas as a film: the column's paint, as
// thick as the column integral F of density (paint volume per unit area). Its solid {z <= F} is
// the level set of film_density. A column is thin while its densest cell stays below the
// threshold; from there to threshold + film_fade its surface density goes over from the film's
// to the volume's, so the film turns into the threshold surface of thick paint without a jump.

/// Film record of column (x, y); none off the map (no ray of the rendered tiles samples there).
WB_HD WB_INLINE FilmColumn column_film(const RenderVolume& v, int x, int y) {
  const int lx = x - v.top_x0, ly = y - v.top_y0;
  if (!v.film || lx < 0 || ly < 0 || lx >= v.top_w || ly >= v.top_h) return FilmColumn{0.f, 0, 0, 0, 0, 0, 0, 0.f, 0.f};
  return v.film[int64_t(ly) * v.top_w + lx];
}

/// How thin a column is for the surface: 1 while its densest cell is below the threshold, 0 from
/// threshold + film_fade up, linear between.
WB_HD WB_INLINE float column_thinness(const RenderParams& P, float max_density) {
  return clampf((P.threshold + P.film_fade - max_density) / P.film_fade, 0.f, 1.f);
}

/// The film at a canvas point, bilinear between column centres (integer + 0.5).
struct FilmSample {
  float height;  ///< film height F, cells
  float thin;    ///< the columns' thinness, weighted by their paint (bare columns do not vote)
  PaintSample paint;  ///< the columns' mean paint, weighted by their paint (when asked for)
  /// Where a column near holds a coat: the height of the paint stacked in the columns (a thick
  /// column's coat top, a thin one's film, 0 bare), and the coats' paint (when asked for).
  float coat;
  PaintSample coat_paint;  ///< density: the coats' own thickness, cells
};
WB_HD WB_INLINE FilmSample film_at(const RenderVolume& v, float x, float y, bool with_paint) {
  const float fx = x - 0.5f, fy = y - 0.5f;
  const float flx = floorf(fx), fly = floorf(fy);
  const int ix = int(flx), iy = int(fly);
  const float ax = fx - flx, ay = fy - fly;
  FilmSample f{0.f, 0.f, PaintSample{Vec3(0.f, 0.f, 0.f), 0.f, 0.f, 0.f}, 0.f, PaintSample{Vec3(0.f, 0.f, 0.f), 0.f, 0.f, 0.f}};
  // Thick paint and bare canvas all around (the block map says so): no film, thin = 0, exactly
  // what the four columns would give. Blocks off the map are not trusted.
  if (v.block_film) {
    const int lx = ix - v.top_x0, ly = iy - v.top_y0;
    if (lx >= 0 && ly >= 0) {
      const int bx = lx / kTopBlock, by = ly / kTopBlock;
      if (bx < v.blk_w && by < v.blk_h && !v.block_film[by * v.blk_w + bx]) return f;
    }
  }
  float stack = 0.f, wc = 0.f;
  bool coated = false;
  for (int c = 0; c < 4; ++c) {
    const float w = ((c & 1) ? ax : 1.f - ax) * ((c & 2) ? ay : 1.f - ay);
    if (w <= 0.f) continue;
    const FilmColumn k = column_film(v, ix + (c & 1), iy + (c >> 1));
    stack += w * (k.coat > 0.f ? k.coat : (k.thin != 0 ? k.height : 0.f));
    if (k.coat_thick > 0.f) {
      coated = true;
      wc += w;
      f.coat_paint.density += k.coat_thick * w;
      if (with_paint) {
        f.coat_paint.ryb += Vec3(decode_unorm16(k.r), decode_unorm16(k.y), decode_unorm16(k.b)) * w;
        f.coat_paint.oil += decode_unorm16(k.oil) * w;
        f.coat_paint.dryness += decode_unorm16(k.dryness) * w;
      }
    }
    const float wd = w * k.height;
    if (!(wd > 0.f)) continue;
    f.height += wd;
    const float wt = wd * decode_unorm16(k.thin);
    f.thin += wt;
    if (with_paint && wt > 0.f) {  // the film's paint is its thin columns' (thick ones bring theirs in the volume)
      f.paint.ryb += Vec3(decode_unorm16(k.r), decode_unorm16(k.y), decode_unorm16(k.b)) * wt;
      f.paint.oil += decode_unorm16(k.oil) * wt;
      f.paint.dryness += decode_unorm16(k.dryness) * wt;
    }
  }
  if (f.height > 0.f) {
    if (f.thin > 0.f) {  // divided, not multiplied by 1 / thin: the weights may be subnormal
      f.paint.ryb = f.paint.ryb / f.thin;
      f.paint.oil /= f.thin;
      f.paint.dryness /= f.thin;
    }
    f.thin /= f.height;
    f.paint.density = f.height;
  }  // no paint in these columns: thin = 0 leaves the volume's density (of paint off the map)
  if (coated) {
    f.coat = stack;
    f.coat_paint.density /= wc;
    if (with_paint) {
      f.coat_paint.ryb = f.coat_paint.ryb / wc;
      f.coat_paint.oil /= wc;
      f.coat_paint.dryness /= wc;
    }
  }
  return f;
}

/// Film height at a canvas point, cells: the one definition of the film that the image, the
/// height, normal and albedo maps and the tile cache all go through.
WB_HD WB_INLINE float film_height(const RenderVolume& v, float x, float y) { return film_at(v, x, y, false).height; }

/// Density of the film solid at height z over a film F thick: the threshold at z = F, changing by
/// one per cell in z as across the top of a layer of full cells; 0 where there is no film.
WB_HD WB_INLINE float film_density(const RenderParams& P, float F, float z) {
  return F > 0.f ? clampf(P.threshold + F - z, 0.f, 1.f) : 0.f;
}

/// Density as the surface sees it: the film's where the paint is thin, the volume's where it is
/// thick, blended by thinness between. Films lie below z_top_max (tops count them).
/// A coat lies on thick paint: the solid is the volume's or the paint stacked in the columns,
/// whichever is higher (where nothing is above the thick top, the stack is at or below the
/// volume's threshold surface and changes nothing).
WB_HD WB_INLINE float surface_density(const RenderVolume& v, const RenderParams& P, Vec3 p) {
  if (p.z >= float(v.z_top_max) + P.threshold) return sample_density(v, p);
  const FilmSample f = film_at(v, p.x, p.y, false);
  const float df = film_density(P, f.height, p.z);
  if (f.thin >= 1.f) return df;
  const float d = sample_density(v, p);
  const float dv = f.thin <= 0.f ? d : f.thin * df + (1.f - f.thin) * d;
  return f.coat > 0.f ? maxf(dv, film_density(P, f.coat, p.z)) : dv;
}

/// Paint of the coat where it is what the surface sees (its density over the volume's).
WB_HD WB_INLINE PaintSample with_coat(const RenderParams& P, const FilmSample& f, Vec3 p, PaintSample k) {
  if (!(f.coat > 0.f)) return k;
  const float dc = film_density(P, f.coat, p.z);
  if (!(dc > k.density)) return k;
  const float wk = k.density, wc = dc - k.density;
  PaintSample out;
  out.ryb = (k.ryb * wk + f.coat_paint.ryb * wc) / dc;
  out.oil = (k.oil * wk + f.coat_paint.oil * wc) / dc;
  out.dryness = (k.dryness * wk + f.coat_paint.dryness * wc) / dc;
  out.density = dc;
  return out;
}

/// Paint as the surface sees it: the film's and the volume's paint mixed by their shares of
/// surface_density (density = that), and a coat's where it lies on thick paint.
WB_HD WB_INLINE PaintSample surface_paint(const RenderVolume& v, const RenderParams& P, Vec3 p) {
  if (p.z >= float(v.z_top_max) + P.threshold) return sample_paint(v, p);
  const FilmSample f = film_at(v, p.x, p.y, true);
  if (f.thin <= 0.f) return with_coat(P, f, p, sample_paint(v, p));
  PaintSample k = f.paint;
  const float wf = f.thin * film_density(P, f.height, p.z);
  k.density = wf;
  if (f.thin >= 1.f) return k;
  const PaintSample s = sample_paint(v, p);
  const float wv = (1.f - f.thin) * s.density, wt = wf + wv;
  if (!(wt > 0.f)) return PaintSample{Vec3(0.f, 0.f, 0.f), 0.f, 0.f, 0.f};
  k.ryb = (f.paint.ryb * wf + s.ryb * wv) / wt;
  k.oil = (f.paint.oil * wf + s.oil * wv) / wt;
  k.dryness = (f.paint.dryness * wf + s.dryness * wv) / wt;
  k.density = wt;
  return with_coat(P, f, p, k);
}

/// Share of the ground that paint F cells thick hides (Beer–Lambert): the ground shows through
/// as 50^(-F / film_hiding), 2 % at the hiding thickness ("complete hiding", contrast ratio 0.98).
WB_HD WB_INLINE float film_cover(const RenderParams& P, float F) {
  return F > 0.f ? 1.f - expf(-3.91202301f * F / P.film_hiding) : 0.f;  // ln 50
}

/// Normal of the film's height field, (-dF/dx, -dF/dy, 1) normalised, by central differences:
/// a film tilts only as much as its thickness changes, however thin it is.
WB_HD WB_INLINE Vec3 film_normal(const RenderVolume& v, Vec3 p, float e) {
  const float gx = film_height(v, p.x + e, p.y) - film_height(v, p.x - e, p.y);
  const float gy = film_height(v, p.x, p.y + e) - film_height(v, p.x, p.y - e);
  return normalize(Vec3(-gx, -gy, 2.f * e));
}

/// Surface normal n = -grad(rho)/|grad(rho)| by central differences of the surface density.
WB_HD WB_INLINE Vec3 density_normal(const RenderVolume& v, const RenderParams& P, Vec3 p, float e) {
  const Vec3 g((surface_density(v, P, p + Vec3(e, 0, 0)) - surface_density(v, P, p - Vec3(e, 0, 0))),
               (surface_density(v, P, p + Vec3(0, e, 0)) - surface_density(v, P, p - Vec3(0, e, 0))),
               (surface_density(v, P, p + Vec3(0, 0, e)) - surface_density(v, P, p - Vec3(0, 0, e))));
  return normalize_or(-g, Vec3(0.f, 0.f, 1.f));
}

/// What one ray found: the surface point, its normal, the blended pigment and the paint state.
struct RayHit {
  int kind;     ///< 0 = missed the canvas (background), 1 = bare canvas, 2 = paint surface
  Vec3 pos;     ///< hit point, cells
  Vec3 normal;
  Vec3 albedo;  ///< unlit RGB after blending the pigment samples below the surface
  Vec3 ryb;     ///< the pigment behind `albedo` (RYB; the paper's where the ray meets bare canvas)
  float dryness;
  float cover;  ///< share of the ground the paint hides (film_cover); 0 off the paint
};

/// The ray of pixel (i, j) starts at height z_start above the canvas.
WB_HD WB_INLINE void pixel_ray(const CameraBasis& cam, float i, float j, Vec3& ground, Vec3& dir) {
  ground = cam.p00 + cam.du * i + cam.dv * j;  // point of the image plane through the canvas centre
  dir = cam.dir;
}

/// Pigment gathered below the surface (§6): samples every penetration_step within
/// L = oil * penetration_per_oil along the ray, tent-weighted w = 1 - s/L so that the surface
/// counts most; samples inside a film see its paint, samples below the canvas the primed canvas.
/// The blend is linear in RYB (glazing mixes pigment like the colour model does); the caller
/// converts it to RGB once.
WB_HD WB_INLINE Vec3 gather_pigment(const RenderVolume& v, const RenderParams& P, Vec3 hit, Vec3 dir, Vec3 n,
                                    PaintSample surf) {
  // The oil is a fraction: its domain keeps the walk finite whatever a cell holds.
  const float L = clampf(surf.oil, 0.f, 1.f) * P.penetration_per_oil;
  if (!(L > P.penetration_step)) return surf.ryb;
  Vec3 acc = surf.ryb;
  float wsum = 1.f;
  for (float s = P.penetration_step; s < L; s += P.penetration_step) {
    const float w = 1.f - s / L;
    const Vec3 q = hit + dir * s;
    if (q.z <= 0.f) {
      acc += P.paper_ryb * w;
      wsum += w;
      continue;
    }
    const PaintSample k = surface_paint(v, P, q);
    if (k.density < P.threshold) continue;  // an air gap along the ray: nothing to see there
    acc += k.ryb * w;
    wsum += w;
  }
  return acc / wsum;
}

/// Casts one ray: march the surface density from `start` along `dir` at P.step until it reaches
/// the threshold, the last sample on the canvas plane z = 0 (where any film reaches it).
WB_HD WB_INLINE RayHit cast_ray(const RenderVolume& v, const RenderParams& P, Vec3 start, Vec3 dir) {
  RayHit h;
  h.kind = 0;
  h.normal = Vec3(0.f, 0.f, 1.f);
  h.albedo = P.background_rgb;
  h.ryb = P.paper_ryb;
  h.dryness = 1.f;
  h.cover = 0.f;
  const float t_end = start.z / -dir.z;  // where the ray meets z = 0 (dir.z < 0)
  float t_prev = 0.f, d_prev = surface_density(v, P, start);
  bool found = d_prev >= P.threshold;
  float t_hit = 0.f;
  if (!found) {
    for (float t = P.step;; t += P.step) {
      const bool last = t >= t_end;
      if (last) t = t_end;
      const float d = surface_density(v, P, start + dir * t);
      if (d >= P.threshold) {
        // Refine between the bracketing samples: linear guess, then two secant/bisection steps.
        float ta = t_prev, da = d_prev, tb = t, db = d;
        float tm = ta;
        for (int k = 0; k < 3; ++k) {
          tm = ta + (tb - ta) * clampf((P.threshold - da) / maxf(db - da, 1e-6f), 0.f, 1.f);
          if (k == 2) break;
          const float dm = surface_density(v, P, start + dir * tm);
          if (dm >= P.threshold) {
            tb = tm;
            db = dm;
          } else {
            ta = tm;
            da = dm;
          }
        }
        t_hit = tm;
        found = true;
        break;
      }
      if (last) break;
      t_prev = t;
      d_prev = d;
    }
  }
  if (found) {
    h.kind = 2;
    h.pos = start + dir * t_hit;
    // The normal of the film where the paint is thin, of the density where it is thick.
    const FilmSample f = film_at(v, h.pos.x, h.pos.y, false);
    if (f.thin >= 1.f) {
      h.normal = film_normal(v, h.pos, P.normal_eps);
    } else if (f.thin <= 0.f) {
      h.normal = density_normal(v, P, h.pos, P.normal_eps);
    } else {
      h.normal = normalize(lerp(density_normal(v, P, h.pos, P.normal_eps), film_normal(v, h.pos, P.normal_eps), f.thin));
    }
    // Pigment just inside the surface.
    const PaintSample surf = surface_paint(v, P, h.pos - h.normal * 0.5f);
    h.dryness = surf.dryness;
    h.ryb = gather_pigment(v, P, h.pos, dir, h.normal, surf);
    h.albedo = ryb_to_rgb(h.ryb);
    // A thin film lets some of the ground through; thick paint hides it.
    h.cover = f.thin * film_cover(P, f.height) + (1.f - f.thin);
    if (h.cover < 1.f) {
      h.albedo = lerp(P.paper_rgb, h.albedo, h.cover);
      h.ryb = lerp(P.paper_ryb, h.ryb, h.cover);
    }
    // A coat on dried paint hides the paint under it as a film hides the canvas (film_cover of
    // its own thickness), wherever the ray meets the coat rather than the paint beside it.
    const float ct = f.coat_paint.density;
    if (f.coat > 0.f && ct > 0.f && h.pos.z > f.coat - ct) {
      const FilmSample fc = film_at(v, h.pos.x, h.pos.y, true);
      const Vec3 under = sample_paint(v, Vec3(h.pos.x, h.pos.y, maxf(f.coat - ct - 0.5f, 0.f))).ryb;
      const float cov = film_cover(P, ct);
      h.ryb = lerp(under, fc.coat_paint.ryb, cov);
      h.albedo = lerp(ryb_to_rgb(under), ryb_to_rgb(fc.coat_paint.ryb), cov);
    }
    return h;
  }
  const Vec3 g = start + dir * t_end;
  if (g.x < 0.f || g.y < 0.f || g.x >= float(v.tiles.width) || g.y >= float(v.tiles.height)) return h;
  h.kind = 1;  // bare canvas: no paint in these columns
  h.pos = Vec3(g.x, g.y, 0.f);
  h.normal = Vec3(0.f, 0.f, 1.f);
  h.albedo = P.paper_rgb;
  return h;
}

/// Starting point of pixel (i, j)'s ray: just above the highest paint it can meet.
WB_HD WB_INLINE Vec3 ray_start(const RenderVolume& v, const CameraBasis& cam, float i, float j) {
  Vec3 g, dir;
  pixel_ray(cam, i, j, g, dir);
  int ztop = v.z_top_max;
  if (cam.top) {
    // Straight down: only the (up to four) columns the trilinear sample touches matter.
    // Straight down: only the columns the trilinear sample gives weight to matter (one at
    // pixel centres on cell centres, up to four otherwise).
    const float fx = g.x - 0.5f, fy = g.y - 0.5f;
    const int ix = int(floorf(fx)), iy = int(floorf(fy));
    const bool wx = fx - floorf(fx) > 0.f, wy = fy - floorf(fy) > 0.f;
    ztop = 0;
    for (int c = 0; c < 4; ++c) {
      if (((c & 1) && !wx) || ((c & 2) && !wy)) continue;
      const int t = column_top(v, ix + (c & 1), iy + (c >> 1));
      ztop = t > ztop ? t : ztop;
    }
  }
  const float z0 = float(ztop) + 0.5f;
  // Move back along -dir from the plane point g until height z0.
  const float t = (z0 - g.z) / -dir.z;
  return g - dir * t;
}

/// Blinn-Phong shading of a hit: ambient (times AO) + diffuse + specular fading with dryness.
WB_HD WB_INLINE Vec3 shade(const RenderParams& P, const RayHit& h, Vec3 dir, float ao) {
  if (h.kind == 0) return P.background_rgb;
  const Vec3 L = P.light_dir;  // normalised on the host
  const float ndl = maxf(dot(h.normal, L), 0.f);
  Vec3 c = h.albedo * (P.ambient * ao + P.diffuse * ndl);
  if (h.kind == 2 && P.specular > 0.f) {
    const Vec3 H = normalize(L - dir);
    const float ndh = maxf(dot(h.normal, H), 0.f);
    const float wet = 1.f - clampf(h.dryness, 0.f, 1.f);
    // The thinnest films shine only as much as they cover, so they fade into the bare canvas.
    c += Vec3(1.f, 1.f, 1.f) * (P.specular * wet * h.cover * powf(ndh, P.shininess) * (ndl > 0.f ? 1.f : 0.f));
  }
  return Vec3(clampf(c.x, 0.f, 1.f), clampf(c.y, 0.f, 1.f), clampf(c.z, 0.f, 1.f));
}

WB_HD WB_INLINE uint32_t pack_rgba8(Vec3 c) {
  const uint32_t r = uint32_t(clampf(c.x, 0.f, 1.f) * 255.f + 0.5f);
  const uint32_t g = uint32_t(clampf(c.y, 0.f, 1.f) * 255.f + 0.5f);
  const uint32_t b = uint32_t(clampf(c.z, 0.f, 1.f) * 255.f + 0.5f);
  return r | (g << 8) | (b << 16) | (255u << 24);
}

}  // namespace wb
