// Bristle <-> particle liquid transfer (paper §5.1, Eq. 12-14, Figures 9-10): the capacity of a
// bristle sample from the bristle density psi (Eq. 12) and the spherical cap cut off by a
// nearby surface (Eq. 13), absorption with colour mixing (Eq. 14), colour bleeding of
// saturated samples, and emission in the lower hemisphere. Colours mix by Algorithm 2.
#pragma once
#include <cstdint>

#include "core/color/ryb.h"
#include "core/exec/hd.h"
#include "core/math/vec.h"
#include "core/transfer/grid_particle_kernels.h"

namespace wb {

inline constexpr float kTransferPi = 3.14159265358979f;

/// Eq. 12: potential capacity M'_j = max((1 - mu psi(x_j)) M_max, M_min), kg.
WB_HD WB_INLINE float potential_capacity(float psi, float mu, float M_max, float M_min) {
  return maxf((1.f - mu * psi) * M_max, M_min);
}

/// Radius of the load sphere, R_j = (3 M'_j / (4 pi rho0))^(1/3) (§5.1), in cells;
/// cell_mass = rho0 cell^3 converts kg to cell volumes.
WB_HD WB_INLINE float load_radius(float M_prime, float cell_mass) {
  return cbrtf(3.f * maxf(M_prime, 0.f) / (4.f * kTransferPi * cell_mass));
}

/// Volume of the spherical cap of height h cut from a sphere of radius R: pi h^2 (R - h/3).
WB_HD WB_INLINE float spherical_cap_volume(float R, float h) { return kTransferPi * h * h * (R - h / 3.f); }

/// Eq. 13: M_j = M'_j - rho0 pi (R_j - r_j)^2 (R_j - (R_j - r_j)/3), r_j clamped to [0, R_j];
/// lengths in cells, cell_mass = rho0 cell^3. Between M'_j (r = R) and M'_j / 2 (r = 0).
WB_HD WB_INLINE float surface_capacity(float M_prime, float R, float r, float cell_mass) {
  const float h = R - clampf(r, 0.f, R);
  return maxf(M_prime - cell_mass * spherical_cap_volume(R, h), 0.f);
}

/// r_j of Eq. 13: distance from the sample at x (canvas cells) to the nearest surface below it,
/// clamped to [0, R]: the canvas floor at floor_z, or the first point of a downward march
/// (steps of `step` cells) where the window density reaches `threshold` (grid liquid or dried
/// paint; linear between the last two points). The brush works from above, so the surfaces
/// that cut its load lie below it: the march is along -z only.
///
/// With a dryness field (dryness.f set), only dried paint (dryness >= dry_threshold) is a
/// surface: the solid below the sample, which the swept contact slides over.
WB_HD WB_INLINE float surface_distance(Vec3 x, float R, float floor_z, const CellField& density, float threshold,
                                       float step, const CellField& dryness = CellField{}, float dry_threshold = 0.f) {
  float r = x.z - floor_z;
  // Density that counts as surface at p: all of it, or only the dried paint's.
  const auto surface = [&](Vec3 p) {
    return dryness.f == nullptr ? cell_field_at(density, p) : dried_density_at(density, dryness, dry_threshold, p);
  };
  if (density.f != nullptr && r > 0.f) {
    float prev = surface(x);
    if (prev >= threshold) return 0.f;
    float s_prev = 0.f;
    const float reach = minf(R, r);
    for (int it = 0; it < 4096 && s_prev < reach; ++it) {
      const float s = minf(s_prev + step, reach);
      const float val = surface(Vec3(x.x, x.y, x.z - s));
      if (val >= threshold) {
        const float t = val > prev ? (threshold - prev) / (val - prev) : 1.f;
        r = minf(r, s_prev + (s - s_prev) * clampf(t, 0.f, 1.f));
        break;
      }
      prev = val;
      s_prev = s;
    }
  }
  return clampf(r, 0.f, R);
}

/// Colour of a batch mix: the sample's own pigment c_self with weight w_self, plus a batch given
/// by its sums sum_w, sum_w c and sum_w brightness. Linear in RYB, then rescaled to the weighted
/// mean brightness: the many-colour Algorithm 2 (= color_mix_n over every member), which Eq. 14
/// applies when several particles join one sample in a step.
WB_HD WB_INLINE Vec3 mix_batch(Vec3 c_self, float w_self, Vec3 sum_wc, float sum_wb, float sum_w) {
  const float ws = maxf(w_self, 0.f);
  const float w = ws + sum_w;
  if (!(w > 0.f)) return c_self;
  const Vec3 lin = (c_self * ws + sum_wc) / w;
  const float b = (ws * pigment_brightness(c_self) + sum_wb) / w;
  return rescale_to_brightness(lin, b);
}

/// Edge conductance of the wicking flow between samples a and b of one bristle, kg per unit
/// saturation: (k dt + k_slide l) min(M_a, M_b), l the distance the edge slid over the step
/// (capillary flow per second plus drag pumping per cell slid; docs/TRANSFER.md "Wicking").
WB_HD WB_INLINE float wick_conductance(float k_dt, float k_slide, float slid, float Mp_a, float Mp_b) {
  return (k_dt + k_slide * slid) * minf(Mp_a, Mp_b);
}

/// Distance a sample slid along the canvas over a step, cells: its velocity's xy part times dt.
WB_HD WB_INLINE float slid_distance(Vec3 v, float dt) { return sqrtf(v.x * v.x + v.y * v.y) * dt; }

/// Colour bleeding (§5.1): a particle of mass m_k within R_j of a sample that does not absorb it
/// exchanges e = bleed min(m_k, m_j) of colour with the sample; masses are unchanged.
WB_HD WB_INLINE float bleed_weight(float bleed, float m_k, float m_j) { return bleed * minf(m_k, m_j); }

/// Emission plan (§5.1): when m > (1 + eps) M, n = min(limit, ceil((m - M) / emit_mass))
/// particles of (m - M) / n each, capped at emit_mass: the load falls to M in one step or by
/// limit * emit_mass per step. Returns n and sets mass_each.
WB_HD WB_INLINE int emission_count(float m, float M, float eps, float emit_mass, int limit, float& mass_each) {
  mass_each = 0.f;
  if (limit <= 0 || !(m > (1.f + eps) * M) || !(emit_mass > 0.f)) return 0;
  const float excess = m - M;
  const float want = ceilf(excess / emit_mass);
  if (want >= float(limit)) {
    mass_each = minf(emit_mass, excess / float(limit));
    return limit;
  }
  const int n = want < 1.f ? 1 : int(want);
  mass_each = excess / float(n);
  return n;
}

/// Area of the circular segment cut from a disc of radius R by a chord at distance r from its
/// centre, cells^2: R^2 acos(r/R) - r sqrt(R^2 - r^2); 0 when r >= R.
WB_HD WB_INLINE float segment_area(float R, float r) {
  if (!(R > 0.f) || !(r < R)) return 0.f;
  const float q = clampf(r / R, -1.f, 1.f);
  return R * R * acosf(q) - r * R * sqrtf(maxf(1.f - q * q, 0.f));
}

/// Paint a sample leaves on the surface it slides over during a step, kg (docs/TRANSFER.md,
/// "Swept contact"; beyond the paper). The surface r cells below the sample cuts the cap off the
/// sphere of its paint (radius R_m of its load m, as R_j of §5.1 is of M'_j), the geometry of
/// Eq. 13. Sliding `travel` cells over the surface, the sample sweeps a slab of paint of that
/// cap's cross-section, the segment A(R_m, r); the film splits between bristle and surface and
/// `split` of it stays on the surface. Proportional to the distance slid, not to the steps taken;
/// a lightly loaded sample whose paint does not reach the surface leaves nothing (dry brush).
///
/// Film splitting goes both ways: wet paint already on the surface splits too, and (1 - split) of
/// what the sample sweeps of it goes with the bristle. That is the absorption's film_pickup, on
/// the film's particles; here only the deposit. Per cell slid a full, pressed sample lays
/// split A(R, 0) and takes back (1 - split) 2R f of a film f thick, so the film it leaves tends to
/// the thickness where the two balance, split pi R / (4 (1 - split)) (0.59 cells at split 0.5),
/// however many bristles or samples pass.
/// This is what the sample's paint would leave if its load stayed m all along the path; the
/// wick solve takes it from the bristle implicitly (sigma = deposit / m, a sink in
/// transfer_wick), so a fast stroke draws paint down the bristle within the step instead of
/// emptying the contact sample and waiting for the next one.
WB_HD WB_INLINE float swept_deposit(float m, float r, float travel, float split, float cell_mass) {
  if (!(m > 0.f) || !(travel > 0.f)) return 0.f;
  return split * segment_area(load_radius(m, cell_mass), r) * cell_mass * travel;
}

/// Share of a film particle's chord that a touching sample's reach swept over this step
/// (docs/TRANSFER.md "Swept contact"). The sample's reach, a sphere of radius R, cuts the
/// particle's plane (dz below or above the sample) in a disc of radius Rp; in the canvas plane
/// the sample slid along the path from x - d to x relative to the particle (d its velocity less
/// the particle's, times dt). The particle is under the disc over a chord of 2c of that line,
/// c^2 = Rp^2 - e^2 at a distance e from it; the share is the part of the chord the step's path
/// covers, in [0, 1]: the steps of one pass over the particle add to 1 however they cut the pass,
/// and a sample resting on the film, or carrying it along, sweeps none of it.
/// `q` is the particle less the sample's end point, in the canvas plane, and dz their height difference.
WB_HD WB_INLINE float swept_chord_share(float qx, float qy, float dz, float dx, float dy, float R) {
  const float Rp2 = R * R - dz * dz;
  const float len = sqrtf(dx * dx + dy * dy);
  if (!(Rp2 > 0.f) || !(len > 1e-6f)) return 0.f;
  // Along the path from its start (x - d): the particle at t, its distance e from the line.
  const float ux = dx / len, uy = dy / len;
  const float sx = qx + dx, sy = qy + dy;
  const float t = sx * ux + sy * uy;
  const float e2 = maxf(sx * sx + sy * sy - t * t, 0.f);
  if (!(e2 < Rp2)) return 0.f;
  const float c = sqrtf(Rp2 - e2);
  // The chord [t - c, t + c] against the path [0, len]: their overlap, at most the chord.
  const float covered = minf(t + c, len) - maxf(t - c, 0.f);
  return maxf(covered, 0.f) / (2.f * c);
}

/// Chance that a touching sample takes a particle of the surface's film whole this step, having
/// swept `share` of the particle's chord (swept_chord_share): the pick-up side of swept_deposit.
/// The film a bristle slides over splits, and (1 - split) of it goes with the bristle: the
/// chance of surviving the whole pass is split, and one of the step's part of the pass
/// split^share, so the steps of a pass take 1 - split in all whatever the pen's speed and the step.
WB_HD WB_INLINE float film_pickup(float split, float share) {
  if (!(share > 0.f) || !(split < 1.f)) return 0.f;
  if (!(split > 0.f)) return 1.f;
  return 1.f - powf(split, minf(share, 1.f));
}

/// Share of its single-pass deposit a sample leaves when k samples sweep the same canvas column
/// in one step (docs/TRANSFER.md "Swept contact"). Each pass moves the film f towards the
/// balance thickness f* by split of the difference (swept_deposit per unit track area:
/// f <- (1 - split) f + split f*), so k passes in sequence leave 1 - (1 - split)^k of the gap
/// to f*, where k independent passes would each add split of it: the k samples share the
/// sequence's deposit, (1 - (1 - split)^k) / (k split) each. Within a step the samples cannot
/// see each other's paint (it reaches the fields the next step); across steps the film does.
WB_HD WB_INLINE float pass_share(float k, float split) {
  if (!(k > 1.f) || !(split > 0.f)) return 1.f;
  if (!(split < 1.f)) return 1.f / k;
  return (1.f - powf(1.f - split, k)) / (k * split);
}

/// The canvas columns a sample's path over the step crosses (from x - v_t dt to x), a point per
/// cell slid; calls f(ix, iy) for each column of the window [0, nx) x [0, ny) it enters, once
/// per run of points in the same column.
template <class F>
WB_HD WB_INLINE void for_path_columns(Vec3 x, Vec3 v, float dt, int ox, int oy, int nx, int ny, F&& f) {
  const Vec3 vt(v.x, v.y, 0.f);
  const float travel = sqrtf(v.x * v.x + v.y * v.y) * dt;
  const int n = travel > 1.f ? int(ceilf(travel)) : 1;
  int px = -1, py = -1;
  for (int i = 0; i < n; ++i) {
    const Vec3 p = x - vt * (dt * (1.f - (float(i) + 0.5f) / float(n)));
    const int ix = int(floorf(p.x)) - ox, iy = int(floorf(p.y)) - oy;
    if (ix == px && iy == py) continue;
    px = ix, py = iy;
    if (ix >= 0 && iy >= 0 && ix < nx && iy < ny) f(ix, iy);
  }
}

/// Particles that carry a swept deposit: mass_each at most emit_mass, at most two per cell slid
/// (the trail is laid at the grid's resolution whatever the speed). A deposit below a thousandth
/// of an emitted particle (1e-12 kg, 1e-4 of a cell) stays on the bristle: it would only breed
/// particles lighter than the float load it leaves can even register. Returns n, sets mass_each.
WB_HD WB_INLINE int swept_count(float deposit, float travel, float emit_mass, float& mass_each) {
  mass_each = 0.f;
  if (!(deposit >= 1e-3f * emit_mass) || !(emit_mass > 0.f)) return 0;
  const float most = fmaxf(1.f, ceilf(2.f * travel));
  const float n = fminf(fmaxf(ceilf(deposit / emit_mass), 1.f), most);
  mass_each = deposit / n;
  return int(n);
}

/// Position of the i-th of n particles of a swept deposit: spread along the sample's path over
/// the step, from x_j - v_t dt to x_j (v_t: the velocity along the surface), stratified with a
/// per-sample, per-step `jitter` in [0, 1) (at u = (i + jitter) / n: with a fixed offset a sample
/// that leaves one particle a step leaves it at the same point of every step's path, and the
/// stroke is a chain of beads at the step period), across the cap's
/// footprint (half-width a = sqrt(R_m^2 - r^2)) by pattern point `slot`, a quarter cell above
/// the surface r_j below the sample (never below the canvas), and over the active window's
/// `columns`: particles live only there (a path that began outside the window, which moved with
/// the brush, ends its trail at the window's wall).
WB_HD WB_INLINE Vec3 swept_position(Vec3 x_j, Vec3 v_t, float dt, float a, float r, int i, int n, float jitter,
                                    Vec3 pattern, float floor_z, const CellField& columns) {
  const float u = (float(i) + jitter) / float(n);
  Vec3 p = into_columns(columns, x_j - v_t * (dt * (1.f - u)) + Vec3(pattern.x * a, pattern.y * a, 0.f));
  p.z = maxf(x_j.z - r, floor_z) + 0.25f;
  return p;
}

/// Deterministic value in [0, 1) for item j (a sample, a particle) at step `step`: a stratification
/// jitter, a draw.
WB_HD WB_INLINE float step_uniform(int64_t j, int64_t step) {
  const uint32_t h = transfer_hash(uint32_t(j) * 2654435761u ^ uint32_t(step) * 40503u ^ 0x9e3779b9u);
  return float(h >> 8) * (1.f / 16777216.f);
}

/// Point s of the fixed emission pattern of P points, uniform in the lower half of the unit
/// ball (canvas -z, §5.1 "bottom hemisphere", Figure 10): Fibonacci directions over the
/// hemisphere (uniform in area), radii from a golden-ratio sequence with the cube-root
/// volume law, kept off the centre (radius fraction in [0.46, 1]).
WB_HD WB_INLINE Vec3 emission_pattern_point(int s, int P) {
  const float z = -(float(s) + 0.5f) / float(P);
  const float rho = sqrtf(maxf(1.f - z * z, 0.f));
  const float phi = 2.39996323f * float(s);
  float u = (float(s) + 0.5f) * 0.61803399f;
  u -= floorf(u);
  const float radius = cbrtf(0.1f + 0.9f * u);
  return Vec3(rho * cosf(phi), rho * sinf(phi), z) * radius;
}

/// Slot of the emission pattern for the i-th particle sample j lays at step `step`: the step's
/// particles take consecutive slots (spread over the pattern) from a start drawn for the sample
/// and the step. Not a cycle with the step: that would shift the film's stretches laid step by
/// step in a P-step cycle, lines across a slow stroke (docs/TRANSFER.md "Ribs on slow strokes").
WB_HD WB_INLINE int pattern_slot(int64_t j, int64_t step, int i, int P) {
  const uint32_t h = transfer_hash(uint32_t(j) * 747796405u ^ uint32_t(step) * 2891336453u ^ 0x85ebca6bu);
  return int((uint64_t(h) + uint64_t(i)) % uint64_t(P));
}

/// Position of the i-th particle emitted by sample j this step: its pattern slot (pattern_slot),
/// scaled by R_j, kept at or above the canvas (but never above the sample).
WB_HD WB_INLINE Vec3 emission_position(Vec3 x_j, float R_j, int64_t j, int64_t step_index, int i, int P,
                                       float floor_z) {
  Vec3 p = x_j + emission_pattern_point(pattern_slot(j, step_index, i, P), P) * R_j;
  const float lo = minf(floor_z + 0.01f, x_j.z);
  if (p.z < lo) p.z = lo;
  return p;
}

}  // namespace wb
