// Parameters of the particle stage (paper §4.3 Eq. 8-11, Table 1). One POD, passed
// by value to the stage drivers. Units: lengths in canvas cells (1 cell = 0.2 mm),
// velocities in cells/s, time in s. Table 1 distances converted with that cell size.
#pragma once
#include <cstdint>

#include "core/math/vec.h"

namespace wb {

struct ParticleParams {
  /// Inertial weight of the local-frame update. Default 0.1, range [0, 0.2]. Table 1, Eq. 9.
  float beta_L = 0.1f;
  /// Adhesion range: blend weight max(1 - d_B/D1, 0). Default 15 cells (0.3 cm), range [0, 100]. Table 1, Eq. 10.
  float D1 = 15.f;
  /// Particle range around the bristles (grid <-> particle conversion, §5.2); also the cap of d_B.
  /// Default 50 cells (1 cm), range [D1, 200]. Table 1.
  float D0 = 50.f;
  /// Friction range delta: friction vanishes beyond 1/delta. Default 0.1 / cell (1/0.2 cm), range [0.01, 1]. Table 1, Eq. 8.
  float delta = 0.1f;
  /// Friction rate at the surface k, 1/s: Eq. 8's drag read as dv/dt = -k w v. Default 600, range
  /// [0, 1e6]: the viscous relaxation rate mu / (rho0 L^2) of a layer as deep as the friction range
  /// L = 1/delta = 2 mm, with the stiff paint's apparent viscosity under a brisk stroke (K gamma^(n-1)
  /// = 30 Pa s^0.5 at gamma = 160/s: 2.4 Pa s) and rho0 = 1000 kg/m^3 (docs/PARTICLES.md).
  float friction_rate = 600.f;
  /// PIC weight of the velocity update (FLIP weight 1 - gamma). Default 0.8, range [0, 1]. Table 1, Eq. 11.
  float gamma = 0.8f;
  /// Gravity, cells/s^2, canvas frame (z up). Default 9.81 m/s^2 = 49050 cells/s^2 down, range |g| in [0, 49050]. Eq. 9.
  /// The Simulator sets it from the grid's (GridParams::gravity_vector: magnitude and canvas tilt).
  Vec3 gravity = Vec3(0.f, 0.f, -49050.f);
  /// Height of the canvas surface (solid floor), cells. Default 0. Eq. 8 (d_k).
  float floor_z = 0.f;
  /// Cell size of the sample grid, cells. Default 2, range [1, D1]. Green 2010, §6. A nearest
  /// query stops at the first ring of cells beyond its best distance, and most particles lie
  /// within a cell or two of a sample: small cells check fewer samples (docs/PARTICLES.md). Its
  /// table has a cell per h^3 of the queries' region (the window's columns, the canvas's depth).
  float sample_cell = 2.f;
  /// Most particles the store may hold. Default 2M, range [1, 2^31). §7 ("as many as 2M particles").
  int64_t max_particles = 2000000;
};

}  // namespace wb
