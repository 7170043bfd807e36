// Relief exports (docs/FORMATS.md "Relief exports"): the decimated mesh stays within its error
// bound; `wetbrush export` writes an OpenEXR height equal to the 16-bit PNG's, a watertight STL
// whose volume is the paint's plus the base's, and a glTF that tinygltf loads back with the
// painting's extent in metres.
#include <gtest/gtest.h>

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <tiny_gltf.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
#include <string>

#include "core/io/png.h"
#include "run_cli.h"
#include "media/relief_export.h"

namespace wb::test {
namespace {

/// The CLI's output, its exit status in `code`.
std::string run_cli(const std::string& args, int* code) {
  const RunResult r = wb::test::run_cli(args);
  *code = r.exit_code;
  return r.output;
}

/// The largest |mesh - height| over every cell centre: each triangle (x, y in cells, heights
/// in any unit) interpolated at the centres it covers. Centres no triangle covers count as
/// infinite error.
double max_vertical_error(const std::vector<std::array<double, 3>>& tri_pts, const std::vector<double>& heights, int w,
                          int h) {
  std::vector<double> err(size_t(w) * h, INFINITY);
  for (size_t t = 0; t + 2 < tri_pts.size(); t += 3) {
    const auto &a = tri_pts[t], &b = tri_pts[t + 1], &c = tri_pts[t + 2];
    const double det = (b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]);
    if (std::fabs(det) < 1e-12) continue;
    const int x0 = std::max(0, int(std::floor(std::min({a[0], b[0], c[0]}) - 0.5)));
    const int x1 = std::min(w - 1, int(std::ceil(std::max({a[0], b[0], c[0]}) - 0.5)));
    const int y0 = std::max(0, int(std::floor(std::min({a[1], b[1], c[1]}) - 0.5)));
    const int y1 = std::min(h - 1, int(std::ceil(std::max({a[1], b[1], c[1]}) - 0.5)));
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) {
        const double px = x + 0.5, py = y + 0.5;
        const double l1 = ((px - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (py - a[1])) / det;
        const double l2 = ((b[0] - a[0]) * (py - a[1]) - (px - a[0]) * (b[1] - a[1])) / det;
        const double l0 = 1 - l1 - l2;
        if (l0 < -1e-6 || l1 < -1e-6 || l2 < -1e-6) continue;
        const double v = l0 * a[2] + l1 * b[2] + l2 * c[2];
        double& e = err[size_t(y) * w + x];
        const double d = std::fabs(v - heights[size_t(y) * w + x]);
        e = std::isinf(e) ? d : std::max(e, d);
      }
  }
  double worst = 0;
  for (double e : err) worst = std::max(worst, e);
  return worst;
}

/// A height map with flat ground, a dome, a tilted plane and a rough patch (cells).
FloatImage test_heights(int w, int h) {
  FloatImage img;
  img.width = w, img.height = h, img.channels = 1;
  img.data.assign(size_t(w) * h, 0.f);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      float v = 0.f;
      const double dx = x + 0.5 - 30, dy = y + 0.5 - 30, r2 = dx * dx + dy * dy;
      if (r2 < 400) v = float(std::sqrt(400 - r2));
      if (x >= 60 && y < 40) v = 0.1f * (x - 60) + 0.05f * y;                              // a plane
      if (x >= 60 && y >= 50) v = float(((x * 7919 + y * 104729) % 1000) / 1000.0 * 3);  // rough
      img.data[size_t(y) * w + x] = v;
    }
  return img;
}

}  // namespace

TEST(ReliefMeshTest, DecimationStaysWithinTheBoundWithoutCracks) {
  const FloatImage hm = test_heights(100, 75);  // not a power of two: the quadtree is clipped
  std::vector<double> heights(hm.data.begin(), hm.data.end());
  for (double bound : {0.0, 0.05, 0.5}) {
    const ReliefMesh m = decimate_height_map(hm, bound);
    std::vector<std::array<double, 3>> pts;
    for (uint32_t v : m.triangles) pts.push_back({m.x[v], m.y[v], m.h[v]});
    const double err = max_vertical_error(pts, heights, hm.width, hm.height);
    EXPECT_LE(err, bound + 1e-5) << "bound " << bound;
    EXPECT_LT(m.vertex_count(), size_t(m.grid_vertices)) << "bound " << bound;
    // The triangles tile the canvas exactly once: their areas add up to it (cracks or overlaps would not).
    double area = 0;
    for (size_t t = 0; t < m.triangles.size(); t += 3) {
      const uint32_t a = m.triangles[t], b = m.triangles[t + 1], c = m.triangles[t + 2];
      const double cross = (double(m.x[b]) - m.x[a]) * (double(m.y[c]) - m.y[a]) -
                           (double(m.y[b]) - m.y[a]) * (double(m.x[c]) - m.x[a]);
      EXPECT_LT(cross, 0) << "triangle " << t / 3 << " is not counter-clockwise from above";
      area += -0.5 * cross;
    }
    EXPECT_NEAR(area, 100.0 * 75.0, 1e-6);
    // Every edge inside has two triangles; the border's edges one.
    std::map<std::pair<uint32_t, uint32_t>, int> edges;
    for (size_t t = 0; t < m.triangles.size(); t += 3)
      for (int k = 0; k < 3; ++k) {
        const uint32_t a = m.triangles[t + k], b = m.triangles[t + (k + 1) % 3];
        ++edges[{std::min(a, b), std::max(a, b)}];
      }
    size_t border_edges = 0;
    for (const auto& [e, n] : edges) {
      EXPECT_LE(n, 2);
      border_edges += n == 1;
    }
    EXPECT_EQ(border_edges, m.border.size());
  }
  // Flat ground merges: the bare canvas is a handful of triangles.
  FloatImage flat = hm;
  std::fill(flat.data.begin(), flat.data.end(), 0.f);
  EXPECT_LT(decimate_height_map(flat, 0.0).vertex_count(), 200u);
}

