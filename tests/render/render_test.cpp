// The renderer (paper §6): flat layers, analytic normals and heights, AO in creases, oil
// transparency, cameras, particles drawn as a surface, incremental re-rendering, and the
// same image on every backend.
#include <cmath>
#include <cstdlib>
#include <cstring>

#include "backend_fixture.h"
#include "core/color/ryb.h"
#include "core/io/png.h"
#include "core/render/renderer.h"
#include "core/render/test_volumes.h"
#include "golden.h"

namespace wb::test {

namespace {
Vec3 px(const Image& img, int x, int y) {
  const uint8_t* p = img.at(x, y);
  return Vec3(p[0] / 255.f, p[1] / 255.f, p[2] / 255.f);
}
float maxdiff(Vec3 a, Vec3 b) { return std::max({std::fabs(a.x - b.x), std::fabs(a.y - b.y), std::fabs(a.z - b.z)}); }
}  // namespace

class RenderTest : public BackendTest {
 protected:
  TileStore volume(const std::string& name) {
    TileStore c(device_, test_volume_dims(name));
    make_test_volume(c, name);
    return c;
  }
};

TEST_F(RenderTest, FlatLayerRendersUniformColour) {
  TileStore c = volume("flat");  // 4-cell layer over [16, 80)^2
  Renderer r(device_);
  const Image img = r.render(c, Camera::top(c.dims()));
  ASSERT_EQ(img.width, 96);
  ASSERT_EQ(img.height, 96);
  // Away from the layer's edges (AO reach + normal stencil), every pixel is the same colour.
  const Vec3 ref = px(img, 48, 48);
  for (int y = 26; y < 70; ++y)
    for (int x = 26; x < 70; ++x) ASSERT_LT(maxdiff(px(img, x, y), ref), 1.5f / 255.f) << x << "," << y;
  // ... and it is the paint's colour, lit: not the canvas.
  EXPECT_GT(ref.x, ref.y + 0.2f);
  EXPECT_GT(maxdiff(ref, px(img, 4, 4)), 0.2f);
  // A zoomed view of the same area is just as uniform.
  const Image z = r.render(c, Camera::top_region(30, 30, 36, 36, 3.f));
  ASSERT_EQ(z.width, 108);
  for (int y = 0; y < z.height; ++y)
    for (int x = 0; x < z.width; ++x) ASSERT_LT(maxdiff(px(z, x, y), ref), 1.5f / 255.f);
}

TEST_F(RenderTest, HemisphereNormalsMatchAnalytic) {
  TileStore c = volume("hemisphere");  // radius 24 about (48, 48, 0)
  Renderer r(device_);
  const FloatImage n = r.render_normal_map(c);
  const FloatImage h = r.render_height_map(c);
  double worst = 0.0;
  int checked = 0;
  for (int y = 0; y < 96; ++y)
    for (int x = 0; x < 96; ++x) {
      const float dx = x + 0.5f - 48.f, dy = y + 0.5f - 48.f;
      if (dx * dx + dy * dy > 0.8f * 0.8f * 24.f * 24.f) continue;
      const float hz = std::sqrt(24.f * 24.f - dx * dx - dy * dy);
      const Vec3 expect = normalize(Vec3(dx, dy, hz));
      const Vec3 got(n.at(x, y, 0), n.at(x, y, 1), n.at(x, y, 2));
      const double ang = std::acos(std::clamp(double(dot(expect, got)), -1.0, 1.0)) * 180.0 / M_PI;
      worst = std::max(worst, ang);
      ++checked;
      ASSERT_NEAR(h.at(x, y), hz, 0.1f) << x << "," << y;  // trilinear sampling of the SDF ramp
    }
  EXPECT_GT(checked, 1000);
  EXPECT_LT(worst, 3.0) << "largest normal error, degrees";
}

TEST_F(RenderTest, HeightMapOfFlatLayerIsExact) {
  TileStore c = volume("flat");
  Renderer r(device_);
  const FloatImage h = r.render_height_map(c);
  for (int y = 0; y < 96; ++y)
    for (int x = 0; x < 96; ++x) {
      const bool in = x >= 16 && x < 80 && y >= 16 && y < 80;
      ASSERT_NEAR(h.at(x, y), in ? 4.f : 0.f, 1e-3f) << x << "," << y;
    }
}

TEST_F(RenderTest, AmbientOcclusionDarkensCreaseNotFlatTop) {
  TileStore c = volume("ridges");  // ridges along y at x = 40 and 56, crease at x = 48
  Renderer r(device_);
  r.params().diffuse = 0.f;
  r.params().specular = 0.f;
  r.params().ambient = 1.f;
  const Image with = r.render(c, Camera::top(c.dims()));
  r.params().ao_strength = 0.f;
  const Image without = r.render(c, Camera::top(c.dims()));
  auto ratio = [&](int x, int y) { return px(with, x, y).z / px(without, x, y).z; };
  EXPECT_LT(ratio(48, 48), 0.9f) << "crease";
  EXPECT_NEAR(ratio(85, 48), 1.f, 1.f / 255.f) << "flat base layer far from the ridges";
  EXPECT_NEAR(ratio(40, 48), 1.f, 0.02f) << "ridge top";
}

TEST_F(RenderTest, ThinOilyGlazeShowsWhatIsBelowThickOpaqueDoesNot) {
  TileStore c = volume("glaze");  // red below; left: 1-cell oily blue glaze; right: 4-cell opaque blue
  Renderer r(device_);
  const FloatImage a = r.render_albedo(c);
  const Vec3 blue = ryb_to_rgb(Vec3(0, 0, 1));
  const Vec3 thin(a.at(32, 32, 0), a.at(32, 32, 1), a.at(32, 32, 2));
  const Vec3 thick(a.at(96, 32, 0), a.at(96, 32, 1), a.at(96, 32, 2));
  EXPECT_LT(maxdiff(thick, blue), 0.01f) << "opaque glaze shows only itself";
  EXPECT_GT(thin.x, blue.x + 0.2f) << "red shows through the oily glaze";
  // Without oil the thin glaze is opaque too.
  r.params().penetration_per_oil = 0.f;
  const FloatImage o = r.render_albedo(c);
  EXPECT_LT(maxdiff(Vec3(o.at(32, 32, 0), o.at(32, 32, 1), o.at(32, 32, 2)), blue), 0.01f);
}

TEST_F(RenderTest, ObliqueViewShowsRelief) {
  TileStore c = volume("hemisphere");
  Renderer r(device_);
  const Camera cam = Camera::oblique(c.dims(), 35.f, 1.f, 30.f);
  const Image img = r.render(c, cam);
  float tx, ty, gx, gy;
  camera_project(cam, Vec3(48, 48, 23.5f), tx, ty);  // near the dome's top
  camera_project(cam, Vec3(48, 48, 0), gx, gy);
  EXPECT_LT(ty, gy - 10.f) << "the top projects well above its foot";
  const Vec3 top = px(img, int(tx), int(ty));
  // Yellow-green paint there (little blue), neither background nor the primed canvas.
  EXPECT_LT(top.z, 0.4f);
  EXPECT_GT(maxdiff(top, r.params().background_rgb), 0.3f);
  // Outside the canvas: background.
  const Vec3 corner = px(img, 0, 0);
  EXPECT_LT(maxdiff(corner, r.params().background_rgb), 2.f / 255.f);
}

TEST_F(RenderTest, ParticlesAreDrawnAsASurface) {
  TileStore c(device_, CanvasDims{64, 64, 16});
  PaintWindow w(device_, Int3{32, 32, 16});
  w.set_origin({16, 16, 0});
  // A ball of 200 particles of blue paint resting on the canvas around (32, 32, 2).
  std::vector<Vec3> x;
  std::vector<float> m, pr, py, pb, po;
  for (int k = 0; k < 200; ++k) {
    const float a = k * 2.39996f, rr = 4.f * std::sqrt((k + 0.5f) / 200.f);
    x.push_back(Vec3(32.f + rr * std::cos(a), 32.f + rr * std::sin(a), 1.5f + 0.5f * (k % 3)));
    m.push_back(0.4f);
    pr.push_back(0.f);
    py.push_back(0.f);
    pb.push_back(1.f);
    po.push_back(0.f);
  }
  DeviceBuffer<Vec3> dx(device_, x.size());
  dx.copy_from_host(x);
  DeviceBuffer<float> dm(device_, m.size()), dr(device_, m.size()), dy(device_, m.size()), db(device_, m.size()),
      doil(device_, m.size());
  dm.copy_from_host(m);
  dr.copy_from_host(pr);
  dy.copy_from_host(py);
  db.copy_from_host(pb);
  doil.copy_from_host(po);
  ParticleOverlay ov;
  ov.x = dx.data();
  ov.mass = dm.data();
  ov.r = dr.data();
  ov.y = dy.data();
  ov.b = db.data();
  ov.oil = doil.data();
  ov.n = int64_t(x.size());
  ov.radius = 1.5f;
  Renderer r(device_);
  const Image plain = r.render(c, Camera::top(c.dims()), &w);
  const Image with = r.render(c, Camera::top(c.dims()), &w, &ov);
  const Vec3 centre = px(with, 32, 32);
  EXPECT_GT(centre.z, centre.x + 0.15f) << "blue paint where the particles are";
  EXPECT_GT(maxdiff(centre, px(plain, 32, 32)), 0.2f);
  EXPECT_LT(maxdiff(px(with, 5, 5), px(plain, 5, 5)), 1.f / 255.f) << "nothing far away";
}

TEST_F(RenderTest, LiveWindowReplacesTiles) {
  TileStore c = volume("flat");
  Renderer r(device_);
  // The live window holds an empty region over the layer: the canvas must show there.
  PaintWindow w(device_, Int3{16, 16, 16});
  w.set_origin({40, 40, 0});
  const Image img = r.render(c, Camera::top(c.dims()), &w);
  const Image base = r.render(c, Camera::top(c.dims()));
  EXPECT_GT(maxdiff(px(img, 48, 48), px(base, 48, 48)), 0.2f);
  EXPECT_LT(maxdiff(px(img, 48, 48), px(base, 4, 4)), 0.12f) << "bare canvas in the emptied window";
}

TEST_F(RenderTest, IncrementalUpdateRendersOnlyChangedTilesAndMatchesFullRender) {
  TileStore c(device_, CanvasDims{512, 512, 16});
  fill_volume(c, 0, 0, 512, 512, [](int x, int y, int z) {
    PaintCell p;
    p.density = sdf_density(3.f + std::sin(x / 9.f) * std::cos(y / 7.f) - (z + 0.5f));
    p.pigment_r = 0.7f;
    p.pigment_b = 0.3f * (x % 64 < 32);
    return p;
  });
  Renderer r(device_);
  CanvasImageCache cache(r, Camera::top(c.dims()), 32);
  cache.update(c);
  EXPECT_EQ(cache.last_rendered_tiles(), 16 * 16);
  cache.update(c);
  EXPECT_EQ(cache.last_rendered_tiles(), 0) << "nothing changed, nothing rendered";
  // A simulation step: the window's paint changes and is scattered back.
  PaintWindow w(device_, Int3{128, 128, 16});
  w.set_origin({200, 160, 0});
  c.gather(w);
  auto f = w.to_host();
  for (int64_t i = 0; i < w.cell_count(); ++i)
    if (f[0][size_t(i)] > 0.f) f[1][size_t(i)] = 0.f, f[3][size_t(i)] = 1.f;  // repaint blue
  w.from_host(f);
  c.scatter(w);
  cache.mark_window_dirty(w);
  const Image& inc = cache.update(c);
  // 128 cells + the reach of normals and AO on each side: at most 6 x 6 tiles of 32, of 256.
  EXPECT_LE(cache.last_rendered_tiles(), 36);
  EXPECT_GE(cache.last_rendered_tiles(), 16);
  const Image full = r.render(c, Camera::top(c.dims()));
  for (int y = 0; y < 512; ++y)
    for (int x = 0; x < 512; ++x)
      ASSERT_EQ(std::memcmp(inc.at(x, y), full.at(x, y), 4), 0) << "incremental differs from full at " << x << "," << y;
}

TEST_F(RenderTest, SameImageOnCpuAndThisBackend) {
  if (device_.is_cpu()) GTEST_SKIP() << "run with WB_DEVICE=cuda to compare the CUDA backend with the CPU";
  for (const char* name : {"hemisphere", "glaze", "ridges"}) {
    TileStore g(device_, test_volume_dims(name)), h(Device(DeviceType::CPU), test_volume_dims(name));
    make_test_volume(g, name);
    make_test_volume(h, name);
    Renderer rg(device_), rh(Device(DeviceType::CPU));
    for (const Camera& cam : {Camera::top(g.dims()), Camera::oblique(g.dims(), 40.f)}) {
      const Image a = rg.render(g, cam), b = rh.render(h, cam);
      int off = 0;
      for (size_t i = 0; i < a.rgba.size(); ++i) off += std::abs(int(a.rgba[i]) - int(b.rgba[i])) > 2;
      EXPECT_LE(off, int(a.rgba.size() / 1000)) << name << ": more than 0.1% of samples differ by > 2/255";
    }
  }
}

TEST_F(RenderTest, RejectsBadParameters) {
  TileStore c(device_, CanvasDims{32, 32, 8});
  Renderer r(device_);
  r.params().step = 0.f;
  EXPECT_THROW(r.render(c, Camera::top(c.dims())), Error);
  r.params().step = 0.25f;
  Camera bad = Camera::top(c.dims());
  bad.zoom = -1.f;
  EXPECT_THROW(r.render(c, bad), Error);
}

// Golden image: the swatches volume seen from above, compared with a tolerance (golden.h).
// Regenerate with `WB_UPDATE_GOLDEN=1 wetbrush_tests --gtest_filter=RenderTest.GoldenSwatches*`.
TEST_F(RenderTest, GoldenSwatchesTopAo64) {
  TileStore c = volume("swatches");
  Renderer r(device_);
  expect_golden(r.render(c, Camera::top(c.dims())), "swatches_top_ao64");
  if (updating_golden()) GTEST_SKIP() << "golden image written";
}

}  // namespace wb::test
