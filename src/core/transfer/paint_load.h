// The paint a brush is loaded with (paper §5.1: the samples' load m_j, pigment c_j and oil):
// what a stroke file's "paint", a palette well and the studio's wells hold.
#pragma once

namespace wb {

/// Paint on the brush at the start of the stroke (and at every pen-down when reloading).
struct PaintLoad {
  float ryb[3] = {0.1f, 0.15f, 0.85f};  ///< pigment, RYB in [0, 1] (default: a deep blue)
  float oil = 0.3f;                     ///< oil fraction in [0, 1] (viscosity, transparency)
  float load = 0.8f;                    ///< fraction of the bristles' capacity filled, [0, 1]
  bool reload_on_pen_down = true;       ///< refill to `load` at every pen-down edge
  bool operator==(const PaintLoad&) const = default;
};

}  // namespace wb
