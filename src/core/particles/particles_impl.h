// Particle stage drivers (paper §4.3, Eq. 8-11), compiled once per backend: one
// parallel_for per stage over the particles (or faces), physics in the *_kernels.h.
#pragma once
#include <cmath>
#include <string>

#include "core/exec/error.h"
#include "core/exec/parallel_for.h"
#include "core/particles/particles.h"

namespace wb::WB_BACKEND_NS {

namespace detail {
void check_params(const ParticleParams& prm, float dt) {
  WB_REQUIRE(std::isfinite(dt) && dt > 0.f, "particles: time step must be positive, got " + std::to_string(dt));
  WB_REQUIRE(prm.beta_L >= 0.f && prm.beta_L <= 1.f,
             "particles: beta_L must lie in [0, 1], got " + std::to_string(prm.beta_L));
  WB_REQUIRE(prm.D1 >= 0.f && std::isfinite(prm.D1), "particles: D1 must be >= 0, got " + std::to_string(prm.D1));
  WB_REQUIRE(prm.delta >= 0.f && std::isfinite(prm.delta),
             "particles: delta must be >= 0, got " + std::to_string(prm.delta));
  WB_REQUIRE(isfinite3(prm.gravity), "particles: gravity is not finite");
}
void check_grid(int nx, int ny, int nz, const char* what) {
  WB_REQUIRE(nx > 0 && ny > 0 && nz > 0, std::string("particles: ") + what + " has an empty window (" +
                                             std::to_string(nx) + " x " + std::to_string(ny) + " x " +
                                             std::to_string(nz) + ")");
}
}  // namespace detail

/// Two-step adhesion update of every particle (Eq. 8-10) over dt seconds. Needs the
/// particles' nearest / d_B from SampleGrid::query_nearest with a range >= prm.D1 on
/// the same samples. Positions and velocities are updated in place; `motion` is scratch for
/// s.count() samples.
void particles_adhesion_step(ParticleView p, SampleView s, SolidView solid, ParticleParams prm, float dt,
                             SampleMotion* motion) {
  detail::check_params(prm, dt);
  WB_REQUIRE(p.count >= 0, "particles_adhesion_step: negative particle count");
  WB_REQUIRE(solid.height == nullptr || (solid.nx > 0 && solid.ny > 0),
             "particles_adhesion_step: solid height map without extent");
  const int64_t n_samples = s.count();
  WB_REQUIRE(n_samples == 0 || motion, "particles_adhesion_step: no room for the samples' motion");
  // Each sample's part of Eq. 9 once, not once for each particle it holds.
  parallel_for(n_samples, [=] WB_HD(int64_t j) { motion[j] = sample_motion(load_sample(s, j), dt); });
  parallel_for(p.count, [=] WB_HD(int64_t k) {
    Vec3 x = p.x[k], v = p.v[k];
    if (!isfinite3(x) || !isfinite3(v)) return;  // left as it is for the step's containment to remove
    const int32_t j = p.nearest[k];
    if (j >= 0 && j < n_samples) {
      adhesion_update(x, v, motion + j, p.d_B[k], solid, prm, dt);
    } else {
      adhesion_update(x, v, nullptr, p.d_B[k], solid, prm, dt);
    }
    p.x[k] = x;
    p.v[k] = v;
  });
}

#if defined(__CUDACC__)
constexpr int64_t kRasterRun = 1;  // a thread a particle: the device's atomics are cheap
#else
constexpr int64_t kRasterRun = 64;  // a thread's particles in order, their runs summed first
#endif

/// Adds the particles' mass (cell centres) and momentum and mass weight (MAC faces) into g,
/// trilinearly (flip_kernels.h); the mass only when the face fields are all null. Particles
/// outside the window are skipped.
void particles_rasterise(ParticleView p, ParticleRasterView g) {
  detail::check_grid(g.nx, g.ny, g.nz, "rasterisation target");
  const bool faces = g.face[0] && g.face[1] && g.face[2];
  const bool cells_only = !g.face[0] && !g.face[1] && !g.face[2];
  WB_REQUIRE(g.cell && (faces || cells_only), "particles_rasterise: a target field is null");
  const int64_t n = p.count, chunks = (n + kRasterRun - 1) / kRasterRun;
  parallel_for(
      chunks,
      [=] WB_HD(int64_t c) {
        const int64_t k0 = c * kRasterRun;
        rasterise_particles(g, p.x, p.v, p.m, p.oil, k0, k0 + kRasterRun < n ? k0 + kRasterRun : n);
      },
      kMinParallelSize / kRasterRun);
}

/// (u, v, w)[f] = momentum / weight on faces with weight > 0, else `empty` (e.g. 0).
void particles_face_velocity(ParticleRasterView g, float* u, float* v, float* w, float empty) {
  detail::check_grid(g.nx, g.ny, g.nz, "face velocity");
  WB_REQUIRE(g.face[0] && g.face[1] && g.face[2], "particles_face_velocity: a rasterised face field is null");
  WB_REQUIRE(u && v && w, "particles_face_velocity: an output field is null");
  const int64_t nu = int64_t(g.nx + 1) * g.ny * g.nz, nv = int64_t(g.nx) * (g.ny + 1) * g.nz,
                nw = int64_t(g.nx) * g.ny * (g.nz + 1);
  parallel_for(nu, [=] WB_HD(int64_t f) { u[f] = face_velocity(g.face[0][f], empty); });
  parallel_for(nv, [=] WB_HD(int64_t f) { v[f] = face_velocity(g.face[1][f], empty); });
  parallel_for(nw, [=] WB_HD(int64_t f) { w[f] = face_velocity(g.face[2][f], empty); });
}

/// Eq. 11 for every particle: before = joint field u before projection, after = u_bar.
void particles_flip_pic(ParticleView p, MacView before, MacView after, float gamma) {
  WB_REQUIRE(gamma >= 0.f && gamma <= 1.f,
             "particles_flip_pic: gamma must lie in [0, 1], got " + std::to_string(gamma));
  detail::check_grid(before.nx, before.ny, before.nz, "FLIP/PIC field before projection");
  detail::check_grid(after.nx, after.ny, after.nz, "FLIP/PIC field after projection");
  WB_REQUIRE(before.nx == after.nx && before.ny == after.ny && before.nz == after.nz && before.ox == after.ox &&
                 before.oy == after.oy && before.oz == after.oz,
             "particles_flip_pic: the fields before and after projection cover different windows");
  parallel_for(p.count, [=] WB_HD(int64_t k) {
    // Both fields at the particle from one stencil (the windows are the same).
    const MacStencil s = mac_stencil(before.nx, before.ny, before.nz, before.local(p.x[k]));
    p.v[k] = flip_pic_velocity(p.v[k], s.of(before.u, before.v, before.w), s.of(after.u, after.v, after.w), gamma);
  });
}

/// Particles kept (particle_kept); used by ParticleStore::compact.
void particles_keep_flags(const uint32_t* dead, const float* m, uint32_t* keep, int64_t n) {
  parallel_for(n, [=] WB_HD(int64_t i) { keep[i] = particle_kept(dead[i], m[i]) ? 1u : 0u; });
}

/// to[pos[i]] = the state of particle i for every kept i < n; pos is the exclusive scan of the
/// keep flags (ParticleStore::compact).
void particles_compact_state(ParticleView p, ParticleStateView to, const uint32_t* pos, int64_t n) {
  parallel_for(n, [=] WB_HD(int64_t i) {
    if (!particle_kept(p.dead[i], p.m[i])) return;
    const int64_t k = pos[i];
#define WB_X(type, name, doc) to.name[k] = p.name[i];
    WB_PARTICLE_STATE_FIELDS(WB_X)
#undef WB_X
  });
}

/// Sort keys by half cell: keys[k] = the half cell (a window cell halved along each axis) of
/// particle k, numbered x fastest over the window of `dims` cells at canvas cell `origin` (the
/// half cells' count for a particle outside it or not finite), index[k] = k.
void particles_cell_keys(ParticleView p, Int3 origin, Int3 dims, uint32_t* keys, uint32_t* index) {
  WB_REQUIRE(dims.x > 0 && dims.y > 0 && dims.z > 0 && int64_t(8) * dims.x * dims.y * dims.z < (int64_t(1) << 31),
             "particles_cell_keys: the window's cells do not fit a key");
  parallel_for(p.count, [=] WB_HD(int64_t k) {
    const Vec3 x = p.x[k];
    const float q[3] = {x.x - float(origin.x), x.y - float(origin.y), x.z - float(origin.z)};
    const int n[3] = {dims.x, dims.y, dims.z};
    int c[3];
    bool inside = true;
    for (int a = 0; a < 3; ++a) {
      inside = inside && q[a] >= 0.f && q[a] < float(n[a]);  // false for a NaN as well
      c[a] = inside ? int(2.f * q[a]) : 0;
    }
    keys[k] = inside ? uint32_t((int64_t(c[2]) * (2 * n[1]) + c[1]) * (2 * n[0]) + c[0])
                     : uint32_t(int64_t(8) * n[0] * n[1] * n[2]);
    index[k] = uint32_t(k);
  });
}

/// to[i] = the state of particle from[i] for i < n: the particles in a new order
/// (ParticleStore::sort_by_cell).
void particles_gather_state(ParticleView p, ParticleStateView to, const uint32_t* from, int64_t n) {
  parallel_for(n, [=] WB_HD(int64_t i) {
    const int64_t k = from[i];
#define WB_X(type, name, doc) to.name[i] = p.name[k];
    WB_PARTICLE_STATE_FIELDS(WB_X)
#undef WB_X
  });
}

/// Scratch of particles [first, first + n): nearest = -1, d_B = 0, dead = 0.
void particles_init_scratch(ParticleView p, int64_t first, int64_t n) {
  parallel_for(n, [=] WB_HD(int64_t i) {
    const int64_t k = first + i;
    p.nearest[k] = -1;
    p.d_B[k] = 0.f;
    p.dead[k] = 0u;
  });
}

/// Height fields of what the particles rest on over the window's columns (SolidView), absolute
/// canvas z, nx * ny floats each: `height`, the top of the highest dried cell (dryness at or above
/// dry_threshold, the grid's solid test) as a whole cell (the grid holds one state a cell, so
/// wet paint over a partly filled dried cell starts at its top; column_solid_tops gives the paint's
/// own top), or floor_z where none; `wet_top` (nullable), the top
/// of the highest liquid cell above it, or `height` where none. Liquid is the grid's joint test:
/// density plus `particle_density` (the particles' raster, nullable) at or above liquid_threshold;
/// where the layer near the bristles is mostly particles (§5.2), its grid density alone is air.
void particles_solid_height(PaintWindowView pw, const float* particle_density, float dry_threshold,
                            float liquid_threshold, float floor_z, float* height, float* wet_top) {
  WB_REQUIRE(pw.density && pw.dryness && height, "particles_solid_height: missing fields");
  WB_REQUIRE(std::isfinite(dry_threshold) && dry_threshold > 0.f && std::isfinite(liquid_threshold) &&
                 liquid_threshold > 0.f && std::isfinite(floor_z),
             "particles_solid_height: bad threshold or floor");
  const int64_t layer = int64_t(pw.nx) * pw.ny;
  parallel_for_runs<kColumnLanes>(layer, [=] WB_HD(int64_t col0, int lanes) {
    // Down each column of the run at once, layer by layer (parallel_for_runs<kColumnLanes>): the highest
    // dried solid (column_solid_tops) and, above it, the highest liquid cell by the grid's joint
    // test, whose top is the wet paint's free surface.
    float solid[kColumnLanes], wet[kColumnLanes];
    int above[kColumnLanes];  // the first layer over the solid; -1 while none is found
    for (int l = 0; l < lanes; ++l) solid[l] = floor_z, wet[l] = -INFINITY, above[l] = -1;
    for (int k = pw.nz - 1; k >= 0; --k) {
      const int64_t c0 = int64_t(k) * layer + col0;
      for (int l = 0; l < lanes; ++l) {
        const int64_t id = c0 + l;
        const float rho = pw.density[id];
        const bool searching = above[l] < 0;
        const bool is_solid = searching & dried_solid(rho, pw.dryness[id], dry_threshold);
        const float joint = rho + (particle_density ? particle_density[id] : 0.f);
        const bool liquid = searching & !is_solid & (wet[l] == -INFINITY) & (joint >= liquid_threshold);
        solid[l] = is_solid ? maxf(floor_z, float(pw.oz + k) + minf(rho, 1.f)) : solid[l];
        above[l] = is_solid ? k + 1 : above[l];
        wet[l] = liquid ? float(pw.oz + k) + minf(joint, 1.f) : wet[l];
      }
    }
    for (int l = 0; l < lanes; ++l) {
      const int64_t c = col0 + l;
      // The grid holds one state per cell: wet paint cannot share a cell with dried paint, so over
      // a partly filled dried top the particles' floor is that cell's top.
      const float top = above[l] > 0 ? maxf(floor_z, float(pw.oz + above[l])) : solid[l];
      height[c] = top;
      if (wet_top) wet_top[c] = maxf(top, wet[l]);
    }
  });
}

/// The ground a particle in flight lands on, per window column (absolute canvas z): the solid's
/// top (as `height` above), raised through the liquid cells (joint test) stacked on it up to the
/// first that is not. Paint held up in the air above a gap is not ground.
void particles_ground_surface(PaintWindowView pw, const float* particle_density, float dry_threshold,
                              float liquid_threshold, float floor_z, float* surface) {
  WB_REQUIRE(pw.density && pw.dryness && surface, "particles_ground_surface: missing fields");
  WB_REQUIRE(std::isfinite(dry_threshold) && dry_threshold > 0.f && std::isfinite(liquid_threshold) &&
                 liquid_threshold > 0.f && std::isfinite(floor_z),
             "particles_ground_surface: bad threshold or floor");
  const int64_t layer = int64_t(pw.nx) * pw.ny;
  parallel_for_runs<kColumnLanes>(layer, [=] WB_HD(int64_t col0, int lanes) {
    float top[kColumnLanes];
    int above[kColumnLanes];
    column_solid_tops(pw, col0, lanes, dry_threshold, floor_z, top, above);
    for (int l = 0; l < lanes; ++l) {
      // Up from the solid through liquid cells (the joint test) to the first that is not, counting
      // its partial fill: paint held up in the air by the bristles, above a gap, is not ground.
      const int64_t c = col0 + l;
      float t = top[l];
      for (int k = above[l]; k < pw.nz; ++k) {
        const int64_t id = int64_t(k) * layer + c;
        const float joint = pw.density[id] + (particle_density ? particle_density[id] : 0.f);
        t = maxf(t, float(pw.oz + k) + minf(joint, 1.f));
        if (joint < liquid_threshold) break;
      }
      surface[c] = t;
    }
  });
}

}  // namespace wb::WB_BACKEND_NS
