#include "core/sim/joint_fields.h"

#include "core/exec/dispatch.h"

namespace wb {

void joint_scale(const Device& d, const float* in, float* out, int64_t n, float scale) {
  WB_DISPATCH(d, joint_scale(in, out, n, scale));
}
void joint_raster_density(const Device& d, const FloatPair* cell, float* density, float* oil, int64_t n, float scale) {
  WB_REQUIRE(n == 0 || (cell && density), "joint_raster_density: a field is null");
  WB_DISPATCH(d, joint_raster_density(cell, density, oil, n, scale));
}
void joint_blend_velocity(const Device& d, GridView g, PaintWindowView paint, ParticleRasterView raster,
                          float cell_mass) {
  WB_REQUIRE(raster.nx == g.d.nx && raster.ny == g.d.ny && raster.nz == g.d.nz,
             "joint_blend_velocity: particle raster and grid differ in size");
  WB_REQUIRE(raster.face[0] && raster.face[1] && raster.face[2], "joint_blend_velocity: the raster has no faces");
  WB_DISPATCH(d, joint_blend_velocity(g, paint, raster, cell_mass));
}
void joint_zero_nonfinite(const Device& d, float* v, int64_t n) { WB_DISPATCH(d, joint_zero_nonfinite(v, n)); }
void joint_clamp_to_canvas(const Device& d, ParticleView p, Vec3 lo, Vec3 hi) {
  WB_DISPATCH(d, joint_clamp_to_canvas(p, lo, hi));
}
void joint_kill_nonfinite(const Device& d, ParticleView p) { WB_DISPATCH(d, joint_kill_nonfinite(p)); }
void joint_ground_under(const Device& d, PaintWindowView pw, float dry_threshold, float cx, float cy, float r,
                        float floor_z, float* out) {
  WB_DISPATCH(d, joint_ground_under(pw, dry_threshold, cx, cy, r, floor_z, out));
}
void joint_sample_extent(const Device& d, const Vec3* x, int64_t n, float z_top, float* out) {
  WB_DISPATCH(d, joint_sample_extent(x, n, z_top, out));
}

}  // namespace wb
