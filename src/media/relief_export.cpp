#include "media/relief_export.h"

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfOutputFile.h>
#include <ImfStdIO.h>
#include <ImfStringAttribute.h>
#include <tiny_gltf.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <exception>
#include <sstream>

#include "core/exec/error.h"
#include "core/io/atomic_file.h"
#include "core/io/png.h"

namespace wb {
namespace {

/// The vertex grid over a height map of W x H cells: W + 2 columns, at x = 0, the W cell
/// centres and x = W (rows likewise), so the mesh reaches the canvas edges.
struct VertexGrid {
  const FloatImage& h;
  int nx, ny;
  explicit VertexGrid(const FloatImage& img) : h(img), nx(img.width + 2), ny(img.height + 2) {}
  double px(int i) const { return i == 0 ? 0.0 : (i == nx - 1 ? double(h.width) : i - 0.5); }
  double py(int j) const { return j == 0 ? 0.0 : (j == ny - 1 ? double(h.height) : j - 0.5); }
  float height(int i, int j) const {
    return h.at(std::clamp(i - 1, 0, h.width - 1), std::clamp(j - 1, 0, h.height - 1));
  }
};

/// Whether the heights of the closed rectangle [x0, x1] x [y0, y1] of the vertex grid lie
/// within err of each other, or within err/2 of their least-squares plane: either way any
/// triangulation of vertices from the square differs from every height in it by at most err.
bool is_flat(const VertexGrid& g, int x0, int y0, int x1, int y1, double err) {
  double lo = INFINITY, hi = -INFINITY;
  for (int j = y0; j <= y1; ++j)
    for (int i = x0; i <= x1; ++i) {
      const double v = g.height(i, j);
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
  if (hi - lo <= err) return true;
  // Plane h = a + b (x - cx) + c (y - cy), centred for a well-conditioned solve.
  const double cx = 0.5 * (g.px(x0) + g.px(x1)), cy = 0.5 * (g.py(y0) + g.py(y1));
  double n = 0, sx = 0, sy = 0, sxx = 0, sxy = 0, syy = 0, sh = 0, sxh = 0, syh = 0;
  for (int j = y0; j <= y1; ++j)
    for (int i = x0; i <= x1; ++i) {
      const double x = g.px(i) - cx, y = g.py(j) - cy, v = g.height(i, j);
      n += 1, sx += x, sy += y, sxx += x * x, sxy += x * y, syy += y * y;
      sh += v, sxh += x * v, syh += y * v;
    }
  // Cramer's rule on the 3x3 normal equations.
  const double m[3][3] = {{n, sx, sy}, {sx, sxx, sxy}, {sy, sxy, syy}};
  const double r[3] = {sh, sxh, syh};
  auto det3 = [](const double a[3][3]) {
    return a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
           a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
  };
  const double d = det3(m);
  if (std::fabs(d) < 1e-12) return false;
  double coef[3];
  for (int k = 0; k < 3; ++k) {
    double mk[3][3];
    std::memcpy(mk, m, sizeof m);
    for (int row = 0; row < 3; ++row) mk[row][k] = r[row];
    coef[k] = det3(mk) / d;
  }
  for (int j = y0; j <= y1; ++j)
    for (int i = x0; i <= x1; ++i) {
      const double plane = coef[0] + coef[1] * (g.px(i) - cx) + coef[2] * (g.py(j) - cy);
      if (std::fabs(g.height(i, j) - plane) > 0.5 * err) return false;
    }
  return true;
}

/// Float RGB in [0, 1] to 8-bit RGB.
std::vector<uint8_t> to_rgb8(const FloatImage& f) {
  std::vector<uint8_t> out(size_t(f.width) * f.height * 3);
  for (size_t i = 0; i < out.size(); ++i)
    out[i] = uint8_t(std::lround(std::clamp(f.data[i], 0.f, 1.f) * 255.f));
  return out;
}

void check_height_map(const FloatImage& h) {
  WB_REQUIRE(h.width > 0 && h.height > 0 && h.channels == 1 && h.data.size() == size_t(h.width) * h.height,
             "relief export: the height map is empty or not one channel");
}

}  // namespace

ReliefMesh decimate_height_map(const FloatImage& height_cells, double error_cells) {
  check_height_map(height_cells);
  WB_REQUIRE(std::isfinite(error_cells) && error_cells >= 0.0, "relief export: the error bound must be >= 0");
  const VertexGrid g(height_cells);
  const int nx = g.nx, ny = g.ny;
  int size = 1;
  while (size < std::max(nx - 1, ny - 1)) size *= 2;

  // Top-down quadtree over the vertex grid, its squares clipped to the grid (the far edges'
  // remainders are rectangles, down to one segment wide): a square or rectangle stays whole when
  // flat or a single cell; otherwise it splits.
  struct Node {
    int x0, y0, x1, y1, s;
  };
  std::vector<Node> leaves, stack{{0, 0, std::min(size, nx - 1), std::min(size, ny - 1), size}};
  while (!stack.empty()) {
    const Node n = stack.back();
    stack.pop_back();
    const int w = n.x1 - n.x0, h = n.y1 - n.y0;
    if ((w == 1 && h == 1) || is_flat(g, n.x0, n.y0, n.x1, n.y1, error_cells)) {
      leaves.push_back(n);
      continue;
    }
    const int half = n.s / 2;
    for (int c = 0; c < 4; ++c) {
      const int x0 = n.x0 + (c % 2) * half, y0 = n.y0 + (c / 2) * half;
      if (x0 >= nx - 1 || y0 >= ny - 1) continue;  // wholly outside the grid
      stack.push_back({x0, y0, std::min(x0 + half, nx - 1), std::min(y0 + half, ny - 1), half});
    }
  }

  // The grid vertices the mesh uses: every leaf's corners (and the centres added below).
  std::vector<uint8_t> active(size_t(nx) * ny, 0);
  for (const Node& n : leaves)
    for (int c = 0; c < 4; ++c) active[size_t(c / 2 ? n.y1 : n.y0) * nx + (c % 2 ? n.x1 : n.x0)] = 1;

  ReliefMesh mesh;
  mesh.grid_vertices = nx * ny;
  std::vector<int32_t> index(size_t(nx) * ny, -1);
  auto vertex = [&](int i, int j) -> uint32_t {
    int32_t& v = index[size_t(j) * nx + i];
    if (v < 0) {
      v = int32_t(mesh.x.size());
      mesh.x.push_back(float(g.px(i)));
      mesh.y.push_back(float(g.py(j)));
      mesh.h.push_back(g.height(i, j));
    }
    return uint32_t(v);
  };
  // Counter-clockwise seen from above: with y down the image, a negative cross product.
  auto triangle = [&](uint32_t a, uint32_t b, uint32_t c) {
    const double cross = (double(mesh.x[b]) - mesh.x[a]) * (double(mesh.y[c]) - mesh.y[a]) -
                         (double(mesh.y[b]) - mesh.y[a]) * (double(mesh.x[c]) - mesh.x[a]);
    if (cross > 0) std::swap(b, c);
    mesh.triangles.insert(mesh.triangles.end(), {a, b, c});
  };
  std::vector<uint32_t> ring;
  for (const Node& n : leaves) {
    // The leaf's border, once round, through every vertex a neighbour uses on it.
    ring.clear();
    for (int i = n.x0; i < n.x1; ++i)
      if (active[size_t(n.y0) * nx + i]) ring.push_back(vertex(i, n.y0));
    for (int j = n.y0; j < n.y1; ++j)
      if (active[size_t(j) * nx + n.x1]) ring.push_back(vertex(n.x1, j));
    for (int i = n.x1; i > n.x0; --i)
      if (active[size_t(n.y1) * nx + i]) ring.push_back(vertex(i, n.y1));
    for (int j = n.y1; j > n.y0; --j)
      if (active[size_t(j) * nx + n.x0]) ring.push_back(vertex(n.x0, j));
    if (ring.size() == 4) {
      triangle(ring[0], ring[1], ring[2]);
      triangle(ring[0], ring[2], ring[3]);
    } else if (n.x1 - n.x0 >= 2 && n.y1 - n.y0 >= 2) {
      // A fan from an inner grid vertex.
      const uint32_t c = vertex((n.x0 + n.x1) / 2, (n.y0 + n.y1) / 2);
      for (size_t k = 0; k < ring.size(); ++k) triangle(c, ring[k], ring[(k + 1) % ring.size()]);
    } else {
      // A strip one segment wide has no inner vertex: zip its two long sides together, always
      // stepping along the side whose next vertex comes first.
      const bool vertical = n.x1 - n.x0 == 1;
      const int len = vertical ? n.y1 - n.y0 : n.x1 - n.x0;
      auto side = [&](int k, int along) {  // grid vertex `along` of long side k (0 or 1)
        return vertical ? std::pair{k ? n.x1 : n.x0, n.y0 + along} : std::pair{n.x0 + along, k ? n.y1 : n.y0};
      };
      auto is_active = [&](std::pair<int, int> v) { return active[size_t(v.second) * nx + v.first] != 0; };
      std::vector<int> chain[2];
      for (int k = 0; k < 2; ++k)
        for (int t = 0; t <= len; ++t)
          if (is_active(side(k, t))) chain[k].push_back(t);
      size_t a = 0, b = 0;
      auto vtx = [&](int k, size_t i) {
        const auto [vi, vj] = side(k, chain[k][i]);
        return vertex(vi, vj);
      };
      while (a + 1 < chain[0].size() || b + 1 < chain[1].size()) {
        const bool step0 = b + 1 >= chain[1].size() || (a + 1 < chain[0].size() && chain[0][a + 1] <= chain[1][b + 1]);
        if (step0) {
          triangle(vtx(0, a), vtx(1, b), vtx(0, a + 1));
          ++a;
        } else {
          triangle(vtx(0, a), vtx(1, b), vtx(1, b + 1));
          ++b;
        }
      }
    }
  }
  // The canvas border, counter-clockwise seen from above: right to left along the top edge,
  // down the left, along the bottom, up the right.
  for (int i = nx - 1; i > 0; --i)
    if (active[i]) mesh.border.push_back(vertex(i, 0));
  for (int j = 0; j < ny - 1; ++j)
    if (active[size_t(j) * nx]) mesh.border.push_back(vertex(0, j));
  for (int i = 0; i < nx - 1; ++i)
    if (active[size_t(ny - 1) * nx + i]) mesh.border.push_back(vertex(i, ny - 1));
  for (int j = ny - 1; j > 0; --j)
    if (active[size_t(j) * nx + nx - 1]) mesh.border.push_back(vertex(nx - 1, j));
  return mesh;
}

void write_height_exr(const std::string& path, const FloatImage& height_cells) {
  check_height_map(height_cells);
  const int w = height_cells.width, h = height_cells.height;
  std::vector<float> mm(height_cells.data.size());
  for (size_t i = 0; i < mm.size(); ++i) mm[i] = float(double(height_cells.data[i]) * kCellMm);
  std::string bytes;
  try {
    Imf::Header header(w, h);
    header.compression() = Imf::ZIP_COMPRESSION;
    header.channels().insert("Y", Imf::Channel(Imf::FLOAT));
    header.insert("wetbrush:units", Imf::StringAttribute("mm"));
    header.insert("wetbrush:cell_size_mm", Imf::StringAttribute("0.2"));
    Imf::StdOSStream os;
    {
      Imf::OutputFile file(os, header);
      Imf::FrameBuffer fb;
      fb.insert("Y", Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(mm.data()), sizeof(float), sizeof(float) * size_t(w)));
      file.setFrameBuffer(fb);
      file.writePixels(h);
    }
    bytes = os.str();
  } catch (const std::exception& e) {
    WB_THROW(path + ": cannot encode the OpenEXR height map: " + e.what());
  }
  write_file_atomic(path, bytes.data(), bytes.size());
}

StlStats write_relief_stl(const std::string& path, const FloatImage& height_cells, double base_mm, double error_mm) {
  WB_REQUIRE(std::isfinite(base_mm) && base_mm > 0.0 && base_mm <= 1000.0,
             "STL export: the base thickness must be in (0, 1000] mm");
  WB_REQUIRE(std::isfinite(error_mm) && error_mm >= 0.0, "STL export: the error bound must be >= 0 mm");
  const ReliefMesh mesh = decimate_height_map(height_cells, error_mm / kCellMm);
  const double extent_y = height_cells.height * kCellMm;
  // Millimetres, z up and y up the image: the image is not mirrored seen from above.
  auto top = [&](uint32_t v) {
    return std::array<float, 3>{float(mesh.x[v] * kCellMm), float(extent_y - mesh.y[v] * kCellMm),
                                float(base_mm + mesh.h[v] * kCellMm)};
  };
  auto bottom = [&](uint32_t v) {
    std::array<float, 3> p = top(v);
    p[2] = 0.f;
    return p;
  };
  using P = std::array<float, 3>;
  std::vector<std::array<P, 3>> tris;
  tris.reserve(mesh.triangle_count() + 4 * mesh.border.size());
  // Adds a triangle facing `out` (its winding reversed if it faced away).
  auto add = [&](P a, P b, P c, const double out[3]) {
    const double u[3] = {double(b[0]) - a[0], double(b[1]) - a[1], double(b[2]) - a[2]};
    const double v[3] = {double(c[0]) - a[0], double(c[1]) - a[1], double(c[2]) - a[2]};
    const double n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
    if (n[0] * out[0] + n[1] * out[1] + n[2] * out[2] < 0) std::swap(b, c);
    tris.push_back({a, b, c});
  };
  const double up[3] = {0, 0, 1}, down[3] = {0, 0, -1};
  for (size_t t = 0; t < mesh.triangles.size(); t += 3)
    add(top(mesh.triangles[t]), top(mesh.triangles[t + 1]), top(mesh.triangles[t + 2]), up);
  // Walls down the border and a bottom fanned from its centre: every edge has two triangles.
  const double cx = 0.5 * height_cells.width * kCellMm, cy = 0.5 * extent_y;
  const P centre{float(cx), float(cy), 0.f};
  const size_t nb = mesh.border.size();
  for (size_t k = 0; k < nb; ++k) {
    const uint32_t a = mesh.border[k], b = mesh.border[(k + 1) % nb];
    const P at = top(a), bt = top(b), ab = bottom(a), bb = bottom(b);
    const double out[3] = {0.5 * (at[0] + bt[0]) - cx, 0.5 * (at[1] + bt[1]) - cy, 0.0};
    add(at, bt, bb, out);
    add(at, bb, ab, out);
    add(centre, ab, bb, down);
  }

  std::vector<uint8_t> bytes(84 + 50 * tris.size(), 0);
  const char title[] = "wetbrush relief: millimetres, z up";
  std::memcpy(bytes.data(), title, sizeof title - 1);
  const uint32_t count = uint32_t(tris.size());
  std::memcpy(&bytes[80], &count, 4);
  StlStats stats;
  stats.triangles = tris.size();
  uint8_t* p = &bytes[84];
  for (const auto& t : tris) {
    const double u[3] = {double(t[1][0]) - t[0][0], double(t[1][1]) - t[0][1], double(t[1][2]) - t[0][2]};
    const double v[3] = {double(t[2][0]) - t[0][0], double(t[2][1]) - t[0][1], double(t[2][2]) - t[0][2]};
    double n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
    const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    float nf[3] = {0, 0, 0};
    if (len > 0)
      for (int k = 0; k < 3; ++k) nf[k] = float(n[k] / len);
    std::memcpy(p, nf, 12);
    for (int k = 0; k < 3; ++k) std::memcpy(p + 12 + 12 * k, t[k].data(), 12);
    p += 50;  // the attribute byte count stays 0
    // Divergence theorem: the signed tetrahedra from the origin.
    const auto& a = t[0];
    const auto& b = t[1];
    const auto& c = t[2];
    stats.volume_mm3 += (double(a[0]) * (double(b[1]) * c[2] - double(b[2]) * c[1]) -
                         double(a[1]) * (double(b[0]) * c[2] - double(b[2]) * c[0]) +
                         double(a[2]) * (double(b[0]) * c[1] - double(b[1]) * c[0])) /
                        6.0;
  }
  write_file_atomic(path, bytes);
  return stats;
}

GltfStats write_relief_glb(const std::string& path, const FloatImage& height_cells, const FloatImage& albedo,
                           double error_mm) {
  WB_REQUIRE(std::isfinite(error_mm) && error_mm >= 0.0, "glTF export: the error bound must be >= 0 mm");
  WB_REQUIRE(albedo.width == height_cells.width && albedo.height == height_cells.height && albedo.channels == 3,
             "glTF export: the colour map must be RGB of the height map's size");
  const ReliefMesh mesh = decimate_height_map(height_cells, error_mm / kCellMm);
  const size_t nv = mesh.vertex_count();
  const int w = height_cells.width, h = height_cells.height;
  constexpr double m_per_cell = kCellMm * 1e-3;

  // Interleaving is not needed: one buffer holds positions, normals, UVs, indices and the PNG.
  std::vector<float> pos(nv * 3), nrm(nv * 3), uv(nv * 2);
  float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  auto cell_h = [&](int cx, int cy) { return double(height_cells.at(std::clamp(cx, 0, w - 1), std::clamp(cy, 0, h - 1))); };
  for (size_t v = 0; v < nv; ++v) {
    // glTF is y up: canvas x -> x, height -> y, canvas y (down the image) -> z.
    const float p[3] = {float(mesh.x[v] * m_per_cell), float(mesh.h[v] * m_per_cell), float(mesh.y[v] * m_per_cell)};
    for (int k = 0; k < 3; ++k) {
      pos[v * 3 + k] = p[k];
      lo[k] = std::min(lo[k], p[k]);
      hi[k] = std::max(hi[k], p[k]);
    }
    // The height map's slope at the vertex's cell (central differences; heights and lengths in cells).
    const int cx = std::clamp(int(std::floor(mesh.x[v])), 0, w - 1), cy = std::clamp(int(std::floor(mesh.y[v])), 0, h - 1);
    const int xl = std::max(cx - 1, 0), xr = std::min(cx + 1, w - 1), yl = std::max(cy - 1, 0), yr = std::min(cy + 1, h - 1);
    const double dx = xr > xl ? (cell_h(xr, cy) - cell_h(xl, cy)) / (xr - xl) : 0.0;
    const double dy = yr > yl ? (cell_h(cx, yr) - cell_h(cx, yl)) / (yr - yl) : 0.0;
    const double len = std::sqrt(dx * dx + 1.0 + dy * dy);
    nrm[v * 3 + 0] = float(-dx / len);
    nrm[v * 3 + 1] = float(1.0 / len);
    nrm[v * 3 + 2] = float(-dy / len);
    uv[v * 2 + 0] = float(mesh.x[v] / w);
    uv[v * 2 + 1] = float(mesh.y[v] / h);
  }
  const std::vector<uint8_t> png = encode_png8(to_rgb8(albedo).data(), w, h, 3);

  tinygltf::Model model;
  model.asset.version = "2.0";
  model.asset.generator = "wetbrush";
  tinygltf::Buffer buffer;
  auto append = [&](const void* data, size_t bytes, int target) {
    while (buffer.data.size() % 4) buffer.data.push_back(0);  // accessors need 4-byte alignment
    tinygltf::BufferView view;
    view.buffer = 0;
    view.byteOffset = buffer.data.size();
    view.byteLength = bytes;
    view.target = target;
    const auto* b = static_cast<const uint8_t*>(data);
    buffer.data.insert(buffer.data.end(), b, b + bytes);
    model.bufferViews.push_back(view);
    return int(model.bufferViews.size() - 1);
  };
  auto accessor = [&](int view, int component, int type, size_t count) {
    tinygltf::Accessor a;
    a.bufferView = view;
    a.componentType = component;
    a.type = type;
    a.count = count;
    model.accessors.push_back(a);
    return int(model.accessors.size() - 1);
  };
  const int a_pos = accessor(append(pos.data(), pos.size() * 4, TINYGLTF_TARGET_ARRAY_BUFFER),
                             TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, nv);
  model.accessors[size_t(a_pos)].minValues = {lo[0], lo[1], lo[2]};
  model.accessors[size_t(a_pos)].maxValues = {hi[0], hi[1], hi[2]};
  const int a_nrm = accessor(append(nrm.data(), nrm.size() * 4, TINYGLTF_TARGET_ARRAY_BUFFER),
                             TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, nv);
  const int a_uv = accessor(append(uv.data(), uv.size() * 4, TINYGLTF_TARGET_ARRAY_BUFFER),
                            TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC2, nv);
  const int a_idx = accessor(append(mesh.triangles.data(), mesh.triangles.size() * 4, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER),
                             TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, TINYGLTF_TYPE_SCALAR, mesh.triangles.size());
  tinygltf::Image image;
  image.name = "albedo";
  image.mimeType = "image/png";
  image.bufferView = append(png.data(), png.size(), 0);
  image.width = w;
  image.height = h;
  model.images.push_back(image);
  model.buffers.push_back(std::move(buffer));

  tinygltf::Sampler sampler;
  sampler.magFilter = TINYGLTF_TEXTURE_FILTER_LINEAR;
  sampler.minFilter = TINYGLTF_TEXTURE_FILTER_LINEAR;
  sampler.wrapS = sampler.wrapT = TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE;
  model.samplers.push_back(sampler);
  tinygltf::Texture texture;
  texture.source = 0;
  texture.sampler = 0;
  model.textures.push_back(texture);
  tinygltf::Material material;
  material.name = "paint";
  material.pbrMetallicRoughness.baseColorTexture.index = 0;
  material.pbrMetallicRoughness.metallicFactor = 0.0;
  material.pbrMetallicRoughness.roughnessFactor = 0.6;  // oil paint: a soft sheen
  model.materials.push_back(material);

  tinygltf::Primitive prim;
  prim.attributes["POSITION"] = a_pos;
  prim.attributes["NORMAL"] = a_nrm;
  prim.attributes["TEXCOORD_0"] = a_uv;
  prim.indices = a_idx;
  prim.material = 0;
  prim.mode = TINYGLTF_MODE_TRIANGLES;
  tinygltf::Mesh gmesh;
  gmesh.name = "paint surface";
  gmesh.primitives.push_back(prim);
  model.meshes.push_back(gmesh);
  tinygltf::Node node;
  node.mesh = 0;
  node.name = "painting";
  model.nodes.push_back(node);
  tinygltf::Scene scene;
  scene.nodes.push_back(0);
  model.scenes.push_back(scene);
  model.defaultScene = 0;

  std::ostringstream os;
  tinygltf::TinyGLTF writer;
  WB_REQUIRE(writer.WriteGltfSceneToStream(&model, os, false, true), path + ": cannot encode the glTF binary");
  const std::string bytes = os.str();
  write_file_atomic(path, bytes.data(), bytes.size());
  return GltfStats{nv, mesh.triangle_count(), mesh.grid_vertices};
}

ReliefStats write_relief_exports(const Device& device, TileStore& canvas, const ReliefPaths& paths,
                                 const ReliefOptions& options) {
  ReliefStats stats;
  if (paths.exr.empty() && paths.stl.empty() && paths.glb.empty()) return stats;
  Renderer r(device);
  const FloatImage height = r.render_height_map(canvas);
  if (!paths.exr.empty()) write_height_exr(paths.exr, height);
  if (!paths.stl.empty()) stats.stl = write_relief_stl(paths.stl, height, options.base_mm, options.error_mm);
  if (!paths.glb.empty()) stats.glb = write_relief_glb(paths.glb, height, r.render_albedo(canvas), options.error_mm);
  return stats;
}

ReliefStats write_relief_exports(Session& session, const ReliefPaths& paths, const ReliefOptions& options) {
  TileStore canvas = session.canvas_copy(session.device());
  return write_relief_exports(session.device(), canvas, paths, options);
}

}  // namespace wb
