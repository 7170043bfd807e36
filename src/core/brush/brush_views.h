// Brush stage (paper §4.1): the POD views the brush kernels take. The environment
// (drag from the paint flow, dried paint as solid) and the brush frame's motion are
// plain values; the bristle state is SoA, one entry per vertex (bristle k, vertex i at
// k * per_bristle + i; vertex 0 is the root, pinned in the ferrule).
#pragma once
#include <cstdint>

#include "core/canvas/tile_store.h"
#include "core/exec/hd.h"
#include "core/math/vec.h"

namespace wb {

/// The paint's flow for the drag term of Eq. 2 (a_i) on the active window of nx x ny x nz cells
/// at canvas cell (ox, oy, oz): the grid's MAC velocity (sample_mac's layout, canvas cells/s),
/// read where the bristle is, and the cell-centred density (value (x, y, z) at canvas
/// (ox + x + 0.5, oy + y + 0.5, oz + z + 0.5)). The drag acceleration is
/// k * density * (u - v_vertex), 1/s.
struct DragField {
  const float* u = nullptr;  ///< (nx + 1) x ny x nz faces
  const float* v = nullptr;  ///< nx x (ny + 1) x nz faces
  const float* w = nullptr;  ///< nx x ny x (nz + 1) faces
  const float* density = nullptr;
  int nx = 0, ny = 0, nz = 0;
  int ox = 0, oy = 0, oz = 0;
  float k = 0.f;
};

/// Dried paint on the canvas: a cell is solid when density > 0 and dryness >= threshold.
/// valid == false: no canvas store (only the canvas plane z = 0 collides).
struct SolidField {
  TileStoreView tiles{};
  float dryness_threshold = 0.9f;
  bool valid = false;
};

/// Per-vertex state, device pointers. "_old" holds the state at the start of the
/// step: it gives the PBD velocities and is the copy restored when a step goes non-finite.
struct BristleState {
  Vec3* xb;      ///< position in the brush frame, cells (Eq. 1: x^B = R_B (x + c_B))
  Vec3* vb;      ///< velocity relative to the brush frame, brush coordinates, cells/s
  Vec3* x;       ///< position in the canvas frame, cells
  Vec3* v;       ///< velocity in the canvas frame, cells/s
  Vec3* xb_old;
  Vec3* vb_old;
  Vec3* x_old;
  Vec3* v_old;
  Vec3* delta;   ///< scratch: minimum-density corrections
  int bristles;
  int per_bristle;
  WB_HD int64_t count() const { return int64_t(bristles) * per_bristle; }
};

/// Rest description of the bristles, device pointers.
struct BristleRest {
  const Vec3* root;          ///< per bristle: root in the ferrule, brush frame
  const Vec3* dir;           ///< per bristle: unit rest direction, brush frame
  const float* seg_length;   ///< per vertex i >= 1: rest length of segment (i-1, i); entry 0 unused
  const float* bend_k;       ///< per bristle: bending stiffness per solver iteration, [0, 1]
};

/// The brush frame at the end of the step and its motion (all in brush coordinates),
/// the quantities of Eq. 2.
struct BrushFrame {
  Mat3 R;          ///< brush -> canvas (pose.rotation)
  Mat3 R_B;        ///< canvas -> brush (Eq. 1)
  Vec3 p;          ///< ferrule centre, canvas cells (-c_B)
  Vec3 vdot_B;     ///< linear acceleration of the frame, cells/s^2
  Vec3 omega_B;    ///< angular velocity of the frame, rad/s
  Vec3 omegadot_B; ///< angular acceleration of the frame, rad/s^2
};

/// External forces of Eq. 2 (a_i) as the kernels see them.
struct BrushForces {
  Vec3 gravity;    ///< canvas frame, cells/s^2
  DragField drag;
  bool has_drag;
};

}  // namespace wb