TEST(ExportCli, ReliefsOfHemisphere) {
  const auto dir = std::filesystem::temp_directory_path() / ("wetbrush_relief_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string ora = (dir / "h.ora").string(), png = (dir / "h.png").string(), exr = (dir / "h.exr").string(),
                    stl = (dir / "h.stl").string(), glb = (dir / "h.glb").string();
  int code = -1;
  std::string out = run_cli("render --device cpu --test-volume hemisphere --ao-rays 0 --save " + ora, &code);
  ASSERT_EQ(code, 0) << out;
  const double base_mm = 1.5, error_mm = 0.02;
  out = run_cli("export --device cpu " + ora + " --height " + png + " --height-exr " + exr + " --stl " + stl +
                    " --gltf " + glb + " --base-mm 1.5 --error-mm 0.02",
                &code);
  ASSERT_EQ(code, 0) << out;
  std::printf("%s", out.c_str());

  // The EXR: millimetres, equal to the PNG's height within its quantisation.
  Imf::InputFile in(exr.c_str());
  const Imath::Box2i dw = in.header().dataWindow();
  const int w = dw.max.x - dw.min.x + 1, h = dw.max.y - dw.min.y + 1;
  ASSERT_EQ(w, 96);
  ASSERT_EQ(h, 96);
  ASSERT_NE(in.header().channels().findChannel("Y"), nullptr);
  EXPECT_EQ(in.header().channels().findChannel("Y")->type, Imf::FLOAT);
  std::vector<float> mm(size_t(w) * h);
  Imf::FrameBuffer fb;
  fb.insert("Y", Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(mm.data()), sizeof(float), sizeof(float) * w));
  in.setFrameBuffer(fb);
  in.readPixels(dw.min.y, dw.max.y);
  const PngPixels p = read_png(png);
  ASSERT_EQ(p.width, w);
  const double mm_per_unit = 32.0 / 65535.0 * kCellMm;  // the hemisphere's canvas is 32 cells deep
  double max_diff = 0, max_mm = 0, paint_mm3 = 0;
  for (size_t i = 0; i < mm.size(); ++i) {
    max_diff = std::max(max_diff, std::fabs(mm[i] - p.data16[i] * mm_per_unit));
    max_mm = std::max(max_mm, double(mm[i]));
    paint_mm3 += mm[i] * kCellMm * kCellMm;
  }
  std::printf("EXR against PNG: max difference %.3g mm (PNG step %.3g mm); top %.3f mm\n", max_diff, mm_per_unit, max_mm);
  EXPECT_LE(max_diff, 0.5 * mm_per_unit + 1e-6);
  EXPECT_NEAR(max_mm, 24 * kCellMm, 0.1);  // radius 24 cells

  // The STL: welded, every edge has two triangles that run it in opposite directions, and the
  // volume is the paint's plus the base's.
  const std::vector<uint8_t> s = read_file(stl);
  ASSERT_GE(s.size(), 84u);
  uint32_t n = 0;
  std::memcpy(&n, &s[80], 4);
  ASSERT_EQ(s.size(), 84 + 50 * size_t(n));
  std::map<std::array<float, 3>, uint32_t> weld;
  std::map<std::pair<uint32_t, uint32_t>, int> directed;
  double volume = 0;
  for (uint32_t t = 0; t < n; ++t) {
    std::array<std::array<float, 3>, 3> v;
    uint32_t id[3];
    for (int k = 0; k < 3; ++k) {
      std::memcpy(v[k].data(), &s[84 + 50 * size_t(t) + 12 + 12 * k], 12);
      id[k] = weld.emplace(v[k], uint32_t(weld.size())).first->second;
    }
    for (int k = 0; k < 3; ++k) ++directed[{id[k], id[(k + 1) % 3]}];
    const auto &a = v[0], &b = v[1], &c = v[2];
    volume += (double(a[0]) * (double(b[1]) * c[2] - double(b[2]) * c[1]) -
               double(a[1]) * (double(b[0]) * c[2] - double(b[2]) * c[0]) +
               double(a[2]) * (double(b[0]) * c[1] - double(b[1]) * c[0])) /
              6.0;
  }
  size_t bad_edges = 0;
  for (const auto& [e, count] : directed)
    if (count != 1 || directed.count({e.second, e.first}) != 1 || directed.at({e.second, e.first}) != 1) ++bad_edges;
  EXPECT_EQ(bad_edges, 0u) << "edges not shared by exactly two consistently oriented triangles";
  const double base_mm3 = base_mm * w * h * kCellMm * kCellMm;
  const double expect = paint_mm3 + base_mm3;
  std::printf("STL: %u triangles, %zu vertices; volume %.2f mm3, paint %.2f + base %.2f = %.2f mm3 (%.3f %%)\n", n,
              weld.size(), volume, paint_mm3, base_mm3, expect, 100.0 * (volume - expect) / expect);
  EXPECT_NEAR(volume, expect, 0.02 * expect);
  // The paint alone within 2 % too: the base does not hide an error in the relief.
  EXPECT_NEAR(volume - base_mm3, paint_mm3, 0.02 * paint_mm3);

  // The glTF: loads, fewer vertices than the grid, the extent in metres, within the bound.
  tinygltf::Model model;
  tinygltf::TinyGLTF loader;
  std::string err, warn;
  ASSERT_TRUE(loader.LoadBinaryFromFile(&model, &err, &warn, glb)) << err;
  ASSERT_EQ(model.meshes.size(), 1u);
  const tinygltf::Primitive& prim = model.meshes[0].primitives.at(0);
  auto data_of = [&](int accessor) {
    const tinygltf::Accessor& a = model.accessors.at(size_t(accessor));
    const tinygltf::BufferView& bv = model.bufferViews.at(size_t(a.bufferView));
    return model.buffers.at(size_t(bv.buffer)).data.data() + bv.byteOffset + a.byteOffset;
  };
  const tinygltf::Accessor& pa = model.accessors.at(size_t(prim.attributes.at("POSITION")));
  ASSERT_EQ(pa.componentType, TINYGLTF_COMPONENT_TYPE_FLOAT);
  const auto* pos = reinterpret_cast<const float*>(data_of(prim.attributes.at("POSITION")));
  EXPECT_EQ(prim.attributes.count("NORMAL"), 1u);
  EXPECT_EQ(prim.attributes.count("TEXCOORD_0"), 1u);
  const size_t grid = size_t(w + 2) * (h + 2);
  std::printf("glTF: %zu vertices (full grid %zu), %zu triangles\n", pa.count, grid,
              model.accessors.at(size_t(prim.indices)).count / 3);
  EXPECT_LT(pa.count, grid / 2);
  const double cell_m = kCellMm * 1e-3;
  double lo[3] = {1e9, 1e9, 1e9}, hi[3] = {-1e9, -1e9, -1e9};
  for (size_t v = 0; v < pa.count; ++v)
    for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], double(pos[v * 3 + k])), hi[k] = std::max(hi[k], double(pos[v * 3 + k]));
  EXPECT_NEAR(lo[0], 0.0, cell_m);
  EXPECT_NEAR(hi[0], w * cell_m, cell_m);
  EXPECT_NEAR(lo[2], 0.0, cell_m);
  EXPECT_NEAR(hi[2], h * cell_m, cell_m);
  EXPECT_NEAR(lo[1], 0.0, cell_m);
  EXPECT_NEAR(hi[1], max_mm * 1e-3, cell_m);
  const tinygltf::Accessor& ia = model.accessors.at(size_t(prim.indices));
  ASSERT_EQ(ia.componentType, TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT);
  const auto* idx = reinterpret_cast<const uint32_t*>(data_of(prim.indices));
  std::vector<std::array<double, 3>> pts;
  for (size_t i = 0; i < ia.count; ++i) {
    const float* q = pos + size_t(idx[i]) * 3;
    pts.push_back({q[0] / cell_m, q[2] / cell_m, q[1] * 1e3});  // cells, cells, mm
  }
  const double gltf_err = max_vertical_error(pts, std::vector<double>(mm.begin(), mm.end()), w, h);
  std::printf("glTF: max vertical error %.4f mm (bound %.3f mm)\n", gltf_err, error_mm);
  EXPECT_LE(gltf_err, error_mm + 1e-4);
  // The albedo texture: an embedded PNG of the canvas's size.
  ASSERT_EQ(model.images.size(), 1u);
  EXPECT_EQ(model.images[0].mimeType, "image/png");
  EXPECT_EQ(model.images[0].width, w);
  EXPECT_EQ(model.textures.size(), 1u);

  // An unwritable path is a message and a non-zero exit, and an export without a file says so.
  out = run_cli("export --device cpu " + ora + " --stl /nonexistent-dir/x.stl", &code);
  EXPECT_NE(code, 0);
  EXPECT_NE(out.find("/nonexistent-dir/x.stl"), std::string::npos) << out;
  out = run_cli("export --device cpu " + ora + " --gltf " + glb + " --error-mm -1", &code);
  EXPECT_NE(code, 0);
  EXPECT_NE(out.find("--error-mm"), std::string::npos) << out;
  std::filesystem::remove_all(dir);
}

}  // namespace wb::test
