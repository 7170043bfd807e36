// Pieces of the synthetic scenes of the particle and transfer benchmarks (the paper's
// Figure 12 load).
#pragma once
#include <random>
#include <vector>

#include "core/math/vec.h"

namespace wb::bench {

/// n particle positions around the samples: 90 % within 8 cells of a random sample, every
/// tenth up to 40 cells away; none below the canvas (z mirrored).
inline std::vector<Vec3> positions_around(const std::vector<Vec3>& samples, size_t n, std::mt19937& rng) {
  std::uniform_real_distribution<float> U(0.f, 1.f);
  std::vector<Vec3> x(n);
  for (size_t k = 0; k < n; ++k) {
    const Vec3 s = samples[size_t(U(rng) * float(samples.size() - 1))];
    const float reach = k % 10 == 0 ? 40.f : 8.f;
    Vec3 o;
    do o = Vec3(2.f * U(rng) - 1.f, 2.f * U(rng) - 1.f, 2.f * U(rng) - 1.f);
    while (length2(o) > 1.f);
    x[k] = s + o * reach;
    if (x[k].z < 0.f) x[k].z = -x[k].z;
  }
  return x;
}

}  // namespace wb::bench
