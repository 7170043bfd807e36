// Brush model (paper §4.1): bristle roots, rest directions, lengths and stiffness by
// shape, deterministic from the seed. See docs/BRUSH.md for the shape table.
#include "core/brush/brush_model.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <unordered_map>

#include "core/exec/error.h"

namespace wb {

namespace {

uint64_t splitmix64(uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}
/// Uniform in [-1, 1], a pure function of (seed, bristle, channel).
float unit_noise(uint32_t seed, int k, int channel) {
  const uint64_t h = splitmix64((uint64_t(seed) << 32) ^ (uint64_t(uint32_t(k)) << 4) ^ uint64_t(channel));
  return float(double(h >> 11) * (1.0 / 9007199254740992.0)) * 2.f - 1.f;
}

void check(bool ok, const std::string& field, const std::string& what) {
  if (!ok) WB_THROW("brush spec: " + field + " " + what);
}

bool elliptic(BrushShape s) { return s == BrushShape::Round || s == BrushShape::Mop || s == BrushShape::Rigger; }

/// Roots in the ferrule's mouth (z = 0). Elliptic shapes: a Vogel (sunflower) spiral, which
/// spaces points evenly; flat shapes: a jittered grid of rows across the thickness.
std::vector<Vec3> place_roots(const BrushSpec& spec) {
  const int n = spec.bristles;
  std::vector<Vec3> roots(static_cast<size_t>(n));
  const float hw = 0.5f * spec.width, ht = 0.5f * spec.thickness;
  if (elliptic(spec.shape)) {
    const float golden = 2.39996323f;
    const float turn = 3.14159265f * unit_noise(spec.seed, -1, 7);
    for (int k = 0; k < n; ++k) {
      const float r = std::sqrt((float(k) + 0.5f) / float(n));
      const float a = float(k) * golden + turn;
      roots[size_t(k)] = Vec3(hw * r * std::cos(a), ht * r * std::sin(a), 0.f);
    }
    return roots;
  }
  const int rows = std::max(1, int(std::lround(std::sqrt(double(n) * spec.thickness / spec.width))));
  const int cols = (n + rows - 1) / rows;
  const float sx = spec.width / float(cols), sy = spec.thickness / float(rows);
  for (int k = 0; k < n; ++k) {
    const int c = k / rows, r = k % rows;
    const float jx = 0.2f * sx * unit_noise(spec.seed, k, 1), jy = 0.2f * sy * unit_noise(spec.seed, k, 2);
    const float x = (float(c) + 0.5f) * sx - hw + jx;
    const float y = (float(r) + 0.5f + ((c & 1) ? 0.25f : -0.25f) * (rows > 1 ? 1.f : 0.f)) * sy - ht + jy;
    roots[size_t(k)] = Vec3(x, std::clamp(y, -ht, ht), 0.f);
  }
  return roots;
}

/// Rest direction (brush frame, bristles hang along -z): round and rigger taper to a
/// point, the mop splays slightly, the fan spreads in angle across its width.
Vec3 rest_direction(const BrushSpec& spec, Vec3 root, float length) {
  switch (spec.shape) {
    case BrushShape::Round:
      return normalize(Vec3(-0.6f * root.x, -0.6f * root.y, -length));
    case BrushShape::Rigger:
      return normalize(Vec3(-0.5f * root.x, -0.5f * root.y, -length));
    case BrushShape::Mop:
      return normalize(Vec3(0.2f * root.x, 0.2f * root.y, -length));
    case BrushShape::Fan: {
      const float a = (root.x / (0.5f * spec.width)) * 0.7f;  // +-40 degrees at the edges
      return Vec3(std::sin(a), 0.f, -std::cos(a));
    }
    default:
      return Vec3(0.f, 0.f, -1.f);
  }
}

}  // namespace

float shape_length_profile(BrushShape shape, float x, float width) {
  const float u = std::clamp(x / (0.5f * width), -1.f, 1.f);  // -1 .. 1 across the width
  switch (shape) {
    case BrushShape::Filbert:
      return 0.7f + 0.3f * std::sqrt(std::max(0.f, 1.f - u * u));
    case BrushShape::Angular:
      return 1.f - 0.2f * (u + 1.f);  // 1 at -width/2 down to 0.6 at +width/2
    default:
      return 1.f;
  }
}

BristleLayout build_bristle_layout(const BrushSpec& spec) {
  check(spec.bristles >= 1 && spec.bristles <= 8192, "bristles", "must be in 1..8192 (got " + std::to_string(spec.bristles) + ")");
  check(spec.vertices_per_bristle >= 3 && spec.vertices_per_bristle <= 64, "vertices_per_bristle",
        "must be in 3..64 (got " + std::to_string(spec.vertices_per_bristle) + ")");
  check(spec.samples_per_bristle >= 2 && spec.samples_per_bristle <= 4096, "samples_per_bristle",
        "must be in 2..4096 (got " + std::to_string(spec.samples_per_bristle) + ")");
  check(std::isfinite(spec.length) && spec.length > 0.f && spec.length <= 2000.f, "length", "must be in (0, 2000] cells");
  check(std::isfinite(spec.width) && spec.width > 0.f && spec.width <= 2000.f, "width", "must be in (0, 2000] cells");
  check(std::isfinite(spec.thickness) && spec.thickness > 0.f && spec.thickness <= 2000.f, "thickness",
        "must be in (0, 2000] cells");
  check(spec.length_variation >= 0.f && spec.length_variation <= 0.5f, "length_variation", "must be in [0, 0.5]");
  check(spec.stiffness >= 0.f && spec.stiffness <= 1.f, "stiffness", "must be in [0, 1]");
  check(spec.stiffness_variation >= 0.f && spec.stiffness_variation <= 1.f, "stiffness_variation", "must be in [0, 1]");
  check(std::isfinite(spec.bristle_radius) && spec.bristle_radius > 0.f && spec.bristle_radius <= 10.f,
        "bristle_radius", "must be in (0, 10] cells");
  check(spec.beta_B >= 0.f && spec.beta_B <= 1.f, "beta_B", "must be in [0, 1]");
  check(spec.max_press >= 0.f && spec.max_press <= 1.f, "max_press", "must be in [0, 1]");

  BristleLayout L;
  L.bristles = spec.bristles;
  L.per_bristle = spec.vertices_per_bristle;
  L.root = place_roots(spec);
  const int n = spec.bristles, V = spec.vertices_per_bristle;
  L.dir.resize(size_t(n));
  L.length.resize(size_t(n));
  L.stiffness.resize(size_t(n));
  L.rest.resize(size_t(n) * V);
  float max_length = 0.f;
  for (int k = 0; k < n; ++k) {
    const Vec3 root = L.root[size_t(k)];
    const float len = spec.length * shape_length_profile(spec.shape, root.x, spec.width) *
                      (1.f + spec.length_variation * unit_noise(spec.seed, k, 3));
    L.length[size_t(k)] = len;
    max_length = std::max(max_length, len);
    L.stiffness[size_t(k)] = std::clamp(spec.stiffness * (1.f + spec.stiffness_variation * unit_noise(spec.seed, k, 4)), 0.f, 1.f);
    const Vec3 d = rest_direction(spec, root, len);
    L.dir[size_t(k)] = d;
    for (int i = 0; i < V; ++i) L.rest[size_t(k) * V + i] = root + d * (len * float(i) / float(V - 1));
  }
  // The paper asks for a sample gap below one cell (so that psi and the contact trace
  // have no holes); the Hermite arc is at most a few percent longer than the polyline.
  const float gap = max_length / float(spec.samples_per_bristle - 1);
  check(gap < 1.f, "samples_per_bristle",
        "too small: the longest bristle (" + std::to_string(max_length) + " cells) would have samples " +
            std::to_string(gap) + " cells apart; use at least " + std::to_string(int(std::ceil(max_length)) + 2));

  // Closest rest vertices of different bristles, searched up to 2 r (the contact
  // distance the minimum-density constraint keeps) with a hash grid of that cell size.
  const float probe = 2.f * spec.bristle_radius;
  std::unordered_map<int64_t, std::vector<int>> grid;
  auto cell_key = [&](int cx, int cy, int cz) {
    return (int64_t(cx) * 73856093) ^ (int64_t(cy) * 19349663) ^ (int64_t(cz) * 83492791);
  };
  auto cell_of = [&](Vec3 p, int& cx, int& cy, int& cz) {
    cx = int(std::floor(p.x / probe));
    cy = int(std::floor(p.y / probe));
    cz = int(std::floor(p.z / probe));
  };
  for (int g = 0; g < n * V; ++g) {
    int cx, cy, cz;
    cell_of(L.rest[size_t(g)], cx, cy, cz);
    grid[cell_key(cx, cy, cz)].push_back(g);
  }
  float best2 = probe * probe;
  for (int g = 0; g < n * V; ++g) {
    int cx, cy, cz;
    cell_of(L.rest[size_t(g)], cx, cy, cz);
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          auto it = grid.find(cell_key(cx + dx, cy + dy, cz + dz));
          if (it == grid.end()) continue;
          for (int h : it->second)
            if (h / V != g / V) best2 = std::min(best2, length2(L.rest[size_t(g)] - L.rest[size_t(h)]));
        }
  }
  L.min_rest_spacing = std::sqrt(best2);
  return L;
}

