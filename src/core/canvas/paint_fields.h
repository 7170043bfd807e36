// The paint fields of one canvas cell (paper §3: liquid density, pigment, oil
// density, dryness), listed once. The list generates the dense window's buffers,
// its POD view, the tile encoding and the document serialisation.
#pragma once
#include "core/exec/hd.h"

// X(name, description)
#define WB_PAINT_FIELDS(X)                                                            \
  X(density, "paint volume fraction of the cell, 1 = full at rho0 (mass = density*rho0*h^3)") \
  X(pigment_r, "RYB pigment, red component in [0, 1]")                                \
  X(pigment_y, "RYB pigment, yellow component in [0, 1]")                             \
  X(pigment_b, "RYB pigment, blue component in [0, 1]")                              \
  X(oil, "oil density in [0, 1]: more oil = thinner, more transparent paint")       \
  X(dryness, "dryness in [0, 1]; solid at and above the drying threshold")

namespace wb {

/// Number of fields in WB_PAINT_FIELDS.
inline constexpr int kPaintFieldCount = 6;

/// Dried paint is solid (§4.2 "we treat it as a solid cell") where a cell holds at least this much
/// of it: the level at which the grid counts paint as liquid and the renderer and the transfer find
/// its surface. A cell with less (the dried trace of a wet stroke's thin top and edges, often a few
/// hundredths) lies above that surface; counted solid as a whole, it held the brush, the particles
/// and the grid's wet paint up to a cell above the dried surface (docs/TRANSFER.md "The brush on
/// dried paint"). One rule for the grid, the particles, the transfer and the brush.
inline constexpr float kSolidDensity = 0.5f;
WB_HD WB_INLINE bool dried_solid(float density, float dryness, float dry_threshold) {
  return (density >= kSolidDensity) & (dryness >= dry_threshold);  // no branch: column scans vectorise over it
}

/// One cell's paint, decoded (host-side helper type for tests, I/O and probes).
struct PaintCell {
#define WB_X(name, doc) float name = 0.f;
  WB_PAINT_FIELDS(WB_X)
#undef WB_X
};

}  // namespace wb
