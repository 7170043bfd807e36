// The paint fields of one canvas cell (paper §3: liquid density, pigment, oil
// density, dryness), listed once. The list generates the dense window's buffers,
// its POD view, the tile encoding and the document serialisation.
#pragma once

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

/// One cell's paint, decoded (host-side helper type for tests, I/O and probes).
struct PaintCell {
#define WB_X(name, doc) float name = 0.f;
  WB_PAINT_FIELDS(WB_X)
#undef WB_X
};

}  // namespace wb
