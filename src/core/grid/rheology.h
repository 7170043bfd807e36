// Grid stage, rheology of oil paint (docs/GRID.md "Rheology"): a regularised Herschel–Bulkley
// fluid. The paper's paint is Newtonian with a viscosity from the oil fraction (§4.2); oil paint
// is shear-thinning with a yield stress: it flows under the brush and holds its ridges at rest.
// Stresses in Pa, consistency in Pa s^n, strain rates in 1/s (velocity in cells/s over cells).
#pragma once
#include <math.h>

#include "core/grid/grid_fields.h"
#include "core/grid/project_kernels.h"
#include "core/math/vec.h"

namespace wb {

/// Paint of oil fraction `oil` between the stiff (oil 0) and oily (oil 1) end members: tau_y and K
/// interpolate geometrically (they span decades), n linearly.
WB_HD WB_INLINE HerschelBulkley rheology_at_oil(float oil, HerschelBulkley stiff, HerschelBulkley oily) {
  oil = clampf(oil, 0.f, 1.f);
  auto geo = [oil](float a, float b) { return (a > 0.f && b > 0.f) ? a * powf(b / a, oil) : a + (b - a) * oil; };
  return HerschelBulkley{geo(stiff.tau_y, oily.tau_y), geo(stiff.K, oily.K), stiff.n + (oily.n - stiff.n) * oil};
}

/// Apparent viscosity mu = tau / gamma_dot, Pa s, regularised at vanishing strain rate with
/// Papanastasiou's exponential (J. Rheol. 31, 1987) for the yield term, and the same critical rate
/// 1/m for the power law: mu(0) = tau_y m + K m^(1-n), finite, so the unyielded paint is a very
/// viscous liquid (creeping at tau / mu(0)) rather than a singular solid.
WB_HD WB_INLINE float apparent_viscosity(const HerschelBulkley& hb, float gamma_dot, float m) {
  gamma_dot = maxf(gamma_dot, 0.f);
  const float x = m * gamma_dot;
  // (1 - e^-x) / gamma_dot, with its series near 0 where the quotient loses precision.
  const float yield_term = x < 1e-3f ? m * (1.f - 0.5f * x) : (1.f - expf(-x)) / gamma_dot;
  return hb.tau_y * yield_term + hb.K * powf(gamma_dot + 1.f / m, hb.n - 1.f);
}

/// Mixture velocity of a face, theta u + (1 - theta) u_solid (what the paint there moves with).
WB_HD WB_INLINE float mixture_velocity(const GridView& g, int c, int64_t f) {
  const float t = g.theta[c][f];
  return t * g.vel[c][f] + (1.f - t) * g.solid_vel[c][f];
}

/// Magnitude of the strain rate sqrt(2 D:D) at the centre of cell (i,j,k), 1/s, with
/// D = (grad u + grad u^T) / 2 from the mixture face velocities. Normal rates are the MAC face
/// differences; shear rates central differences of the cell-centred velocity, mirrored against
/// the canvas floor and dried paint (no slip) and held constant toward air and the window's walls
/// (a free surface carries no shear).
WB_HD WB_INLINE float cell_strain_rate(const GridView& g, int i, int j, int k) {
  const GridDims& d = g.d;
  // Cell-centred velocity component a of cell (ii,jj,kk), assumed in the window.
  auto centred = [&](int a, int ii, int jj, int kk) {
    const int64_t f0 = d.fidx(a, ii, jj, kk);
    const int64_t f1 = d.fidx(a, ii + (a == 0), jj + (a == 1), kk + (a == 2));
    return 0.5f * (mixture_velocity(g, a, f0) + mixture_velocity(g, a, f1));
  };
  float grad[3][3];  // grad[a][b] = d u_a / d x_b
  for (int a = 0; a < 3; ++a) {
    const float ua = centred(a, i, j, k);
    for (int b = 0; b < 3; ++b) {
      if (a == b) {
        const int64_t f0 = d.fidx(a, i, j, k);
        const int64_t f1 = d.fidx(a, i + (a == 0), j + (a == 1), k + (a == 2));
        grad[a][b] = mixture_velocity(g, a, f1) - mixture_velocity(g, a, f0);
        continue;
      }
      float side[2];
      for (int s = 0; s < 2; ++s) {
        const int o = s ? 1 : -1;
        const int ii = i + (b == 0 ? o : 0), jj = j + (b == 1 ? o : 0), kk = k + (b == 2 ? o : 0);
        if (kk < 0) {
          side[s] = -ua;  // the canvas floor: u = 0 half a cell below the centre
        } else if (ii < 0 || jj < 0 || ii >= d.nx || jj >= d.ny || kk >= d.nz) {
          side[s] = ua;
        } else {
          const uint8_t cl = g.cls[d.cell(ii, jj, kk)];
          side[s] = cl == kCellSolid ? -ua : (cl == kCellAir ? ua : centred(a, ii, jj, kk));
        }
      }
      grad[a][b] = 0.5f * (side[1] - side[0]);
    }
  }
  float dd = 0.f;
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) {
      const float e = 0.5f * (grad[a][b] + grad[b][a]);
      dd += e * e;
    }
  return sqrtf(2.f * dd);
}

}  // namespace wb
