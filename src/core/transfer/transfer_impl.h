// Transfer stage drivers (paper §5.1-5.2, Eq. 12-16), compiled once per backend: one
// parallel_for per pass over samples, particles, cells or distance-field lines; the physics
// is in bristle_particle_kernels.h and grid_particle_kernels.h. Race-free by construction:
// a particle has one candidate absorber (its nearest sample), per-sample and per-cell
// accumulation goes through atomics, and new particles get slots from an exclusive scan.
#pragma once
#include "core/exec/atomics.h"
#include "core/exec/parallel_for.h"
#include "core/transfer/transfer.h"

namespace wb::WB_BACKEND_NS {

// --- Eq. 12-13: capacity ----------------------------------------------------------------

void transfer_capacity(SampleView s, BristleLoadView load, CellField psi, CellField density, CellField dryness,
                       TransferParams prm, float floor_z, float dry_threshold, float dt) {
  const float mu = prm.mu, M_max = prm.M_max, M_min = prm.M_min, cm = prm.cell_mass();
  const float thr = prm.surface_density, step = prm.march_step;
  parallel_for(s.count(), [=] WB_HD(int64_t j) {
    const Vec3 x = s.x[j];
    const float psi_j = clampf(cell_field_at(psi, x), 0.f, 1.f);
    const float Mp = potential_capacity(psi_j, mu, M_max, M_min);
    const float R = load_radius(Mp, cm);
    const float r = surface_distance(x, R, floor_z, density, thr, step);
    load.potential[j] = Mp;
    load.capacity[j] = surface_capacity(Mp, R, r, cm);
    load.radius[j] = R;
    // The solid below (canvas, dried paint): what the swept contact slides over. Wet paint
    // thicker than the load sphere carries the sample above it (it ploughs, Eq. 13 emits).
    const float gap = surface_distance(x, R, floor_z, density, thr, step, dryness, dry_threshold);
    load.gap[j] = gap;
    // Swept contact: the share of its load the sample would leave sliding this step (sigma_j of
    // the wick's sink). A sample beyond the window's columns (a brush wider than its window) lays
    // none: its trail would be put in the wall's column (swept_position keeps particles in the
    // window), a line along the wall as the window follows the stroke. Its paint stays on the
    // bristle until it is inside.
    const bool inside = over_columns(density, x);
    const Vec3 v = s.v[j];
    const float m = load.m[j];
    const float travel = slid_distance(v, dt);
    load.sweep[j] = m > 0.f && inside ? swept_deposit(m, gap, travel, prm.split, cm) / m : 0.f;
  });
}

// --- swept contact: samples sweeping the same columns in one step share their deposit ----

void transfer_contact_paths(SampleView s, BristleLoadView load, float dt, int ox, int oy, int nx, int ny,
                            uint32_t* passes) {
  parallel_for(load.count, [=] WB_HD(int64_t j) {
    if (!(load.sweep[j] > 0.f)) return;
    for_path_columns(s.x[j], s.v[j], dt, ox, oy, nx, ny,
                     [&](int ix, int iy) { atomic_add(&passes[int64_t(iy) * nx + ix], 1u); });
  });
}

void transfer_contact_share(SampleView s, BristleLoadView load, float dt, int ox, int oy, int nx, int ny,
                            const uint32_t* passes, float split) {
  parallel_for(load.count, [=] WB_HD(int64_t j) {
    if (!(load.sweep[j] > 0.f)) return;
    float sum = 0.f;
    int n = 0;
    for_path_columns(s.x[j], s.v[j], dt, ox, oy, nx, ny, [&](int ix, int iy) {
      sum += float(passes[int64_t(iy) * nx + ix]);
      ++n;
    });
    if (n > 0) load.sweep[j] *= pass_share(sum / float(n), split);
  });
}

// --- wicking along each bristle (docs/TRANSFER.md "Wicking") -------------------------------

// Backward Euler for M'_i s_i - sum_e g_e (s_nb - s_i) = m_i on each bristle, a tridiagonal
// M-matrix system, solved by parallel cyclic reduction (Hockney and Jesshope 1988): a thread a
// sample, ceil(log2 per) passes, each eliminating the neighbours at twice the last distance.
// The reduction keeps each row's sum e = b + a + c (= M_i (1 + sigma_i) at first) rather than
// its diagonal b: under a fast flow (g >> M) b is the near-cancelling g_{i-1} + g_i + M, and the
// new rows' margins would be differences of such; e's update is a sum of terms >= 0 (as in
// Grassmann, Taksar and Heyman's elimination), so the solve stays accurate where Thomas's did.
// The signs of an M-matrix hold (a, c <= 0, d >= 0), so s >= 0. Then the edge fluxes from the
// new saturations carry colour and oil upwind from the old values, and the flux form keeps the
// bristle's mass (to rounding).
void transfer_wick(SampleView s, BristleLoadView load, int bristles, int per, float k_dt, float k_slide, float dt,
                   WickScratch w) {
  const int64_t ns = int64_t(bristles) * per;
  // Saturation against the capacity M_j of Eq. 13: a contact sample that emitted down to M_j is
  // as full as its neighbours, so paint flows to it only as it loses paint by sliding (swept
  // contact), not at a rate per second (a held brush does not leak).
  const float* Mp = load.capacity;
  const float* sigma = load.sweep;
  const Vec3* v = s.v;
  // Conductance of edge t (samples t, t + 1 of one bristle); the drag term uses its mean slide.
  const auto edge = [=] WB_HD(int64_t t) {
    const float slid = 0.5f * (slid_distance(v[t], dt) + slid_distance(v[t + 1], dt));
    return wick_conductance(k_dt, k_slide, slid, Mp[t], Mp[t + 1]);
  };
  // Row i: (-g_{i-1}) s_{i-1} + (M_i (1 + sigma_i) + g_{i-1} + g_i) s_i + (-g_i) s_{i+1} = m_i,
  // with the swept contact's sink sigma_i M_i s_i; its sum e_i = M_i (1 + sigma_i).
  parallel_for(ns, [=] WB_HD(int64_t t) {
    const int i = int(t % per);
    const float g_prev = i > 0 ? edge(t - 1) : 0.f;
    const float g = i + 1 < per ? edge(t) : 0.f;
    w.g[t] = g;
    w.a[0][t] = -g_prev;
    w.c[0][t] = -g;
    w.e[0][t] = maxf(Mp[t], 1e-30f) * (1.f + maxf(sigma[t], 0.f));
    w.d[0][t] = load.m[t];
  });
  int cur = 0;
  for (int stride = 1; stride < per; stride *= 2, cur = 1 - cur) {
    const float *a = w.a[cur], *e = w.e[cur], *c = w.c[cur], *d = w.d[cur];
    float *a2 = w.a[1 - cur], *e2 = w.e[1 - cur], *c2 = w.c[1 - cur], *d2 = w.d[1 - cur];
    parallel_for(ns, [=] WB_HD(int64_t t) {
      const int i = int(t % per);
      const bool lo = i - stride >= 0, hi = i + stride < per;
      // Row t minus al times row t - stride and ga times row t + stride, which removes its
      // couplings to them (b = e - a - c, a sum of terms >= 0).
      const float al = lo ? -a[t] / (e[t - stride] - a[t - stride] - c[t - stride]) : 0.f;
      const float ga = hi ? -c[t] / (e[t + stride] - a[t + stride] - c[t + stride]) : 0.f;
      a2[t] = lo ? al * a[t - stride] : 0.f;
      c2[t] = hi ? ga * c[t + stride] : 0.f;
      e2[t] = e[t] + (lo ? al * e[t - stride] : 0.f) + (hi ? ga * e[t + stride] : 0.f);
      d2[t] = d[t] + (lo ? al * d[t - stride] : 0.f) + (hi ? ga * d[t + stride] : 0.f);
    });
  }
  // The flux F_t from sample t to t + 1 and its giver's old colour and oil (upwind), into the
  // other copy's rows, which the reduction no longer needs.
  // Each row is s_t e_t = d_t now (its couplings are gone).
  const float *e = w.e[cur], *d = w.d[cur];
  float *F = w.a[1 - cur], *give_r = w.e[1 - cur], *give_y = w.c[1 - cur], *give_b = w.d[1 - cur],
        *give_oil = w.a[cur];
  parallel_for(ns, [=] WB_HD(int64_t t) {
    const int i = int(t % per);
    if (i + 1 >= per) {
      F[t] = 0.f;
      return;
    }
    const float f = w.g[t] * (d[t] / e[t] - d[t + 1] / e[t + 1]);
    const int64_t giver = f > 0.f ? t : t + 1;
    F[t] = f;
    give_r[t] = load.pigment_r[giver];
    give_y[t] = load.pigment_y[giver];
    give_b[t] = load.pigment_b[giver];
    give_oil[t] = load.oil[giver];
  });
  // Each sample mixes in what it received with the giver's old colour (Algorithm 2, batch form
  // as in Eq. 14); a sample that only gives keeps its colour.
  parallel_for(ns, [=] WB_HD(int64_t t) {
    const int i = int(t % per);
    const float F_left = i > 0 ? F[t - 1] : 0.f;
    const float F_right = F[t];
    const Vec3 ci(load.pigment_r[t], load.pigment_y[t], load.pigment_b[t]);
    const float oil_i = load.oil[t];
    const float mi = load.m[t];
    float gain = 0.f, oil_in = 0.f, b_in = 0.f;
    Vec3 wc(0.f, 0.f, 0.f);
    if (F_left > 0.f) {  // from i - 1
      const Vec3 cl(give_r[t - 1], give_y[t - 1], give_b[t - 1]);
      gain += F_left;
      wc = wc + cl * F_left;
      b_in += F_left * pigment_brightness(cl);
      oil_in += F_left * give_oil[t - 1];
    }
    if (F_right < 0.f) {  // from i + 1
      const Vec3 cr(give_r[t], give_y[t], give_b[t]);
      gain -= F_right;
      wc = wc + cr * (-F_right);
      b_in += -F_right * pigment_brightness(cr);
      oil_in += -F_right * give_oil[t];
    }
    const float lose = maxf(-F_left, 0.f) + maxf(F_right, 0.f);
    const float keep = maxf(mi - lose, 0.f);
    const float m_new = maxf(mi + F_left - F_right, 0.f);
    // What the sink took: sigma M s = sigma / (1 + sigma) of the sample's paint after the flow;
    // it stays on the sample until the emission pass lays it along the path.
    const float sg = maxf(sigma[t], 0.f);
    load.sweep[t] = m_new * sg / (1.f + sg);
    if (gain > 0.f) {
      const Vec3 cn = mix_batch(ci, keep, wc, b_in, gain);
      load.pigment_r[t] = cn.x;
      load.pigment_y[t] = cn.y;
      load.pigment_b[t] = cn.z;
      load.oil[t] = (keep * oil_i + oil_in) / maxf(keep + gain, 1e-30f);
    }
    load.m[t] = m_new;
  });
}

// --- Eq. 14: absorption and colour bleeding ----------------------------------------------

void transfer_absorb(ParticleView p, SampleView s, BristleLoadView load, AbsorbScratch a, TransferParams prm,
                     float dt, int64_t step_index) {
  const int64_t ns = load.count;
  const float bleed = prm.bleed;
  const uint32_t limit = uint32_t(prm.absorb_limit > 0 ? prm.absorb_limit : 0);
  parallel_for(p.count, [=] WB_HD(int64_t k) {
    if (p.dead[k]) return;
    const int32_t j = p.nearest[k];
    if (j < 0 || j >= ns) return;
    const float mk = p.m[k];
    if (!(mk > 0.f)) return;
    const float R = load.radius[j];
    const Vec3 q = p.x[k] - s.x[j];
    const bool within = length2(q) < R * R;
    // A sample touching a surface takes the share of the film there that its reach swept over
    // this step (film splitting, as when it deposits), along the whole path it slid, not only
    // where the step ended: a pass takes 1 - split of a particle however many steps it lasts,
    // so the pick-up does not beat with the travel a step. A particle is taken whole with that
    // chance, so the film is not split into ever lighter particles. Away from surfaces a sample
    // takes the particles within R_j (Eq. 14).
    const bool touching = load.gap[j] < R;
    float chance = 0.f;
    if (touching) {
      const Vec3 d = (s.v[j] - p.v[k]) * dt;
      chance = film_pickup(prm.split, swept_chord_share(q.x, q.y, q.z, d.x, d.y, R));
      if (!within && !(chance > 0.f)) return;
    } else if (!within) {
      return;
    }
    const float mj = load.m[j], Mj = load.capacity[j];
    const Vec3 ck(p.pigment_r[k], p.pigment_y[k], p.pigment_b[k]);
    if (mj < Mj && limit > 0) {
      if (touching && !(step_uniform(k, step_index) < chance)) return;  // left on the surface
      // Tickets enforce the per-step limit on the particles a sample takes (§5.1); the claimed
      // mass reproduces the sequential test "m_j < M_j before this particle" (a rejected claim
      // only makes later ones stricter).
      const uint32_t t = atomic_add(&a.ticket[j], 1u);
      if (t < limit) {
        const float before = atomic_add(&a.claimed[j], mk);
        if (mj + before < Mj) {
          // Dead and weightless: the census, taken before the step's compaction, counts its
          // paint in the bristles only.
          p.dead[k] = 1u;
          p.m[k] = 0.f;
          a.moved[k] = mk;
          atomic_add(&a.acc_m[j], mk);
          atomic_add(&a.acc_c[0][j], mk * ck.x);
          atomic_add(&a.acc_c[1][j], mk * ck.y);
          atomic_add(&a.acc_c[2][j], mk * ck.z);
          atomic_add(&a.acc_b[j], mk * pigment_brightness(ck));
          atomic_add(&a.acc_oil[j], mk * p.oil[k]);
          atomic_add(&a.counters[0], int32_t(1));
          return;
        }
      }
    }
    if (!within) return;
    // Colour bleeding: the sample's colour as it was at the start of the pass (the sample is
    // updated in the next launch), the particle's mass unchanged.
    const float e = bleed_weight(bleed, mk, mj);
    if (!(e > 0.f)) return;
    const Vec3 cj(load.pigment_r[j], load.pigment_y[j], load.pigment_b[j]);
    const Vec3 cn = color_mix(ck, cj, mk, e);
    p.pigment_r[k] = cn.x;
    p.pigment_y[k] = cn.y;
    p.pigment_b[k] = cn.z;
    atomic_add(&a.bl_w[j], e);
    atomic_add(&a.bl_c[0][j], e * ck.x);
    atomic_add(&a.bl_c[1][j], e * ck.y);
    atomic_add(&a.bl_c[2][j], e * ck.z);
    atomic_add(&a.bl_b[j], e * pigment_brightness(ck));
    atomic_add(&a.bl_n[j], 1u);  // a sample's count: one address for all would be contended
  });
}

void transfer_absorb_apply(BristleLoadView load, AbsorbScratch a) {
  parallel_for(load.count, [=] WB_HD(int64_t j) {
    if (a.bl_n[j] > 0u) atomic_add(&a.counters[1], int32_t(a.bl_n[j]));
    const float am = a.acc_m[j], bw = a.bl_w[j];
    if (!(am > 0.f) && !(bw > 0.f)) return;
    const float mj = load.m[j];
    const Vec3 cj(load.pigment_r[j], load.pigment_y[j], load.pigment_b[j]);
    const Vec3 sum_c(a.acc_c[0][j] + a.bl_c[0][j], a.acc_c[1][j] + a.bl_c[1][j], a.acc_c[2][j] + a.bl_c[2][j]);
    const Vec3 cn = mix_batch(cj, mj, sum_c, a.acc_b[j] + a.bl_b[j], am + bw);  // Eq. 14, Algorithm 2
    load.pigment_r[j] = cn.x;
    load.pigment_y[j] = cn.y;
    load.pigment_b[j] = cn.z;
    if (am > 0.f) {
      const float m_new = mj + am;  // Eq. 14: m_j + sum m_k
      load.oil[j] = (maxf(mj, 0.f) * load.oil[j] + a.acc_oil[j]) / maxf(m_new, 1e-30f);
      load.m[j] = m_new;
    }
  });
}

// --- coarse distance to the bristles (§5.2 "within D0") ------------------------------------

void transfer_distance_occupancy(SampleView s, DistanceBlocks db, int32_t* occ, int ox, int oy, int oz) {
  parallel_for(s.count(), [=] WB_HD(int64_t j) {
    const Vec3 x = s.x[j];
    const int64_t b = db.block_of(Vec3(x.x - float(ox), x.y - float(oy), x.z - float(oz)));
    if (b >= 0) atomic_max(&occ[b], int32_t(1));
  });
}

void transfer_distance_init(const int32_t* occ, float* d2, int64_t n) {
  parallel_for(n, [=] WB_HD(int64_t b) { d2[b] = occ[b] ? 0.f : kFarDistance2; });
}

void transfer_distance_pass(DistanceBlocks db, int axis, const float* src, float* dst, int32_t* v, float* z) {
  const int n = axis == 0 ? db.bx : (axis == 1 ? db.by : db.bz);
  const int64_t total = int64_t(db.bx) * db.by * db.bz;
  const int64_t lines = total / n;
  parallel_for(lines, [=] WB_HD(int64_t L) {
    int64_t base, stride;
    if (axis == 0) {
      base = db.index(0, int(L % db.by), int(L / db.by));
      stride = 1;
    } else if (axis == 1) {
      base = db.index(int(L % db.bx), 0, int(L / db.bx));
      stride = db.bx;
    } else {
      base = db.index(int(L % db.bx), int(L / db.bx), 0);
      stride = int64_t(db.bx) * db.by;
    }
    edt_line(src + base, dst + base, n, stride, v + L * n, z + L * (n + 1));
    // After the last axis the field holds distances, not their squares: a particle's lookup
    // blends eight of them (DistanceBlocks::distance), a root each taken here once.
    if (axis == 2)
      for (int q = 0; q < n; ++q) {
        float& e = dst[base + q * stride];
        e = e >= kFarDistance2 ? kFarDistance2 : sqrtf(e);
      }
  });
}

// --- Eq. 16: particles back to the grid -----------------------------------------------------

void transfer_to_grid_mark(ParticleView p, PaintWindowView pw, DistanceBlocks db, DepositScratch acc,
                           TransferParams prm, float dry_threshold) {
  const float slow2 = prm.slow_speed * prm.slow_speed, h = prm.kernel_h, inv_cm = 1.f / prm.cell_mass();
  const float margin = prm.return_margin;
  parallel_for(p.count, [=] WB_HD(int64_t k) {
    if (p.dead[k]) return;
    const float mk = p.m[k];
    if (!(mk > 0.f)) return;
    const Vec3 x = p.x[k];
    Vec3 q(x.x - float(pw.ox), x.y - float(pw.oy), x.z - float(pw.oz));
    if (!(q.x >= 0.f && q.y >= 0.f && q.z >= 0.f && q.x < float(pw.nx) && q.y < float(pw.ny) && q.z < float(pw.nz))) {
      // Outside the window (flew out in one step): only the keep-box pass takes it, at the edge.
      if (!acc.keep.on || !isfinite3(q)) return;
      q = Vec3(clampf(q.x, 0.5f, float(pw.nx) - 0.5f), clampf(q.y, 0.5f, float(pw.ny) - 0.5f),
               clampf(q.z, 0.5f, float(pw.nz) - 0.5f));
    }
    // Leaving the window's next box: back to the grid now, or it would be outside every field.
    const bool leaving = !acc.keep.contains(q);
    if (!leaving && (acc.only_leaving || !(length2(p.v[k]) < slow2) || db.near(q, margin))) return;
    // In flight above the paint (leaving the window, or thrown out of it): it lands first, its
    // centre half a cell over the surface (a particle is about a cell across).
    if (acc.surface) {
      const int i = clampi(int(q.x), 0, pw.nx - 1), j = clampi(int(q.y), 0, pw.ny - 1);
      q.z = minf(q.z, maxf(acc.surface[int64_t(j) * pw.nx + i] - float(pw.oz), 0.f) + 0.5f);
    }
    const Vec3 ck(p.pigment_r[k], p.pigment_y[k], p.pigment_b[k]);
    const float bk = pigment_brightness(ck), oil = p.oil[k], dry = p.dryness[k];
    const float a = mk * inv_cm;  // density units
    const int cells = for_each_kernel_cell(pw, q, h, dry_threshold, [&](int64_t id, float w) {
      const float add = a * w;  // Eq. 16: m_k W(p_k - x_c, h)
      atomic_add(&acc.rho[id], to_fixed(add));
      atomic_add(&acc.c[0][id], to_fixed(add * ck.x));
      atomic_add(&acc.c[1][id], to_fixed(add * ck.y));
      atomic_add(&acc.c[2][id], to_fixed(add * ck.z));
      atomic_add(&acc.b[id], to_fixed(add * bk));
      atomic_add(&acc.oil[id], to_fixed(add * oil));
      atomic_add(&acc.dryness[id], to_fixed(add * dry));
      acc.cells.touch(id);
    });
    if (cells > 0) {
      // The particle is left weightless, in place, to the step's compaction (the census, taken
      // before it, counts its paint in the grid only); a window move's pass marks nothing more
      // (the sort after it moves the state, not the dead flags), the step's own pass marks it dead.
      p.m[k] = 0.f;
      if (!acc.only_leaving) p.dead[k] = 1u;
      acc.moved[k] = mk;
      atomic_add(acc.counter, int32_t(1));
    }
  });
}

void transfer_to_grid_apply(PaintWindowView pw, DepositScratch acc, double* into_grid) {
  // The listed cells only (fewer than the window's, which bounds the list); each is zeroed
  // once read, for the next pass.
  parallel_for_count(acc.cells.count, pw.size(), [=] WB_HD(int64_t t) {
    const int64_t c = acc.cells.items[t];
    const float add = from_fixed(acc.rho[c]);
    const Vec3 sum_c(from_fixed(acc.c[0][c]), from_fixed(acc.c[1][c]), from_fixed(acc.c[2][c]));
    const float sum_b = from_fixed(acc.b[c]), sum_oil = from_fixed(acc.oil[c]), sum_dry = from_fixed(acc.dryness[c]);
    acc.rho[c] = acc.c[0][c] = acc.c[1][c] = acc.c[2][c] = acc.b[c] = acc.oil[c] = acc.dryness[c] = 0;
    acc.cells.listed[c] = 0;
    if (!(add > 0.f)) return;
    atomic_add(acc.received, to_fixed(add));  // the books: what the cells received, in any order
    const float rho = maxf(pw.density[c], 0.f);
    const float tot = rho + add;
    const Vec3 cold(pw.pigment_r[c], pw.pigment_y[c], pw.pigment_b[c]);
    // Pigment: Algorithm 2 with weights = the cell's mass and the added mass; oil and
    // dryness: mass-weighted (the "linear interpolation" of §5.2).
    const Vec3 cn = mix_batch(cold, rho, sum_c, sum_b, add);
    pw.pigment_r[c] = cn.x;
    pw.pigment_y[c] = cn.y;
    pw.pigment_b[c] = cn.z;
    pw.oil[c] = (rho * pw.oil[c] + sum_oil) / tot;
    pw.dryness[c] = (rho * pw.dryness[c] + sum_dry) / tot;
    pw.density[c] = pw.density[c] + add;
  });
  parallel_for(1, [=] WB_HD(int64_t) {
    *into_grid += from_fixed_sum(*acc.received);
    *acc.received = 0;
  });
}

// --- §5.1: emission -------------------------------------------------------------------------

void transfer_emit_count(SampleView s, BristleLoadView load, TransferParams prm, float dt, uint32_t* count,
                         float* mass_each, float* swept_each, uint32_t* swept_n) {
  const float eps = prm.epsilon, emit_mass = prm.emit_mass;
  const int limit = prm.emit_limit;
  parallel_for(load.count, [=] WB_HD(int64_t j) {
    // §5.1: the load above (1 + eps) M_j leaves, at most emit_limit particles a step.
    float me = 0.f;
    const int n = emission_count(load.m[j], load.capacity[j], eps, emit_mass, limit, me);
    // Swept contact: what the sample leaves on the surface it slid over this step.
    const float travel = slid_distance(s.v[j], dt);
    const float left = load.m[j] - float(n) * me;
    const float deposit = minf(load.sweep[j], left);  // the wick solve's deposit
    float se = 0.f;
    const int ns = swept_count(deposit, travel, emit_mass, se);
    count[j] = uint32_t(n + ns);
    mass_each[j] = me;
    swept_each[j] = se;
    swept_n[j] = uint32_t(ns);
  });
}

void transfer_emit_fill(SampleView s, BristleLoadView load, ParticleView p, NewBatch batch, const float* mass_each,
                        const float* swept_each, const uint32_t* swept_n, int64_t step_index, TransferParams prm,
                        float floor_z, float dt, PaintWindowView pw, float dry_threshold, float* emitted) {
  const int P = prm.emit_pattern;
  const CellField density{pw.density, pw.nx, pw.ny, pw.nz, pw.ox, pw.oy, pw.oz};
  const CellField dryness{pw.dryness, pw.nx, pw.ny, pw.nz, pw.ox, pw.oy, pw.oz};
  const float thr = prm.surface_density, march = prm.march_step;
  const float cm = prm.cell_mass();
  parallel_for(load.count, [=] WB_HD(int64_t j) {
    emitted[j] = 0.f;
    const int n = int(batch.count[j]);
    if (n == 0) return;
    const int64_t off = batch.slot(j);
    const int64_t left = batch.n - off;
    const int n_eff = left <= 0 ? 0 : (left < n ? int(left) : n);
    if (n_eff == 0) return;
    const int n_swept = int(swept_n[j]), n_static = n - n_swept;
    const Vec3 xj = s.x[j], vj = s.v[j];
    const Vec3 vt(vj.x, vj.y, 0.f);
    const float R = load.radius[j], r = load.gap[j];
    // Footprint half-width of the paint sphere on the surface (swept_deposit's cap).
    const float Rm = load_radius(load.m[j], cm);
    const float a = sqrtf(maxf(Rm * Rm - r * r, 0.f));
    float out = 0.f;
    for (int i = 0; i < n_eff; ++i) {
      const int64_t k = batch.first + off + i;
      if (i < n_static) {
        p.x[k] = emission_position(xj, R, j, step_index, i, P, floor_z);
        p.v[k] = vj;  // "the new particles share the same attributes as the sample, including the velocity"
        p.m[k] = mass_each[j];
      } else {
        // Left on the surface along the path slid this step, at rest with it.
        const int q = i - n_static;
        const float jitter = step_uniform(j, step_index);
        const Vec3 pattern = emission_pattern_point(pattern_slot(j, step_index, n_static + q, P), P);
        // Laid where the path touches the surface: a point over a hollow the bristle bridged
        // (its surface more than half a cell lower than at the contact) moves to the next point
        // of the path that touches, else to the end of the path, where the contact is.
        const float reach = r + 0.5f;
        Vec3 at = swept_position(xj, vt, dt, a, r, n_swept, n_swept, 0.f, pattern, floor_z, density);  // the end
        for (int t = 0; t < n_swept; ++t) {
          const Vec3 cand = swept_position(xj, vt, dt, a, r, (q + t) % n_swept, n_swept, jitter, pattern, floor_z, density);
          if (surface_distance(Vec3(cand.x, cand.y, xj.z), reach + march, floor_z, density, thr, march, dryness,
                               dry_threshold) <= reach) {
            at = cand;
            break;
          }
        }
        p.x[k] = at;
        p.v[k] = Vec3();
        p.m[k] = swept_each[j];
      }
      out += p.m[k];
      p.pigment_r[k] = load.pigment_r[j];
      p.pigment_y[k] = load.pigment_y[j];
      p.pigment_b[k] = load.pigment_b[j];
      p.oil[k] = load.oil[j];
      p.dryness[k] = 0.f;  // paint on the brush is kept wet
    }
    const float m_old = load.m[j];
    const float m_new = maxf(m_old - out, 0.f);
    load.m[j] = m_new;
    emitted[j] = m_old - m_new;
  });
}

// --- Eq. 15: grid cells to particles ---------------------------------------------------------

void transfer_grid_count(PaintWindowView pw, DistanceBlocks db, KeepBox keep, TransferParams prm,
                         float dry_threshold, uint32_t* count) {
  const float min_rho = prm.min_cell_density;
  parallel_for(pw.size(), [=] WB_HD(int64_t c) {
    count[c] = 0u;
    const float rho = pw.density[c];
    // Dried paint, solid or a thin trace, stays on the canvas (the brush does not re-wet it).
    if (!(rho > 0.f) || rho < min_rho || pw.dryness[c] >= dry_threshold) return;
    const int i = int(c % pw.nx), j = int((c / pw.nx) % pw.ny), k = int(c / (int64_t(pw.nx) * pw.ny));
    // Paint outside the keep box stays grid paint: particles there would go straight back.
    if (!keep.contains(i, j, k) || !db.near(Vec3(float(i) + 0.5f, float(j) + 0.5f, float(k) + 0.5f))) return;
    const int split = cell_candidate_split(rho, prm.candidate_split), candidates = split * split * split;
    uint32_t n = 0;
    for (int s = 0; s < candidates; ++s) {
      const Vec3 q = Vec3(float(i), float(j), float(k)) + candidate_offset(i + pw.ox, j + pw.oy, k + pw.oz, s, split);
      if (liquid_density_at(pw, q, dry_threshold) > 0.f) ++n;
    }
    count[c] = n;
  });
}

void transfer_grid_emit(PaintWindowView pw, MacView vel, ParticleView p, NewBatch batch, TransferParams prm,
                        float dry_threshold, float* demand) {
  const float h = prm.kernel_h, cm = prm.cell_mass();
  parallel_for(pw.size(), [=] WB_HD(int64_t c) {
    if (batch.count[c] == 0u) return;
    const int split = cell_candidate_split(pw.density[c], prm.candidate_split), candidates = split * split * split;
    const float share = 1.f / float(candidates);
    const int64_t off = batch.slot(c);
    if (off >= batch.n) return;
    const int i = int(c % pw.nx), j = int((c / pw.nx) % pw.ny), k = int(c / (int64_t(pw.nx) * pw.ny));
    const Vec3 cell_c(pw.pigment_r[c], pw.pigment_y[c], pw.pigment_b[c]);
    const float oil = pw.oil[c], dry = pw.dryness[c];
    int64_t t = 0;
    for (int s = 0; s < candidates && off + t < batch.n; ++s) {
      const Vec3 q = Vec3(float(i), float(j), float(k)) + candidate_offset(i + pw.ox, j + pw.oy, k + pw.oz, s, split);
      const float rho_q = liquid_density_at(pw, q, dry_threshold);
      if (!(rho_q > 0.f)) continue;
      const int64_t pk = batch.first + off + t;
      ++t;
      const Vec3 x(q.x + float(pw.ox), q.y + float(pw.oy), q.z + float(pw.oz));
      const float a = rho_q * share;  // the candidate's share of the cell, density units
      p.x[pk] = x;
      p.v[pk] = vel.u != nullptr ? vel.sample(x) : Vec3(0.f, 0.f, 0.f);
      p.m[pk] = a * cm;  // nominal m_k; grid_finish applies the clamp of Eq. 15
      p.pigment_r[pk] = cell_c.x;
      p.pigment_y[pk] = cell_c.y;
      p.pigment_b[pk] = cell_c.z;
      p.oil[pk] = oil;
      p.dryness[pk] = dry;
      for_each_kernel_cell(pw, q, h, dry_threshold, [&](int64_t id, float w) { atomic_add(&demand[id], a * w); });
    }
  });
}

void transfer_room_ends(const uint32_t* count, const uint32_t* offset, int64_t n, int64_t a, int64_t b,
                        uint32_t* ends) {
  // The scan's prefixes at a and b and its total (n > 0): one small copy for the host.
  parallel_for(1, [=] WB_HD(int64_t) {
    const uint32_t total = offset[n - 1] + count[n - 1];
    ends[0] = a < n ? offset[a] : total;
    ends[1] = b < n ? offset[b] : total;
    ends[2] = total;
  });
}

void transfer_grid_clamp(PaintWindowView pw, float* demand_ratio, float* removed) {
  parallel_for(pw.size(), [=] WB_HD(int64_t c) {
    float rem = 0.f;
    const float ratio = clamp_ratio(demand_ratio[c], pw.density[c], rem);  // Eq. 15 with max(., 0)
    if (rem > 0.f) pw.density[c] = rem >= pw.density[c] ? 0.f : pw.density[c] - rem;
    demand_ratio[c] = ratio;
    removed[c] = rem;
  });
}

void transfer_grid_finish(ParticleView p, int64_t first, int64_t n, PaintWindowView pw, const float* ratio,
                          TransferParams prm, float dry_threshold) {
  const float h = prm.kernel_h;
  parallel_for(n, [=] WB_HD(int64_t i) {
    const int64_t k = first + i;
    const Vec3 x = p.x[k];
    const Vec3 q(x.x - float(pw.ox), x.y - float(pw.oy), x.z - float(pw.oz));
    float keep = 0.f;
    for_each_kernel_cell(pw, q, h, dry_threshold, [&](int64_t id, float w) { keep += w * ratio[id]; });
    p.m[k] = p.m[k] * keep;
  });
}

// --- the load: UI sums, dip / fill / wipe ----------------------------------------------------

void transfer_product(const float* a, const float* b, float* out, int64_t n) {
  parallel_for(n, [=] WB_HD(int64_t i) { out[i] = a[i] * b[i]; });
}

void transfer_load_brightness(BristleLoadView load, float* out) {
  parallel_for(load.count, [=] WB_HD(int64_t j) {
    out[j] = load.m[j] * pigment_brightness(Vec3(load.pigment_r[j], load.pigment_y[j], load.pigment_b[j]));
  });
}

void transfer_load_dip(BristleLoadView load, const float* exchange, Vec3 ryb, float oil, float level, int replace,
                       float* added) {
  parallel_for(load.count, [=] WB_HD(int64_t j) {
    const float target = level * load.potential[j];
    const float m = load.m[j];
    if (replace) {
      load.m[j] = target;
      load.pigment_r[j] = ryb.x;
      load.pigment_y[j] = ryb.y;
      load.pigment_b[j] = ryb.z;
      load.oil[j] = oil;
      added[j] = target - m;
      return;
    }
    // The well's paint replaces the share x of the sample's paint that the pile reaches, then
    // tops it up to the asked level; the rest of the old paint stays (docs/TRANSFER.md "Dipping").
    const float m0 = maxf(m, 0.f);
    const float x = exchange ? exchange[j] : 0.f;
    const float keep = (1.f - x) * m0;
    const float take = x * m0 + maxf(target - m0, 0.f);
    if (!(take > 0.f)) {
      added[j] = 0.f;
      return;
    }
    const Vec3 c = color_mix(Vec3(load.pigment_r[j], load.pigment_y[j], load.pigment_b[j]), ryb, keep, take);
    load.pigment_r[j] = c.x;
    load.pigment_y[j] = c.y;
    load.pigment_b[j] = c.z;
    load.oil[j] = (keep * load.oil[j] + take * oil) / (keep + take);
    load.m[j] = keep + take;
    added[j] = keep + take - m;
  });
}

void transfer_load_scale(BristleLoadView load, float keep, float* change) {
  parallel_for(load.count, [=] WB_HD(int64_t j) {
    const float m = load.m[j];
    const float m_new = m * keep;
    load.m[j] = m_new;
    change[j] = m_new - m;
  });
}

}  // namespace wb::WB_BACKEND_NS
