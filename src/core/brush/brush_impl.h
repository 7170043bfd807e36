// Brush stage drivers (paper §4.1, DESIGN step 1-2), compiled once per backend.
// Order of one step: integrate Eq. 2 in the brush frame -> per-bristle Gauss-Seidel
// sweeps (bending, inextensibility, collision + friction) -> minimum-density Jacobi
// iterations across bristles -> final exact inextensibility + collision -> velocities
// and canvas positions -> samples (spline, Bishop frames, motion).
#pragma once
#include "core/brush/brush_kernels.h"
#include "core/brush/brush_stages.h"
#include "core/brush/samples_kernels.h"
#include "core/exec/atomics.h"
#include "core/exec/parallel_for.h"

namespace wb::WB_BACKEND_NS {

namespace brush_detail {
/// Horizontal fallback for splaying a vertical bristle pressed straight down: the
/// canvas-frame direction of its root away from the ferrule centre.
WB_HD WB_INLINE Vec3 splay_direction(const BrushFrame& f, Vec3 root) {
  const Vec3 r = f.R * Vec3(root.x, root.y, 0.f);
  const Vec3 ax = f.R * Vec3(1.f, 0.f, 0.f);
  return normalize_or(Vec3(r.x, r.y, 0.f), normalize_or(Vec3(ax.x, ax.y, 0.f), Vec3(1.f, 0.f, 0.f)));
}
}  // namespace brush_detail

void brush_integrate(BristleState s, BristleRest r, BrushFrame f, BrushForces e, float beta_B, float damping,
                     float dt) {
  const int V = s.per_bristle;
  parallel_for(s.count(), [=] WB_HD(int64_t g) {
    s.xb_old[g] = s.xb[g];
    s.vb_old[g] = s.vb[g];
    s.x_old[g] = s.x[g];
    s.v_old[g] = s.v[g];
    const int64_t k = g / V;
    if (g % V == 0) {  // the root is pinned in the ferrule
      s.xb[g] = r.root[k];
      s.vb[g] = Vec3();
      return;
    }
    Vec3 dv_canvas = e.gravity * dt;
    if (e.has_drag) dv_canvas += brush::drag_velocity_change(e.drag, s.x[g], s.v[g], dt);
    const Vec3 a = brush::eq2_acceleration(f.R_B * (dv_canvas / dt), f, s.xb[g], s.vb[g], beta_B);
    const Vec3 vb = (s.vb[g] * (1.f - damping) + a * dt);
    s.vb[g] = vb;
    s.xb[g] = s.xb[g] + vb * dt;
  });
}

void brush_solve(BristleState s, BristleRest r, BrushFrame f, SolidField solid, int iterations, float friction_it) {
  const int V = s.per_bristle;
  parallel_for(s.bristles, [=] WB_HD(int64_t k) {
    const int64_t base = k * V;
    const Vec3 d0 = r.dir[k];
    const float kb = r.bend_k[k];
    const Vec3 splay = brush_detail::splay_direction(f, r.root[k]);
    for (int it = 0; it < iterations; ++it) {
      for (int i = 1; i < V; ++i) {
        const int64_t g = base + i;
        const float l0 = r.seg_length[g];
        const float tol = 1e-5f * l0;
        const Vec3 xp = s.xb[g - 1];
        const Vec3 dir = i == 1 ? d0 : normalize_or(xp - s.xb[g - 2], d0);
        Vec3 xi = brush::project_bending(s.xb[g], xp + dir * l0, kb, tol);
        xi = brush::project_distance(xp, xi, l0, tol, dir);
        Vec3 xc = f.R * xi + f.p;
        if (brush::collide_vertex(xc, f.R * xp + f.p, l0, solid, splay)) {
          xc = brush::apply_friction(xc, s.x_old[g], friction_it);
          xi = f.R_B * (xc - f.p);
        }
        s.xb[g] = xi;
      }
    }
  }, kMinParallelHeavy);  // one bristle per element
}

void brush_grid_keys(BristleState s, float h, uint32_t mask, uint32_t* keys, uint32_t* ids) {
  const float inv_cell = 0.5f / h;  // cells of 2h: see for_each_neighbour
  parallel_for(s.count(), [=] WB_HD(int64_t g) {
    const Vec3 x = s.xb[g];
    keys[g] = brush::hash_cell(brush::floor_to_int(x.x * inv_cell), brush::floor_to_int(x.y * inv_cell),
                               brush::floor_to_int(x.z * inv_cell), mask);
    ids[g] = uint32_t(g);
  });
}

void brush_grid_ranges(const uint32_t* keys, int64_t n, uint32_t* cell_start, uint32_t* cell_end) {
  parallel_for(n, [=] WB_HD(int64_t i) {
    const uint32_t key = keys[i];
    if (i == 0 || keys[i - 1] != key) cell_start[key] = uint32_t(i);
    if (i == n - 1 || keys[i + 1] != key) cell_end[key] = uint32_t(i + 1);
  });
}

namespace brush_detail {
/// Visits every vertex of another bristle within h of vertex g. The grid cells are 2h
/// wide, so the ball of radius h overlaps at most 2 x 2 x 2 of them; each candidate's own
/// cell is checked so that hash collisions are neither counted twice nor mistaken.
template <typename F>
WB_HD WB_INLINE void for_each_neighbour(const BristleState& s, const MinDensityGrid& grid, int64_t g, F&& fn) {
  const Vec3 x = s.xb[g];
  const int V = s.per_bristle;
  const float inv_cell = 0.5f / grid.h;
  const float gx = x.x * inv_cell, gy = x.y * inv_cell, gz = x.z * inv_cell;
  const int cx = brush::floor_to_int(gx), cy = brush::floor_to_int(gy), cz = brush::floor_to_int(gz);
  // The other cell along each axis: the side of the cell's centre x lies on.
  const int ox = gx - float(cx) < 0.5f ? -1 : 1, oy = gy - float(cy) < 0.5f ? -1 : 1, oz = gz - float(cz) < 0.5f ? -1 : 1;
  for (int c = 0; c < 8; ++c) {
    const int nx = cx + ((c & 1) ? ox : 0), ny = cy + ((c & 2) ? oy : 0), nz = cz + ((c & 4) ? oz : 0);
    const uint32_t key = brush::hash_cell(nx, ny, nz, grid.mask);
    const uint32_t b = grid.cell_start[key], e = grid.cell_end[key];
    for (uint32_t q = b; q < e; ++q) {
      const int64_t j = grid.ids[q];
      if (j / V == g / V) continue;
      const Vec3 xj = s.xb[j];
      const Vec3 d = x - xj;
      const float r2 = length2(d);
      if (r2 >= grid.h * grid.h) continue;
      if (brush::floor_to_int(xj.x * inv_cell) != nx || brush::floor_to_int(xj.y * inv_cell) != ny ||
          brush::floor_to_int(xj.z * inv_cell) != nz)
        continue;
      fn(j, d, sqrtf(r2));
    }
  }
}
}  // namespace brush_detail

void brush_density_lambda(BristleState s, MinDensityGrid grid, float* lambda) {
  parallel_for(s.count(), [=] WB_HD(int64_t g) {
    float rho = 0.f, sum_grad2 = 0.f;
    Vec3 grad_i;
    brush_detail::for_each_neighbour(s, grid, g, [&](int64_t j, Vec3 d, float r) {
      rho += brush::density_kernel(r, grid.h);
      const Vec3 u = r > 1e-6f ? d / r : brush::separation_dir(g, j);
      const Vec3 gj = u * (brush::density_kernel_dr(r, grid.h) / grid.rho0);  // grad_i of W, / rho0
      grad_i += gj;
      sum_grad2 += length2(gj);
    });
    const float C = rho / grid.rho0 - 1.f;  // Macklin & Müller 2013 Eq. 1, unilateral
    lambda[g] = C > 0.f ? -C / (sum_grad2 + length2(grad_i) + grid.eps) : 0.f;
  });
}

void brush_density_delta(BristleState s, MinDensityGrid grid, const float* lambda) {
  parallel_for(s.count(), [=] WB_HD(int64_t g) {
    const float li = lambda[g];
    Vec3 dx;
    brush_detail::for_each_neighbour(s, grid, g, [&](int64_t j, Vec3 d, float r) {
      const float lsum = li + lambda[j];
      if (lsum == 0.f) return;
      const Vec3 u = r > 1e-6f ? d / r : brush::separation_dir(g, j);
      dx += u * (lsum * brush::density_kernel_dr(r, grid.h) / grid.rho0);  // Macklin & Müller 2013 Eq. 12
    });
    // One Jacobi step moves a vertex by at most s_min / 2: a crowd's summed pushes would
    // otherwise throw it across its neighbours.
    s.delta[g] = brush::clamp_length(dx, 0.25f * grid.h);
  });
}

void brush_density_apply(BristleState s) {
  const int V = s.per_bristle;
  // Only the part of a correction across its segment is kept, and a vertex pushed aside
  // carries the rest of its bristle with it (prefix sum from root to tip): a segment's
  // length then changes only to second order (|d|^2 / 2 l0), so the constraint can act
  // last in the step without breaking inextensibility.
  parallel_for(s.bristles, [=] WB_HD(int64_t k) {
    Vec3 carried;
    for (int i = 1; i < V; ++i) {
      const int64_t g = k * V + i;
      const Vec3 t = normalize_or(s.xb[g] - s.xb[g - 1], Vec3());
      const Vec3 d = s.delta[g];
      carried += d - t * dot(t, d);
      s.xb[g] = s.xb[g] + carried;
    }
  }, kMinParallelHeavy);  // one bristle per element
}

void brush_inextensible(BristleState s, BristleRest r, BrushFrame f, SolidField solid) {
  const int V = s.per_bristle;
  parallel_for(s.bristles, [=] WB_HD(int64_t k) {
    const int64_t base = k * V;
    const Vec3 d0 = r.dir[k];
    const Vec3 splay = brush_detail::splay_direction(f, r.root[k]);
    for (int i = 1; i < V; ++i) {  // exact inextensibility, root to tip, then the surfaces
      const int64_t g = base + i;
      const float l0 = r.seg_length[g];
      const Vec3 xp = s.xb[g - 1];
      Vec3 xi = brush::project_distance(xp, s.xb[g], l0, 1e-6f * l0, d0);
      Vec3 xc = f.R * xi + f.p;
      if (brush::collide_vertex(xc, f.R * xp + f.p, l0, solid, splay)) xi = f.R_B * (xc - f.p);
      s.xb[g] = xi;
    }
  }, kMinParallelHeavy);  // one bristle per element
}

void brush_velocities(BristleState s, BrushFrame f, SolidField solid, float dt) {
  const int V = s.per_bristle;
  const float inv_dt = 1.f / dt;
  parallel_for(s.count(), [=] WB_HD(int64_t g) {
    Vec3 x = f.R * s.xb[g] + f.p;
    if (g % V != 0) {  // the last correction may have nudged a vertex into a surface: lift it
      const float h = brush::support_height(solid, x);
      if (x.z < h) {
        x.z = h;
        s.xb[g] = f.R_B * (x - f.p);
      }
    }
    s.x[g] = x;
    s.v[g] = (x - s.x_old[g]) * inv_dt;  // PBD velocities from the position change
    s.vb[g] = g % V == 0 ? Vec3() : (s.xb[g] - s.xb_old[g]) * inv_dt;
  });
}

// Rolls the sub-step back where counts[0] + counts[1] (its non-finite positions and
// velocities) is not zero, and counts it in counts[2]: decided on the device, no host wait.
void brush_restore(BristleState s, BrushFrame f, int64_t* counts) {
  parallel_for(s.count(), [=] WB_HD(int64_t g) {
    if (counts[0] + counts[1] == 0) return;
    if (g == 0) counts[2] += 1;
    s.xb[g] = s.xb_old[g];
    s.vb[g] = Vec3();
    s.x[g] = f.R * s.xb[g] + f.p;
    s.v[g] = Vec3();
  });
}

void brush_place(BristleState s, BristleRest r, BrushFrame f) {
  parallel_for(s.count(), [=] WB_HD(int64_t g) {
    const Vec3 x = f.R * s.xb[g] + f.p;
    s.x[g] = s.x_old[g] = x;
    s.xb_old[g] = s.xb[g];
    s.vb[g] = s.vb_old[g] = s.v[g] = s.v_old[g] = Vec3();
  });
}

void brush_stretch_and_z(BristleState s, BristleRest r, float* stretch, float* z) {
  const int V = s.per_bristle;
  parallel_for(s.count(), [=] WB_HD(int64_t g) {
    z[g] = s.x[g].z;
    if (g % V == 0) {
      stretch[g] = 0.f;
      return;
    }
    const float l0 = r.seg_length[g];
    stretch[g] = fabsf(length(s.xb[g] - s.xb[g - 1]) - l0) / l0;
  });
}

// ---------------------------------------------------------------------------------
// Samples
// ---------------------------------------------------------------------------------

void samples_spline(BristleState s, SampleView sv, SamplePrev prev, SolidField solid) {
  const int V = s.per_bristle, S = sv.per_bristle;
  const float scale = float(V - 1) / float(S - 1);
  parallel_for(sv.count(), [=] WB_HD(int64_t q) {
    prev.x[q] = sv.x[q];
    prev.t[q] = sv.t[q];
    prev.n[q] = sv.n[q];
    prev.v[q] = sv.v[q];
    prev.omega[q] = sv.omega[q];
    const int64_t k = q / S;
    const int j = int(q % S);
    const Vec3* vx = s.x + k * V;
    const float sp = float(j) * scale;
    int i = int(sp);
    if (i > V - 2) i = V - 2;
    const float u = sp - float(i);
    Vec3 d;
    Vec3 x = brush::hermite(vx[i], brush::fd_tangent(vx, i, V), vx[i + 1], brush::fd_tangent(vx, i + 1, V), u, d);
    const float h = brush::support_height(solid, x);  // the spline may dip below a vertex
    if (x.z < h) x.z = h;
    sv.x[q] = x;
    sv.t[q] = normalize_or(d, normalize_or(vx[i + 1] - vx[i], Vec3(0.f, 0.f, -1.f)));
  });
}

void samples_frames(SampleView sv, BrushFrame f, FrameScan scan) {
  const int S = sv.per_bristle;
  const int64_t n_all = sv.count();
  // Root frame attached to the brush: the handle's x axis made normal to the tangent (its y
  // axis where x is along it).
  const auto normal_to = [=] WB_HD(Vec3 t) {
    const Vec3 ax = f.R.col(0), ay = f.R.col(1);
    const Vec3 n = ax - t * dot(t, ax);
    return length2(n) < 1e-6f ? normalize(ay - t * dot(t, ay)) : normalize(n);
  };
  // n_j is n_0 carried by the transports of edges 1..j: their product, a prefix product over
  // each bristle (Hillis and Steele 1986), ceil(log2 S) passes of a thread a sample instead of
  // one thread walking each bristle.
  parallel_for(n_all, [=] WB_HD(int64_t q) {
    const int j = int(q % S);
    const brush::Quat r = j > 0 ? brush::transport_quat(sv.t[q - 1], sv.t[q]) : brush::Quat{1.f, Vec3()};
    scan.w[0][q] = r.w;
    scan.v[0][q] = r.v;
  });
  int cur = 0;
  for (int stride = 1; stride < S; stride *= 2, cur = 1 - cur) {
    const float* w = scan.w[cur];
    const Vec3* v = scan.v[cur];
    float* w2 = scan.w[1 - cur];
    Vec3* v2 = scan.v[1 - cur];
    parallel_for(n_all, [=] WB_HD(int64_t q) {
      const int j = int(q % S);
      brush::Quat r{w[q], v[q]};
      if (j >= stride) r = brush::quat_normalize(brush::quat_mul(r, brush::Quat{w[q - stride], v[q - stride]}));
      w2[q] = r.w;
      v2[q] = r.v;
    });
  }
  const float* w = scan.w[cur];
  const Vec3* v = scan.v[cur];
  parallel_for(n_all, [=] WB_HD(int64_t q) {
    const int64_t base = q - q % S;
    const Vec3 t = sv.t[q];
    const Vec3 n0 = normal_to(sv.t[base]);
    const Vec3 c = brush::quat_rotate(brush::Quat{w[q], v[q]}, n0);
    // Made normal to t again against rounding (the carried n is normal to it but for that).
    const Vec3 n = normalize_or(c - t * dot(t, c), normal_to(t));
    sv.n[q] = n;
    sv.b[q] = cross(t, n);
  });
}

void samples_motion(SampleView sv, SamplePrev prev, float dt, int history) {
  const float inv_dt = 1.f / dt;
  parallel_for(sv.count(), [=] WB_HD(int64_t q) {
    if (history < 1) {
      sv.v[q] = sv.omega[q] = sv.a[q] = sv.alpha[q] = Vec3();
      return;
    }
    const Vec3 v = (sv.x[q] - prev.x[q]) * inv_dt;
    const Mat3 F = Mat3::from_columns(sv.t[q], sv.n[q], sv.b[q]);
    const Mat3 F0 = Mat3::from_columns(prev.t[q], prev.n[q], cross(prev.t[q], prev.n[q]));
    const Vec3 omega = brush::rotation_vector(F * transpose(F0)) * inv_dt;  // canvas frame
    sv.v[q] = v;
    sv.omega[q] = omega;
    if (history < 2) {
      sv.a[q] = sv.alpha[q] = Vec3();
    } else {
      sv.a[q] = (v - prev.v[q]) * inv_dt;
      sv.alpha[q] = (omega - prev.omega[q]) * inv_dt;
    }
  });
}

void samples_z(SampleView sv, float* z) {
  parallel_for(sv.count(), [=] WB_HD(int64_t q) { z[q] = sv.x[q].z; });
}

void samples_rasterize(SampleView sv, float radius, Int3 origin, Int3 dims, float* psi, float* vx, float* vy,
                       float* vz, TouchList cells) {
  const int S = sv.per_bristle;
  parallel_for(sv.count(), [=] WB_HD(int64_t q) {
    const int j = int(q % S);
    const Vec3 x = sv.x[q];
    const float gp = j > 0 ? length(x - sv.x[q - 1]) : 0.f;
    const float gn = j < S - 1 ? length(sv.x[q + 1] - x) : 0.f;
    const float vol = brush::sample_volume(radius, gp, gn);
    // Cell-centred trilinear splat: cell (i, j, k) of the window is centred at origin + (i, j, k) + 0.5.
    const float gx = x.x - origin.x - 0.5f, gy = x.y - origin.y - 0.5f, gz = x.z - origin.z - 0.5f;
    const int i0 = brush::floor_to_int(gx), j0 = brush::floor_to_int(gy), k0 = brush::floor_to_int(gz);
    if (i0 < -1 || j0 < -1 || k0 < -1 || i0 >= dims.x || j0 >= dims.y || k0 >= dims.z) return;
    const float fx = gx - i0, fy = gy - j0, fz = gz - k0;
    const Vec3 v = sv.v[q];
    for (int c = 0; c < 8; ++c) {
      const int ci = i0 + (c & 1), cj = j0 + ((c >> 1) & 1), ck = k0 + ((c >> 2) & 1);
      if (ci < 0 || cj < 0 || ck < 0 || ci >= dims.x || cj >= dims.y || ck >= dims.z) continue;
      const float w = ((c & 1) ? fx : 1.f - fx) * (((c >> 1) & 1) ? fy : 1.f - fy) * (((c >> 2) & 1) ? fz : 1.f - fz);
      if (w <= 0.f) continue;
      const int64_t at = (int64_t(ck) * dims.y + cj) * dims.x + ci;
      const float m = w * vol;
      atomic_add(&psi[at], m);
      atomic_add(&vx[at], m * v.x);
      atomic_add(&vy[at], m * v.y);
      atomic_add(&vz[at], m * v.z);
      if (cells.on()) cells.touch(at);
    }
  });
}

namespace brush_detail {
/// Cell i of the bristles' raster from its sums: the mean velocity, psi clamped to 1.
WB_HD WB_INLINE void finish_raster_cell(int64_t i, float* psi, float* vx, float* vy, float* vz) {
  const float p = psi[i];
  if (p <= 0.f) return;
  vx[i] /= p;  // divided: p may be subnormal
  vy[i] /= p;
  vz[i] /= p;
  psi[i] = minf(p, 1.f);
}
}  // namespace brush_detail

void samples_rasterize_finish(int64_t n, float* psi, float* vx, float* vy, float* vz, TouchList cells) {
  if (cells.on()) {  // the cells the splat listed: the others hold 0
    parallel_for_count(cells.count, n, [=] WB_HD(int64_t t) {
      brush_detail::finish_raster_cell(cells.items[t], psi, vx, vy, vz);
    });
  } else {
    parallel_for(n, [=] WB_HD(int64_t i) { brush_detail::finish_raster_cell(i, psi, vx, vy, vz); });
  }
}

void samples_raster_clear(int64_t n, float* psi, float* vx, float* vy, float* vz, TouchList cells) {
  parallel_for_count(cells.count, n, [=] WB_HD(int64_t t) {
    const int64_t i = cells.items[t];
    psi[i] = vx[i] = vy[i] = vz[i] = 0.f;
    cells.listed[i] = 0;
  });
}

void samples_contact_keys(SampleView sv, SolidField solid, float contact_height, int32_t* trace, int trace_w,
                          int trace_h, int ox, int oy, uint32_t* keys, uint32_t* vals) {
  const uint32_t sentinel = uint32_t(trace_w) * uint32_t(trace_h);
  parallel_for(sv.count(), [=] WB_HD(int64_t q) {
    const Vec3 x = sv.x[q];
    vals[q] = uint32_t(q);
    keys[q] = sentinel;
    if (!(x.z - brush::ground_below(solid, x, contact_height) < contact_height)) return;
    const int cx = brush::floor_to_int(x.x) - ox, cy = brush::floor_to_int(x.y) - oy;
    if (cx < 0 || cy < 0 || cx >= trace_w || cy >= trace_h) return;
    const uint32_t at = uint32_t(cy) * uint32_t(trace_w) + uint32_t(cx);
    atomic_or(&trace[at], 1);
    keys[q] = at;
  });
}

void count_distinct_flags(const uint32_t* keys, int64_t n, uint32_t sentinel, float* flags) {
  parallel_for(n, [=] WB_HD(int64_t i) {
    flags[i] = keys[i] != sentinel && (i == 0 || keys[i - 1] != keys[i]) ? 1.f : 0.f;
  });
}

}  // namespace wb::WB_BACKEND_NS
