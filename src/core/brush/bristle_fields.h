// Bristle samples (paper §4.1 "Bristle samples and local frames"): the dense points
// along each bristle's Hermite spline, with their minimal-twist frames and the
// motion of those frames, which Eq. 9 needs. Listed once; the list generates the
// owning buffers and the POD view that kernels take.
#pragma once
#include <cstdint>

#include "core/math/vec.h"

// X(type, name, description)
#define WB_SAMPLE_FIELDS(X)                                                              \
  X(Vec3, x, "position, canvas cells")                                                 \
  X(Vec3, t, "unit tangent along the bristle, root to tip")                            \
  X(Vec3, n, "unit Bishop normal (minimal twist, Bishop 1975)")                        \
  X(Vec3, b, "unit binormal, t x n")                                                   \
  X(Vec3, v, "linear velocity, cells/s, canvas frame")                                 \
  X(Vec3, omega, "angular velocity of the frame, rad/s, canvas frame")                 \
  X(Vec3, a, "linear acceleration, cells/s^2, canvas frame (rate of v)")               \
  X(Vec3, alpha, "angular acceleration, rad/s^2, canvas frame (rate of omega)")

namespace wb {

/// POD view of all bristle samples: sample j of bristle k is at k * per_bristle + j.
struct SampleView {
#define WB_X(type, name, doc) type* name;
  WB_SAMPLE_FIELDS(WB_X)
#undef WB_X
  int bristles;
  int per_bristle;
  WB_HD int64_t count() const { return int64_t(bristles) * per_bristle; }
};

}  // namespace wb
