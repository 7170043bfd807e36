// Thin films are paint (docs/RENDERING.md "Films"): paint too thin to reach the surface
// threshold lies at the height of the paint in its column, opaque as that paint is, and meets
// the threshold surface of thick paint without a seam. Golden images of films of 0.1, 0.3,
// 0.6 and 2 cells and of a thick ridge; regenerate with
// `WB_UPDATE_GOLDEN=1 wetbrush_tests --gtest_filter='FilmTest.Golden*'`.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <optional>

#include "backend_fixture.h"
#include "core/color/ryb.h"
#include "core/render/raycast_kernels.h"
#include "core/render/renderer.h"
#include "core/render/test_volumes.h"
#include "golden.h"

namespace wb::test {

namespace {
constexpr int kN = 64;               // canvas side, cells
constexpr int kLo = 12, kHi = 52;    // a film covers [kLo, kHi)^2
constexpr int kIn0 = 20, kIn1 = 44;  // its interior: beyond the reach of normals and AO from the edges
const Vec3 kPigment(0.9f, 0.3f, 0.05f);  // an orange red, far from the primed canvas

Vec3 px(const Image& img, int x, int y) {
  const uint8_t* p = img.at(x, y);
  return Vec3(p[0] / 255.f, p[1] / 255.f, p[2] / 255.f);
}
Vec3 rgb_at(const FloatImage& f, int x, int y) { return Vec3(f.at(x, y, 0), f.at(x, y, 1), f.at(x, y, 2)); }
/// Share of the way from `ground` to `paint` that colour `c` lies (projected onto that line).
float coverage(Vec3 c, Vec3 ground, Vec3 paint) {
  const Vec3 d = paint - ground;
  return dot(c - ground, d) / dot(d, d);
}
float maxdiff(Vec3 a, Vec3 b) { return std::max({std::fabs(a.x - b.x), std::fabs(a.y - b.y), std::fabs(a.z - b.z)}); }

/// A layer of paint `t` cells thick lying on the canvas, as the grid holds one: full cells up to
/// floor(t), the rest in the cell above (density = the filled fraction of the cell).
PaintCell layer(float t, int z, Vec3 ryb, float oil) {
  PaintCell c;
  c.density = std::clamp(t - float(z), 0.f, 1.f);
  c.pigment_r = ryb.x;
  c.pigment_y = ryb.y;
  c.pigment_b = ryb.z;
  c.oil = oil;
  return c;
}
}  // namespace

class FilmTest : public BackendTest {
 protected:
  /// A uniform film `t` cells thick over [kLo, kHi)^2 of a 64^2 canvas.
  TileStore film(float t, float oil = 0.1f) {
    TileStore c(device_, CanvasDims{kN, kN, 16});
    fill_volume(c, kLo, kLo, kHi, kHi, [=](int, int, int z) { return layer(t, z, kPigment, oil); });
    return c;
  }
  /// A ridge along y: a half cylinder of radius 6 cells on the canvas (thick paint).
  TileStore ridge() {
    TileStore c(device_, CanvasDims{kN, kN, 16});
    fill_volume(c, 0, 8, kN, 56, [](int x, int, int z) {
      PaintCell p = layer(0.f, 0, Vec3(0.15f, 0.15f, 0.7f), 0.1f);
      p.density = sdf_density(6.f - std::hypot(x + 0.5f - 32.f, z + 0.5f));
      return p;
    });
    return c;
  }
  /// Lit colour of paint of RGB `rgb` facing straight up, without AO and highlight.
  static Vec3 lit_up(const RenderParams& P, Vec3 rgb) {
    return rgb * (P.ambient + P.diffuse * normalize(P.light_dir).z);
  }
};

TEST_F(FilmTest, HeightExportIsTheFilmThickness) {
  Renderer r(device_);
  for (float t : {0.1f, 0.3f, 0.45f, 0.6f, 2.f}) {
    TileStore c = film(t);
    const FloatImage h = r.render_height_map(c);
    const FloatImage n = r.render_normal_map(c);
    // Below the threshold the film surface is the column's paint exactly; above it the
    // threshold surface of a partly filled top cell lies within 0.09 cells of the layer's top.
    const float tol = t < r.params().threshold ? 1e-3f : 0.1f;
    float lo = 1e9f, hi = -1e9f;
    for (int y = kIn0; y < kIn1; ++y)
      for (int x = kIn0; x < kIn1; ++x) {
        lo = std::min(lo, h.at(x, y));
        hi = std::max(hi, h.at(x, y));
        ASSERT_NEAR(h.at(x, y), t, tol) << "film " << t << " at " << x << "," << y;
        ASSERT_GT(n.at(x, y, 2), 0.9999f) << "a uniform film faces up";
      }
    std::printf("film %.2f cells: exported height %.4f .. %.4f\n", t, lo, hi);
    for (int y = 0; y < kN; ++y)
      for (int x = 0; x < kN; ++x)
        if (x < kLo - 2 || y < kLo - 2 || x >= kHi + 2 || y >= kHi + 2) ASSERT_EQ(h.at(x, y), 0.f) << "bare canvas";
  }
}

TEST_F(FilmTest, HeightExportOfPaintSpreadThinOverSeveralCells) {
  // The same paint volume spread evenly over 1 to 4 cells of the column (density t / n each, no
  // cell at the threshold): the exported height is the paint volume t, however it is spread.
  Renderer r(device_);
  for (float t : {0.1f, 0.3f, 0.45f})
    for (int n : {1, 2, 3, 4}) {
      TileStore c(device_, CanvasDims{kN, kN, 16});
      fill_volume(c, kLo, kLo, kHi, kHi, [=](int, int, int z) {
        PaintCell p = layer(float(n), z, kPigment, 0.1f);
        p.density *= t / float(n);
        return p;
      });
      const FloatImage h = r.render_height_map(c);
      float worst = 0.f;
      for (int y = kIn0; y < kIn1; ++y)
        for (int x = kIn0; x < kIn1; ++x) worst = std::max(worst, std::fabs(h.at(x, y) - t));
      std::printf("paint %.2f cells spread over %d cells: largest |height - %.2f| %.5f\n", t, n, t, worst);
      EXPECT_LT(worst, 1e-3f) << "paint " << t << " over " << n << " cells";
    }
}

TEST_F(FilmTest, CanvasCoveredIncreasinglyWithThickness) {
  // Uniform films of 0.1, 0.3, 0.6 and 2 cells: how far the rendered colour has gone from the
  // lit primed canvas to the lit paint, in the shaded image (no AO or highlight, 8-bit) and in
  // the float albedo. Beer-Lambert with the default hiding thickness 0.2 cells predicts
  // 0.859, 0.997, 1.000, 1.000.
  Renderer r(device_);
  r.params().ao_rays = 0;
  r.params().specular = 0.f;
  const RenderParams& P = r.params();
  const Vec3 paint = ryb_to_rgb(kPigment);
  const Vec3 lit_paint = lit_up(P, paint), lit_canvas = lit_up(P, P.paper_rgb);
  float prev_shaded = -1.f, prev_albedo = -1.f;
  for (float t : {0.1f, 0.3f, 0.6f, 2.f}) {
    TileStore c = film(t);
    const Image img = r.render(c, Camera::top(c.dims()));
    const FloatImage a = r.render_albedo(c);
    float shaded = 0.f, albedo = 0.f;
    for (int y = kIn0; y < kIn1; ++y)
      for (int x = kIn0; x < kIn1; ++x) {
        shaded += coverage(px(img, x, y), lit_canvas, lit_paint);
        albedo += coverage(rgb_at(a, x, y), P.paper_rgb, paint);
      }
    shaded /= float((kIn1 - kIn0) * (kIn1 - kIn0));
    albedo /= float((kIn1 - kIn0) * (kIn1 - kIn0));
    const float expect = 1.f - std::pow(50.f, -t / P.film_hiding);
    std::printf("film %.1f cells: canvas covered %.4f (shaded), %.4f (albedo), Beer-Lambert %.4f\n", t, shaded,
                albedo, expect);
    EXPECT_NEAR(albedo, expect, 0.01f) << "film " << t;
    EXPECT_NEAR(shaded, expect, 0.02f) << "film " << t;
    EXPECT_GE(albedo, prev_albedo) << "film " << t << " covers less than a thinner one";
    EXPECT_GE(shaded, prev_shaded - 1.f / 255.f) << "film " << t << " covers less than a thinner one";
    if (t < 0.2f) {
      EXPECT_LT(shaded, 0.92f) << "a 0.1-cell film lets the canvas show through";
      EXPECT_GT(shaded, 0.80f) << "a 0.1-cell film is mostly paint";
    }
    if (t >= 2.f) {
      EXPECT_GT(shaded, 0.995f) << "2 cells of paint hide the canvas";
      EXPECT_LT(maxdiff(px(img, kN / 2, kN / 2), lit_paint), 2.f / 255.f) << "2 cells are the paint's colour";
    }
    prev_shaded = shaded;
    prev_albedo = albedo;
  }
}

TEST_F(FilmTest, FilmsAreOpaquePaintNotATint) {
  Renderer r(device_);
  r.params().ao_rays = 0;
  r.params().specular = 0.f;
  const RenderParams& P = r.params();
  const Vec3 paint = ryb_to_rgb(kPigment);
  const Vec3 lit_paint = lit_up(P, paint), lit_canvas = lit_up(P, P.paper_rgb);
  for (float t : {0.1f, 0.3f, 0.6f, 2.f}) {
    TileStore c = film(t);
    const Image img = r.render(c, Camera::top(c.dims()));
    const Vec3 got = px(img, kN / 2, kN / 2);
    std::printf("film %.1f: pixel (%.3f %.3f %.3f), lit paint (%.3f %.3f %.3f), lit canvas (%.3f %.3f %.3f)\n", t,
                got.x, got.y, got.z, lit_paint.x, lit_paint.y, lit_paint.z, lit_canvas.x, lit_canvas.y, lit_canvas.z);
    EXPECT_GT(maxdiff(got, lit_canvas), 0.3f) << "film " << t << " is not the canvas";
    if (t >= 0.3f) {
      for (int y = kIn0; y < kIn1; ++y)
        for (int x = kIn0; x < kIn1; ++x)
          ASSERT_LT(maxdiff(px(img, x, y), lit_paint), 3.f / 255.f) << "film " << t << " at " << x << "," << y;
    } else {
      EXPECT_LT(maxdiff(got, lit_paint), maxdiff(got, lit_canvas)) << "film " << t << " is mostly paint";
    }
  }
}

TEST_F(FilmTest, ThinnestFilmsLetTheGroundThroughByBeerLambert) {
  // Ground seen through a film t thick: 2 % of it at the hiding thickness, 50^(-t / hiding).
  Renderer r(device_);
  const RenderParams& P = r.params();
  const Vec3 paint = ryb_to_rgb(kPigment);
  for (float t : {0.01f, 0.05f, 0.1f, 0.3f}) {
    TileStore c = film(t);
    const FloatImage a = r.render_albedo(c);
    const float cover = 1.f - std::pow(50.f, -t / P.film_hiding);
    const Vec3 expect = P.paper_rgb + (paint - P.paper_rgb) * cover;
    const Vec3 got = rgb_at(a, kN / 2, kN / 2);
    std::printf("film %.2f cells (%.3f mm): cover %.3f, albedo (%.3f %.3f %.3f)\n", t, t * 0.2f, cover, got.x, got.y,
                got.z);
    EXPECT_LT(maxdiff(got, expect), 0.01f) << "film " << t;
  }
  // Oily paint is transparent whatever its thickness: the ground shows through a 0.3-cell glaze.
  TileStore oily = film(0.3f, 1.f);
  const Vec3 glaze = rgb_at(r.render_albedo(oily), kN / 2, kN / 2);
  EXPECT_GT(glaze.y, paint.y + 0.1f) << "the light ground lightens an oily film";
}

TEST_F(FilmTest, ThicknessRampRisesWithoutASeam) {
  // Paint rising linearly along x over 120 columns, in two ways: a layer 0 to 3 cells thick
  // (0.025 cell more per column), and paint spread evenly over two cells, density 0 to 1 (0.0167
  // cell of paint more per column; its threshold surface appears at once 1.5 cells up). The film
  // below the threshold and the threshold surface above must meet without a jump in height.
  constexpr int kX0 = 4, kCols = 120;
  auto frac = [](int x) { return (float(x - kX0) + 0.5f) / float(kCols); };
  auto layered = [&](int x) { return 3.f * frac(x); };
  TileStore c(device_, CanvasDims{128, 64, 16});
  fill_volume(c, kX0, 4, kX0 + kCols, 60, [&](int x, int y, int z) {
    if (y < 32) return layer(layered(x), z, kPigment, 0.1f);
    PaintCell p = layer(2.f, z, kPigment, 0.1f);
    p.density *= frac(x);
    return p;
  });
  Renderer r(device_);
  const FloatImage h = r.render_height_map(c);
  const Image img = r.render(c, Camera::top(c.dims()));
  struct Ramp {
    int y;
    float paint_step;  // paint added per column, cells
    std::function<float(int)> paint;
  };
  for (const Ramp& ramp : {Ramp{16, 3.f / kCols, layered}, Ramp{48, 2.f / kCols, [&](int x) { return 2.f * frac(x); }}}) {
    const int y = ramp.y;
    float worst_jump = 0.f, worst_colour = 0.f;
    for (int x = kX0; x + 1 < kX0 + kCols; ++x) {
      const float step = h.at(x + 1, y) - h.at(x, y);
      worst_jump = std::max(worst_jump, step);
      ASSERT_GE(step, -1e-4f) << "height falls at column " << x << " (paint " << ramp.paint(x) << ")";
      ASSERT_LE(step, 4.f * ramp.paint_step) << "seam at column " << x << " (paint " << ramp.paint(x) << ")";
      // Where the paint is opaque its shading changes as gently as its slope does.
      if (ramp.paint(x) >= 0.3f && x + 1 < kX0 + kCols - 6) {
        const float dc = maxdiff(px(img, x + 1, y), px(img, x, y));
        worst_colour = std::max(worst_colour, dc);
        ASSERT_LE(dc, 4.f / 255.f) << "shading seam at column " << x << " (paint " << ramp.paint(x) << ")";
      }
    }
    std::printf("ramp of row %d: largest height step %.4f (paint step %.4f), largest colour step %.1f/255\n", y,
                worst_jump, ramp.paint_step, worst_colour * 255.f);
  }
  // The layer stands at its thickness, within the threshold surface's 0.09 cell above a cell.
  float worst_err = 0.f;
  for (int x = kX0; x < kX0 + kCols; ++x) {
    worst_err = std::max(worst_err, std::fabs(h.at(x, 16) - layered(x)));
    ASSERT_NEAR(h.at(x, 16), layered(x), 0.1f) << "column " << x;
  }
  std::printf("layer ramp: largest |height - thickness| %.4f\n", worst_err);
}

TEST_F(FilmTest, RampFromATenthToTwoCellsHasNoStepAtTheThreshold) {
  // A layer rising linearly from 0.1 to 2 cells over 120 columns (0.0158 cell per column); it
  // crosses the threshold 0.5 between columns 28 and 29. Height and colour rise monotonically and change no
  // more at the crossing than elsewhere.
  constexpr int kX0 = 4, kCols = 120;
  auto thick = [](int x) { return 0.1f + 1.9f * (float(x - kX0) + 0.5f) / float(kCols); };
  TileStore c(device_, CanvasDims{128, 32, 16});
  fill_volume(c, kX0, 4, kX0 + kCols, 28, [&](int x, int, int z) { return layer(thick(x), z, kPigment, 0.1f); });
  Renderer r(device_);
  const FloatImage h = r.render_height_map(c);
  const FloatImage a = r.render_albedo(c);
  const Image img = r.render(c, Camera::top(c.dims()));
  const RenderParams& P = r.params();
  const Vec3 paint = ryb_to_rgb(kPigment);
  const int y = 16;
  const float nominal = 1.9f / kCols;
  int cross = -1;
  float worst = 0.f, at_cross = 0.f, worst_err = 0.f, worst_colour = 0.f, colour_at_cross = 0.f;
  // Skip the ramp's two ends (its edges to the bare canvas).
  for (int x = kX0 + 2; x + 1 < kX0 + kCols - 2; ++x) {
    const float step = h.at(x + 1, y) - h.at(x, y);
    const bool crossing = thick(x) < P.threshold && thick(x + 1) >= P.threshold;
    if (crossing) cross = x;
    worst = std::max(worst, step);
    worst_err = std::max(worst_err, std::fabs(h.at(x, y) - thick(x)));
    ASSERT_GE(step, -1e-4f) << "height falls at column " << x << " (thickness " << thick(x) << ")";
    ASSERT_LE(step, 2.5f * nominal) << "height steps at column " << x << " (thickness " << thick(x) << ")";
    ASSERT_NEAR(h.at(x, y), thick(x), 0.1f) << "column " << x;
    // The albedo covers the canvas more and more, then stays the paint's.
    const float ca = coverage(rgb_at(a, x, y), P.paper_rgb, paint), cb = coverage(rgb_at(a, x + 1, y), P.paper_rgb, paint);
    ASSERT_GE(cb, ca - 1e-4f) << "coverage falls at column " << x;
    const float dc = maxdiff(px(img, x + 1, y), px(img, x, y));
    worst_colour = std::max(worst_colour, dc);
    ASSERT_LE(dc, 4.f / 255.f) << "colour steps at column " << x << " (thickness " << thick(x) << ")";
    if (std::abs(x - cross) <= 1 && cross >= 0) {
      at_cross = std::max(at_cross, step);
      colour_at_cross = std::max(colour_at_cross, dc);
    }
  }
  ASSERT_GE(cross, 0);
  std::printf("ramp 0.1 to 2 cells: threshold crossed at column %d; height step there %.4f, largest %.4f "
              "(thickness step %.4f); largest |height - thickness| %.4f; colour step there %.1f/255, largest "
              "%.1f/255\n",
              cross, at_cross, worst, nominal, worst_err, colour_at_cross * 255.f, worst_colour * 255.f);
  EXPECT_LE(at_cross, 1.5f * nominal) << "no step where the film meets the threshold surface";
  EXPECT_LE(colour_at_cross, 1.f / 255.f) << "no change of colour where the film meets the threshold surface";
}

TEST_F(FilmTest, ThickRidgeKeepsItsThresholdSurface) {
  TileStore c = ridge();
  Renderer r(device_);
  const FloatImage h = r.render_height_map(c);
  for (int y = 16; y < 48; ++y)
    for (int x = 27; x <= 36; ++x) {
      const float dx = x + 0.5f - 32.f;
      ASSERT_NEAR(h.at(x, y), std::sqrt(36.f - dx * dx), 0.1f) << x << "," << y;
    }
}

TEST_F(FilmTest, CoatOnDriedPaintShowsItsColourAndThicknessWetOrDried) {
  // A dried blue layer 2 cells thick; over its middle a coat of the film test's red, 0.1, 0.2 or
  // 0.4 cells of paint in the cell above (as the grid holds paint laid on dried paint), wet, half
  // dry or dried. The coat is what the top view shows there, and the surface rises by its paint;
  // the dried layer beside it keeps its own surface and colour.
  const Vec3 blue(0.1f, 0.15f, 0.85f);
  Renderer r(device_);
  for (float coat_dryness : {0.f, 0.5f, 1.f})
    for (float coat : {0.1f, 0.2f, 0.4f}) {
      TileStore c(device_, CanvasDims{kN, kN, 16});
      fill_volume(c, kLo, kLo, kHi, kHi, [&](int x, int y, int z) {
        PaintCell p = layer(2.f, z, blue, 0.1f);
        p.dryness = p.density > 0.f ? 1.f : 0.f;
        if (z == 2 && x >= kIn0 && x < kIn1 && y >= kIn0 && y < kIn1) {
          p = layer(2.f + coat, z, kPigment, 0.1f);
          p.dryness = coat_dryness;
        }
        return p;
      });
      const FloatImage h = r.render_height_map(c);
      const FloatImage a = r.render_albedo(c);
      const Vec3 red = ryb_to_rgb(kPigment), dried = ryb_to_rgb(blue);
      const int m = (kIn0 + kIn1) / 2, o = (kLo + kIn0) / 2;
      std::printf(
          "coat %.1f, dryness %.1f: height %.3f (dried beside it %.3f); albedo %.2f %.2f %.2f (its paint %.2f %.2f "
          "%.2f)\n",
          coat, coat_dryness, h.at(m, m), h.at(o, o), a.at(m, m, 0), a.at(m, m, 1), a.at(m, m, 2), red.x, red.y, red.z);
      EXPECT_NEAR(h.at(m, m), 2.f + coat, 0.05f) << "the coat stands on the dried paint";
      EXPECT_NEAR(h.at(o, o), 2.f, 0.05f) << "the dried paint beside it keeps its surface";
      // The coat hides the dried paint as a film of its thickness hides the canvas.
      const Vec3 seen = lerp(dried, red, film_cover(r.params(), coat));
      EXPECT_LT(maxdiff(rgb_at(a, m, m), seen), 0.03f) << "the top view shows the coat over the dried paint";
      EXPECT_GT(coverage(rgb_at(a, m, m), dried, red), 0.8f)
          << "a coat a tenth of a cell thick already hides most of it";
      EXPECT_LT(maxdiff(rgb_at(a, o, o), dried), 0.03f) << "and the dried paint's beside it";
    }
}

TEST_F(FilmTest, IncrementalCacheMatchesFullRenderOverFilms) {
  // Films of 0 to 0.8 cells over the canvas; a window step repaints a region with a thicker one.
  TileStore c(device_, CanvasDims{256, 256, 8});
  fill_volume(c, 0, 0, 256, 256, [](int x, int y, int z) {
    return layer(0.4f + 0.4f * std::sin(x / 11.f) * std::cos(y / 7.f), z, kPigment, 0.1f);
  });
  Renderer r(device_);
  CanvasImageCache cache(r, Camera::top(c.dims()), 32);
  cache.update(c);
  PaintWindow w(device_, Int3{64, 64, 8});
  w.set_origin({100, 90, 0});
  c.gather(w);
  auto f = w.to_host();
  for (int64_t i = 0; i < w.cell_count(); ++i) f[0][size_t(i)] *= 0.5f;  // half the paint
  w.from_host(f);
  c.scatter(w);
  cache.mark_window_dirty(w);
  const Image& inc = cache.update(c);
  EXPECT_LT(cache.last_rendered_tiles(), 64);
  const Image full = r.render(c, Camera::top(c.dims()));
  for (int y = 0; y < 256; ++y)
    for (int x = 0; x < 256; ++x)
      ASSERT_EQ(std::memcmp(inc.at(x, y), full.at(x, y), 4), 0) << "incremental differs from full at " << x << "," << y;
}

TEST_F(FilmTest, PaintTooLittleToSeeIsNotSeen) {
  // Paint of subnormal density (below 1.2e-38 of a cell: the traces a flux or a return leaves) in
  // columns with one pigment channel at 0, beside a thin film and on bare canvas: a mean weighted
  // by so little paint taken as a product with its reciprocal (which overflows) gave 0 x inf = NaN,
  // black specks on a raking-light view of press-and-drag, and an infinite oil that sent the
  // pigment's gather below the surface down an endless ray (this canvas's render had not ended
  // after 13 minutes). Every output is finite, and on bare canvas the traces render as the canvas
  // without them.
  const Vec3 red(0.9f, 0.15f, 0.f);
  TileStore bare(device_, CanvasDims{kN, kN, 16});
  fill_volume(bare, kLo, kLo, kHi, kHi, [=](int x, int, int z) { return layer(x < 32 ? 0.3f : 0.f, z, red, 0.3f); });
  TileStore traces(device_, CanvasDims{kN, kN, 16});
  fill_volume(traces, kLo, kLo, kHi, kHi, [=](int x, int y, int z) {
    PaintCell p = layer(x < 32 ? 0.3f : 0.f, z, red, 0.3f);
    // Every fourth column right of the film holds a trace, from 1e-45 (the least subnormal) up.
    if (x >= 32 && (x + y) % 4 == 0 && z < 2) {
      p = layer(1.f, 0, red, 0.3f);
      p.density = (y % 3 == 0 ? 1e-45f : (y % 3 == 1 ? 1e-40f : 3e-39f)) * float(z + 1);
    }
    return p;
  });
  Renderer r(device_);
  r.params().light_dir = Vec3(-1.f, 0.2f, 0.2f);
  const FloatImage a = r.render_albedo(traces), n = r.render_normal_map(traces), h = r.render_height_map(traces);
  for (int y = 0; y < kN; ++y)
    for (int x = 0; x < kN; ++x)
      for (int k = 0; k < 3; ++k) {
        ASSERT_TRUE(std::isfinite(a.at(x, y, k))) << "albedo at " << x << "," << y;
        ASSERT_TRUE(std::isfinite(n.at(x, y, k))) << "normal at " << x << "," << y;
      }
  for (int y = 0; y < kN; ++y)
    for (int x = 0; x < kN; ++x) ASSERT_TRUE(std::isfinite(h.at(x, y))) << "height at " << x << "," << y;
  for (int y = kLo; y < kHi; y += 3)
    for (int x = 32; x < kHi; ++x) {
      const std::optional<Vec3> p = r.pigment_at(traces, x, y);
      if (p) ASSERT_TRUE(std::isfinite(p->x) && std::isfinite(p->y) && std::isfinite(p->z)) << x << "," << y;
    }
  for (float zoom : {1.f, 4.f}) {
    const Image with = r.render(traces, Camera::top_region(0, 0, kN, kN, zoom));
    const Image without = r.render(bare, Camera::top_region(0, 0, kN, kN, zoom));
    int worst = 0;
    // Away from the film's edge (a trace beside it takes the edge's slope, as any paint there does).
    for (int y = 0; y < with.height; ++y)
      for (int x = int(34 * zoom); x < with.width; ++x)
        for (int k = 0; k < 3; ++k) worst = std::max(worst, std::abs(int(with.at(x, y)[k]) - int(without.at(x, y)[k])));
    std::printf("zoom %.0f: the largest difference the traces make, %d of 255\n", zoom, worst);
    EXPECT_LE(worst, 2) << "zoom " << zoom;
  }
}

TEST_F(FilmTest, GoldenFilms) {
  Renderer r(device_);
  for (float t : {0.1f, 0.3f, 0.6f, 2.f}) {
    TileStore c = film(t);
    char name[64];
    std::snprintf(name, sizeof name, "film_%.1f_top_ao64", t);
    r.params() = RenderParams{};
    expect_golden(r.render(c, Camera::top_region(0, 0, kN, kN, 2.f)), name);
    // Raking light from the left, seen from 30 degrees: the film's relief and its edges.
    std::snprintf(name, sizeof name, "film_%.1f_oblique30_raking", t);
    r.params().light_dir = Vec3(-1.f, -0.2f, 0.25f);
    expect_golden(r.render(c, Camera::oblique(c.dims(), 30.f, 2.f, 6.f)), name);
  }
  if (updating_golden()) GTEST_SKIP() << "golden images written";
}

TEST_F(FilmTest, GoldenThickRidge) {
  TileStore c = ridge();
  Renderer r(device_);
  expect_golden(r.render(c, Camera::top_region(0, 0, kN, kN, 2.f)), "ridge6_top_ao64");
  r.params().light_dir = Vec3(-1.f, -0.2f, 0.25f);
  expect_golden(r.render(c, Camera::oblique(c.dims(), 30.f, 2.f, 10.f)), "ridge6_oblique30_raking");
  if (updating_golden()) GTEST_SKIP() << "golden images written";
}

}  // namespace wb::test
