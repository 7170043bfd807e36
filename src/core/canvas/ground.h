// The canvas's ground: the primed weave paint is laid on (docs/STUDIO.md "Canvas texture").
// A woven ground is dried paint of the priming's colour, laid once when the canvas is made, so
// every stage that already meets dried paint (the brush's collision, the transfer's gap, the
// particles' floor, the grid's solid cells, the renderer) meets the weave the same way: a lightly
// loaded brush rests on the threads' crowns and leaves the valleys bare (dry brush).
#pragma once
#include <cmath>
#include <cstdint>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "core/exec/hd.h"
#include "core/math/vec.h"

namespace wb {

enum class Weave {
  Smooth,      ///< a smooth primed board: the bare canvas plane, nothing laid
  Linen,       ///< plain weave of uneven threads (slubs): the painter's fine canvas
  CottonDuck,  ///< plain weave of even, tightly beaten threads
};
const char* to_string(Weave w);

/// What a new canvas is primed with. Sizes in mm (the grid's cell is GridParams::cell_size).
struct CanvasGround {
  Weave weave = Weave::Smooth;
  float thread_mm = 1.0f;  ///< distance between neighbouring threads of the warp (and the weft)
  float relief_mm = 0.3f;  ///< height of a thread's crown over the weave's hollows
  float priming_mm = 0.2f; ///< primer under the weave's hollows (they are not bare cloth)
  bool operator==(const CanvasGround&) const = default;
  /// The defaults of a weave: linen 1.0 mm threads in 0.3 mm relief, cotton duck 0.8 mm in 0.2 mm.
  static CanvasGround of(Weave w);
};

/// Ranges a ground file or dialog may hold; outside them the reader refuses.
inline constexpr float kThreadMmMin = 0.4f, kThreadMmMax = 5.f;
inline constexpr float kReliefMmMin = 0.f, kReliefMmMax = 2.f;
inline constexpr float kPrimingMmMax = 2.f;

nlohmann::json ground_to_json(const CanvasGround& g);
/// Reads and validates a ground, the object at `path` of file `source` (named in errors; throws
/// wb::Error). Values in mm within the ranges above; unknown keys are refused.
CanvasGround ground_from_json(const nlohmann::json& j, const std::string& source, const std::string& path);
/// "smooth", "linen", "cotton_duck"; throws wb::Error naming `what` for other names.
Weave weave_from_name(const std::string& name, const std::string& what);

/// The weave in canvas cells, for the kernel that lays it.
struct WeaveField {
  float spacing = 5.f;   ///< thread spacing, cells
  float relief = 1.5f;   ///< crown over hollow, cells
  float base = 1.f;      ///< primer under the hollows, cells
  float unevenness = 0.f;  ///< 0: even threads; 1: linen's thick and thin threads and slubs
  Vec3 ryb{};            ///< the primer's pigment
  float oil = 0.1f;      ///< a lean, opaque primer
};
WeaveField weave_field(const CanvasGround& g, float cell_size_m, Vec3 priming_ryb);

/// Most paint a woven ground may lay, bytes, and so what a painting may hold
/// (LoadLimits::max_paint_bytes): a primed canvas always opens again. A ground fills every tile.
inline constexpr uint64_t kMaxGroundBytes = uint64_t(4) << 30;
/// Why a width x height x depth canvas cannot take this ground: thicker than half the paint depth,
/// or more paint in its tiles than kMaxGroundBytes. Empty when it can (and for a smooth ground).
std::string ground_refusal(const CanvasGround& g, int width, int height, int depth, float cell_size_m);

/// Linen's threads vary by up to a third of their thickness either way (weave_thickness).
inline constexpr float kThreadVariation = 1.f / 3.f;
/// A thread's thickness factor in [1 - u/3, 1 + u/3] from its index and a segment along it.
WB_HD WB_INLINE float weave_thickness(int thread, int segment, float unevenness) {
  uint32_t h = uint32_t(thread) * 0x9E3779B1u ^ (uint32_t(segment) + 0x7F4A7C15u) * 0x85EBCA77u;
  h ^= h >> 15;
  h *= 0x2C1B3C6Du;
  h ^= h >> 12;
  const float r = float(h & 0xFFFFu) * (1.f / 65535.f);  // [0, 1]
  return 1.f + unevenness * (r - 0.5f) * (2.f * kThreadVariation);
}

/// Height of the ground at canvas point (x, y), cells: a plain weave, the warp along x and the
/// weft along y crossing over and under in turn. Each thread's crown follows a half-disc across
/// it and rises and falls along it between the crossings where it lies on top and below.
WB_HD WB_INLINE float weave_height(const WeaveField& w, float x, float y) {
  const float kPi = 3.14159265f;
  const float u = x / w.spacing, v = y / w.spacing;
  const int i = int(floorf(u)), j = int(floorf(v));
  const float fu = u - float(i) - 0.5f, fv = v - float(j) - 0.5f;  // across the weft / warp, [-0.5, 0.5)
  // Warp thread j (runs along x) is on top over weft i where i + j is even.
  const float parity_j = (j & 1) ? kPi : 0.f, parity_i = (i & 1) ? kPi : 0.f;
  const float warp_rise = 0.5f + 0.5f * cosf(kPi * (u - 0.5f) + parity_j);
  const float weft_rise = 0.5f - 0.5f * cosf(kPi * (v - 0.5f) + parity_i);
  // Linen's threads vary in thickness from thread to thread and along a thread (slubs, a few
  // crossings long).
  const float tw = weave_thickness(2 * j, int(floorf(u / 3.f)), w.unevenness);
  const float tf = weave_thickness(2 * i + 1, int(floorf(v / 3.f)), w.unevenness);
  const float aw = 1.f - (2.f * fv / tw) * (2.f * fv / tw), af = 1.f - (2.f * fu / tf) * (2.f * fu / tf);
  const float warp = aw > 0.f ? sqrtf(aw) * tw * (0.35f + 0.65f * warp_rise) : 0.f;
  const float weft = af > 0.f ? sqrtf(af) * tf * (0.35f + 0.65f * weft_rise) : 0.f;
  return w.base + w.relief * (warp > weft ? warp : weft);
}

/// The dried density of cell z of a column whose ground top is `h` cells. Cells under the top are
/// full; the top cell holds what is left, but dried paint is solid only from kSolidDensity (0.5)
/// up, so a top cell is laid at 0, 0.5 or its fill: the surface every stage reads is the one laid.
WB_HD WB_INLINE float ground_density(float h, int z) {
  const float n = floorf(h);
  float f = h - n;
  f = f < 0.25f ? 0.f : (f < 0.5f ? 0.5f : f);
  const float zf = float(z);
  return zf < n ? 1.f : (zf == n ? f : 0.f);
}

}  // namespace wb
