// Particle stage drivers (paper §4.3, Eq. 8-11), compiled once per backend: one
// parallel_for per stage over the particles (or faces), physics in the *_kernels.h.
#pragma once
#include "core/exec/parallel_for.h"
#include "core/particles/particles.h"

namespace wb::WB_BACKEND_NS {

void particles_adhesion_step(ParticleView p, SampleView s, SolidView solid, ParticleParams prm, float dt) {
  const int64_t n_samples = s.count();
  parallel_for(p.count, [=] WB_HD(int64_t k) {
    Vec3 x = p.x[k], v = p.v[k];
    if (!isfinite3(x) || !isfinite3(v)) return;  // left as it is for the step's containment to remove
    const int32_t j = p.nearest[k];
    if (j >= 0 && j < n_samples) {
      const SampleFrame f = load_sample(s, j);
      adhesion_update(x, v, &f, p.d_B[k], solid, prm, dt);
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

void particles_rasterise(ParticleView p, ParticleRasterView g) {
  const int64_t n = p.count, chunks = (n + kRasterRun - 1) / kRasterRun;
  parallel_for(
      chunks,
      [=] WB_HD(int64_t c) {
        const int64_t k0 = c * kRasterRun;
        rasterise_particles(g, p.x, p.v, p.m, p.oil, k0, k0 + kRasterRun < n ? k0 + kRasterRun : n);
      },
      kMinParallelSize / kRasterRun);
}

void particles_face_velocity(ParticleRasterView g, float* u, float* v, float* w, float empty) {
  const int64_t nu = int64_t(g.nx + 1) * g.ny * g.nz, nv = int64_t(g.nx) * (g.ny + 1) * g.nz,
                nw = int64_t(g.nx) * g.ny * (g.nz + 1);
  parallel_for(nu, [=] WB_HD(int64_t f) { u[f] = face_velocity(g.face[0][f], empty); });
  parallel_for(nv, [=] WB_HD(int64_t f) { v[f] = face_velocity(g.face[1][f], empty); });
  parallel_for(nw, [=] WB_HD(int64_t f) { w[f] = face_velocity(g.face[2][f], empty); });
}

void particles_flip_pic(ParticleView p, MacView before, MacView after, float gamma) {
  parallel_for(p.count, [=] WB_HD(int64_t k) {
    const Vec3 x = p.x[k];
    p.v[k] = flip_pic_velocity(p.v[k], before.sample(x), after.sample(x), gamma);
  });
}

void particles_keep_flags(const uint32_t* dead, uint32_t* keep, int64_t n) {
  parallel_for(n, [=] WB_HD(int64_t i) { keep[i] = dead[i] ? 0u : 1u; });
}

void particles_compact_state(ParticleView p, ParticleStateView to, const uint32_t* pos, int64_t n) {
  parallel_for(n, [=] WB_HD(int64_t i) {
    if (p.dead[i]) return;
    const int64_t k = pos[i];
#define WB_X(type, name, doc) to.name[k] = p.name[i];
    WB_PARTICLE_STATE_FIELDS(WB_X)
#undef WB_X
  });
}

void particles_cell_keys(ParticleView p, Int3 origin, Int3 dims, uint32_t* keys, uint32_t* index) {
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

void particles_gather_state(ParticleView p, ParticleStateView to, const uint32_t* from, int64_t n) {
  parallel_for(n, [=] WB_HD(int64_t i) {
    const int64_t k = from[i];
#define WB_X(type, name, doc) to.name[i] = p.name[k];
    WB_PARTICLE_STATE_FIELDS(WB_X)
#undef WB_X
  });
}

void particles_init_scratch(ParticleView p, int64_t first, int64_t n) {
  parallel_for(n, [=] WB_HD(int64_t i) {
    const int64_t k = first + i;
    p.nearest[k] = -1;
    p.d_B[k] = 0.f;
    p.dead[k] = 0u;
  });
}

void particles_solid_height(PaintWindowView pw, const float* particle_density, float dry_threshold,
                            float liquid_threshold, float floor_z, float* height, float* wet_top) {
  parallel_for(int64_t(pw.nx) * pw.ny, [=] WB_HD(int64_t c) {
    const int64_t layer = int64_t(pw.nx) * pw.ny;
    int above = 0;
    const float surface = column_solid_top(pw, c, dry_threshold, floor_z, above);
    // The grid holds one state per cell: wet paint cannot share a cell with dried paint, so over
    // a partly filled dried top the particles' floor is that cell's top.
    const float top = above > 0 ? maxf(floor_z, float(pw.oz + above)) : surface;
    height[c] = top;
    if (!wet_top) return;
    // The highest liquid cell over it (the grid's joint liquid test) is the wet paint's free surface.
    float wet = top;
    for (int k = pw.nz - 1; k >= above; --k) {
      const int64_t id = int64_t(k) * layer + c;
      const float joint = pw.density[id] + (particle_density ? particle_density[id] : 0.f);
      if (joint >= liquid_threshold) {
        wet = maxf(top, float(pw.oz + k) + minf(joint, 1.f));
        break;
      }
    }
    wet_top[c] = wet;
  });
}

void particles_ground_surface(PaintWindowView pw, const float* particle_density, float dry_threshold,
                              float liquid_threshold, float floor_z, float* surface) {
  parallel_for(int64_t(pw.nx) * pw.ny, [=] WB_HD(int64_t c) {
    const int64_t layer = int64_t(pw.nx) * pw.ny;
    int above = 0;
    float top = column_solid_top(pw, c, dry_threshold, floor_z, above);
    // Up from the solid through liquid cells (the joint test) to the first that is not, counting
    // its partial fill: paint held up in the air by the bristles, above a gap, is not ground.
    for (int k = above; k < pw.nz; ++k) {
      const int64_t id = int64_t(k) * layer + c;
      const float joint = pw.density[id] + (particle_density ? particle_density[id] : 0.f);
      top = maxf(top, float(pw.oz + k) + minf(joint, 1.f));
      if (joint < liquid_threshold) break;
    }
    surface[c] = top;
  });
}

}  // namespace wb::WB_BACKEND_NS
