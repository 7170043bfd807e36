// Particle stage: validation and the one runtime dispatch (paper §4.3).
#include "core/particles/particles.h"

#include <cmath>
#include <string>

#include "core/exec/dispatch.h"
#include "core/exec/error.h"

namespace wb {
namespace {
void check_params(const ParticleParams& prm, float dt) {
  WB_REQUIRE(std::isfinite(dt) && dt > 0.f, "particles: time step must be positive, got " + std::to_string(dt));
  WB_REQUIRE(prm.beta_L >= 0.f && prm.beta_L <= 1.f, "particles: beta_L must lie in [0, 1], got " + std::to_string(prm.beta_L));
  WB_REQUIRE(prm.D1 >= 0.f && std::isfinite(prm.D1), "particles: D1 must be >= 0, got " + std::to_string(prm.D1));
  WB_REQUIRE(prm.delta >= 0.f && std::isfinite(prm.delta), "particles: delta must be >= 0, got " + std::to_string(prm.delta));
  WB_REQUIRE(isfinite3(prm.gravity), "particles: gravity is not finite");
}
void check_grid(int nx, int ny, int nz, const char* what) {
  WB_REQUIRE(nx > 0 && ny > 0 && nz > 0, std::string("particles: ") + what + " has an empty window (" +
                                             std::to_string(nx) + " x " + std::to_string(ny) + " x " +
                                             std::to_string(nz) + ")");
}
}  // namespace

void particles_adhesion_step(const Device& d, const ParticleView& p, const SampleView& s, const SolidView& solid,
                             const ParticleParams& prm, float dt) {
  check_params(prm, dt);
  WB_REQUIRE(p.count >= 0, "particles_adhesion_step: negative particle count");
  WB_REQUIRE(solid.height == nullptr || (solid.nx > 0 && solid.ny > 0),
             "particles_adhesion_step: solid height map without extent");
  WB_DISPATCH(d, particles_adhesion_step(p, s, solid, prm, dt));
}

void particles_rasterise(const Device& d, const ParticleView& p, const ParticleRasterView& g) {
  check_grid(g.nx, g.ny, g.nz, "rasterisation target");
  const bool faces = g.face[0] && g.face[1] && g.face[2];
  const bool cells_only = !g.face[0] && !g.face[1] && !g.face[2];
  WB_REQUIRE(g.cell && (faces || cells_only), "particles_rasterise: a target field is null");
  WB_DISPATCH(d, particles_rasterise(p, g));
}

void particles_face_velocity(const Device& d, const ParticleRasterView& g, float* const vel[3], float empty) {
  check_grid(g.nx, g.ny, g.nz, "face velocity");
  WB_REQUIRE(g.face[0] && g.face[1] && g.face[2], "particles_face_velocity: a rasterised face field is null");
  WB_REQUIRE(vel[0] && vel[1] && vel[2], "particles_face_velocity: an output field is null");
  WB_DISPATCH(d, particles_face_velocity(g, vel[0], vel[1], vel[2], empty));
}

void particles_flip_pic(const Device& d, const ParticleView& p, const MacView& before, const MacView& after,
                        float gamma) {
  WB_REQUIRE(gamma >= 0.f && gamma <= 1.f, "particles_flip_pic: gamma must lie in [0, 1], got " + std::to_string(gamma));
  check_grid(before.nx, before.ny, before.nz, "FLIP/PIC field before projection");
  check_grid(after.nx, after.ny, after.nz, "FLIP/PIC field after projection");
  WB_REQUIRE(before.nx == after.nx && before.ny == after.ny && before.nz == after.nz && before.ox == after.ox &&
                 before.oy == after.oy && before.oz == after.oz,
             "particles_flip_pic: the fields before and after projection cover different windows");
  WB_DISPATCH(d, particles_flip_pic(p, before, after, gamma));
}

void particles_keep_flags(const Device& d, const uint32_t* dead, uint32_t* keep, int64_t n) {
  WB_DISPATCH(d, particles_keep_flags(dead, keep, n));
}
void particles_compact_state(const Device& d, const ParticleView& p, const ParticleStateView& to, const uint32_t* pos,
                             int64_t n) {
  WB_DISPATCH(d, particles_compact_state(p, to, pos, n));
}
void particles_solid_height(const Device& d, const PaintWindowView& pw, const float* particle_density,
                            float dry_threshold, float liquid_threshold, float floor_z, float* height,
                            float* wet_top) {
  WB_REQUIRE(pw.density && pw.dryness && height, "particles_solid_height: missing fields");
  WB_REQUIRE(std::isfinite(dry_threshold) && dry_threshold > 0.f && std::isfinite(liquid_threshold) &&
                 liquid_threshold > 0.f && std::isfinite(floor_z),
             "particles_solid_height: bad threshold or floor");
  WB_DISPATCH(d, particles_solid_height(pw, particle_density, dry_threshold, liquid_threshold, floor_z, height, wet_top));
}

void particles_cell_keys(const Device& d, const ParticleView& p, Int3 origin, Int3 dims, uint32_t* keys,
                         uint32_t* index) {
  WB_REQUIRE(dims.x > 0 && dims.y > 0 && dims.z > 0 && int64_t(8) * dims.x * dims.y * dims.z < (int64_t(1) << 31),
             "particles_cell_keys: the window's cells do not fit a key");
  WB_DISPATCH(d, particles_cell_keys(p, origin, dims, keys, index));
}
void particles_gather_state(const Device& d, const ParticleView& p, const ParticleStateView& to, const uint32_t* from,
                            int64_t n) {
  WB_DISPATCH(d, particles_gather_state(p, to, from, n));
}
void particles_init_scratch(const Device& d, const ParticleView& p, int64_t first, int64_t n) {
  WB_DISPATCH(d, particles_init_scratch(p, first, n));
}

void particles_ground_surface(const Device& d, const PaintWindowView& pw, const float* particle_density,
                              float dry_threshold, float liquid_threshold, float floor_z, float* surface) {
  WB_REQUIRE(pw.density && pw.dryness && surface, "particles_ground_surface: missing fields");
  WB_REQUIRE(std::isfinite(dry_threshold) && dry_threshold > 0.f && std::isfinite(liquid_threshold) &&
                 liquid_threshold > 0.f && std::isfinite(floor_z),
             "particles_ground_surface: bad threshold or floor");
  WB_DISPATCH(d, particles_ground_surface(pw, particle_density, dry_threshold, liquid_threshold, floor_z, surface));
}

}  // namespace wb