std::vector<float> dip_exposure(const BristleLayout& L, int S, float depth) {
  const int V = L.per_bristle;
  std::vector<float> out(size_t(L.bristles) * size_t(S), 0.f);
  if (L.bristles == 0 || V < 2 || S < 2 || !(depth > 0.f)) return out;
  float lowest = 0.f, half_x = 0.f, half_y = 0.f;
  for (const Vec3& p : L.rest) lowest = std::min(lowest, p.z);
  for (const Vec3& r : L.root) half_x = std::max(half_x, std::fabs(r.x)), half_y = std::max(half_y, std::fabs(r.y));
  for (int k = 0; k < L.bristles; ++k) {
    const Vec3 r = L.root[size_t(k)];
    const float ex = half_x > 0.f ? r.x / half_x : 0.f, ey = half_y > 0.f ? r.y / half_y : 0.f;
    const float outer = 1.f / 3.f + (2.f / 3.f) * std::min(1.f, std::sqrt(ex * ex + ey * ey));
    for (int j = 0; j < S; ++j) {
      const float sp = float(j) * float(V - 1) / float(S - 1);
      const int i = std::min(int(sp), V - 2);
      const float u = sp - float(i);
      const float z = L.rest[size_t(k) * V + i].z * (1.f - u) + L.rest[size_t(k) * V + i + 1].z * u;
      out[size_t(k) * S + j] = outer * std::clamp(1.f - (z - lowest) / depth, 0.f, 1.f);
    }
  }
  return out;
}

}  // namespace wb
