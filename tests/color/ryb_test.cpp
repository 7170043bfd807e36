// Colour model (paper §6, Algorithm 2): the RYB cube, brightness-preserving mixing and the
// inverse used to pick colours.
#include <gtest/gtest.h>

#include <random>

#include "core/color/ryb.h"

namespace wb::test {

static float dist(Vec3 a, Vec3 b) { return length(a - b); }

TEST(Ryb, CornersMatchGossettChenCube) {
  EXPECT_LT(dist(ryb_to_rgb({0, 0, 0}), {1, 1, 1}), 1e-6f);
  EXPECT_LT(dist(ryb_to_rgb({1, 0, 0}), {1, 0, 0}), 1e-6f);
  EXPECT_LT(dist(ryb_to_rgb({0, 1, 0}), {1, 1, 0}), 1e-6f);
  EXPECT_LT(dist(ryb_to_rgb({0, 0, 1}), {0.163f, 0.373f, 0.6f}), 1e-6f);
  EXPECT_LT(dist(ryb_to_rgb({1, 1, 0}), {1, 0.5f, 0}), 1e-6f);
  EXPECT_LT(dist(ryb_to_rgb({1, 0, 1}), {0.5f, 0, 0.5f}), 1e-6f);
  EXPECT_LT(dist(ryb_to_rgb({0, 1, 1}), {0, 0.66f, 0.2f}), 1e-6f);
  EXPECT_LT(dist(ryb_to_rgb({1, 1, 1}), {0.2f, 0.094f, 0}), 1e-6f);
}

TEST(Ryb, JacobianMatchesFiniteDifferences) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0.05f, 0.95f);
  for (int k = 0; k < 50; ++k) {
    const Vec3 c(u(rng), u(rng), u(rng));
    const Mat3 J = ryb_to_rgb_jacobian(c);
    const float h = 1e-3f;
    for (int a = 0; a < 3; ++a) {
      Vec3 e(0, 0, 0);
      e[a] = h;
      const Vec3 fd = (ryb_to_rgb(c + e) - ryb_to_rgb(c - e)) / (2 * h);
      EXPECT_LT(dist(fd, J.col(a)), 2e-3f);
    }
  }
}

TEST(Ryb, BlueAndYellowMakeGreen) {
  const Vec3 m = color_mix({0, 0, 1}, {0, 1, 0}, 1.f, 1.f);
  const Vec3 rgb = ryb_to_rgb(m);
  EXPECT_GT(rgb.y, rgb.x + 0.1f) << rgb.x << " " << rgb.y << " " << rgb.z;
  EXPECT_GT(rgb.y, rgb.z + 0.1f);
}

TEST(Ryb, MixKeepsWeightedBrightness) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  int clamped = 0;
  for (int k = 0; k < 2000; ++k) {
    const Vec3 a(u(rng), u(rng), u(rng)), b(u(rng), u(rng), u(rng));
    const float wa = u(rng) + 0.01f, wb = u(rng) + 0.01f;
    const Vec3 m = color_mix(a, b, wa, wb);
    for (int i = 0; i < 3; ++i) {
      ASSERT_GE(m[i], 0.f);
      ASSERT_LE(m[i], 1.f + 1e-6f);
    }
    const float target = (wa * pigment_brightness(a) + wb * pigment_brightness(b)) / (wa + wb);
    const float got = pigment_brightness(m);
    const float mmax = std::max(m.x, std::max(m.y, m.z));
    if (mmax > 1.f - 1e-5f && got > target + 1e-4f) {
      ++clamped;  // the documented clamp: as dark as this hue gets inside the gamut
      continue;
    }
    ASSERT_NEAR(got, target, 1e-4f) << "mix " << k;
  }
  EXPECT_LT(clamped, 400);  // the clamp is the exception, not the rule
}

TEST(Ryb, MixIsSymmetricAndIdempotent) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  for (int k = 0; k < 500; ++k) {
    const Vec3 a(u(rng), u(rng), u(rng)), b(u(rng), u(rng), u(rng));
    const float wa = u(rng) + 0.01f, wb = u(rng) + 0.01f;
    EXPECT_LT(dist(color_mix(a, b, wa, wb), color_mix(b, a, wb, wa)), 1e-6f);
    EXPECT_LT(dist(color_mix(a, a, wa, wb), a), 1e-5f);
  }
  // Zero total weight and pure white are guarded.
  EXPECT_LT(dist(color_mix({0.3f, 0.2f, 0.1f}, {1, 1, 1}, 0.f, 0.f), {0.3f, 0.2f, 0.1f}), 1e-7f);
  EXPECT_LT(dist(color_mix({0, 0, 0}, {0, 0, 0}, 1.f, 2.f), {0, 0, 0}), 1e-7f);
}

TEST(Ryb, ManyColourMixMatchesPairwiseForTwo) {
  const Vec3 c[3] = {{0.9f, 0.1f, 0.f}, {0.f, 0.2f, 0.8f}, {0.5f, 0.5f, 0.5f}};
  const float w2[3] = {0.3f, 0.7f, 0.f};
  EXPECT_LT(dist(color_mix_n(c, w2, 3), color_mix(c[0], c[1], 0.3f, 0.7f)), 1e-5f);
  const float w3[3] = {1.f, 2.f, 3.f};
  const Vec3 m = color_mix_n(c, w3, 3);
  const float target = (pigment_brightness(c[0]) + 2 * pigment_brightness(c[1]) + 3 * pigment_brightness(c[2])) / 6.f;
  EXPECT_NEAR(pigment_brightness(m), target, 1e-4f);
}

TEST(Ryb, InverseRoundTripsInsideTheGamut) {
  float worst = 0.f, worst_rgb = 0.f;
  for (float r = 0.05f; r < 1.f; r += 0.1f)
    for (float y = 0.05f; y < 1.f; y += 0.1f)
      for (float b = 0.05f; b < 1.f; b += 0.1f) {
        const Vec3 c(r, y, b);
        const Vec3 back = rgb_to_ryb(ryb_to_rgb(c));
        worst = std::max(worst, dist(back, c));
        worst_rgb = std::max(worst_rgb, dist(ryb_to_rgb(back), ryb_to_rgb(c)));
      }
  EXPECT_LT(worst_rgb, 1e-4f);
  EXPECT_LT(worst, 2e-3f);
}

}  // namespace wb::test
