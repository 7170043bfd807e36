// The bristle brush (paper §4.1, DESIGN step 1-2): bristles of 10 vertices simulated in
// the non-inertial brush frame (Eq. 1-2, beta_B), with position-based inextensibility,
// bending, collision and a minimum-density constraint; then 128 Hermite samples per
// bristle with Bishop frames and their motion, rasterised into psi for the grid.
#pragma once
#include <cstdint>
#include <vector>

#include "core/brush/bristle_fields.h"
#include "core/brush/brush_model.h"
#include "core/brush/brush_spec.h"
#include "core/brush/brush_stages.h"
#include "core/brush/brush_views.h"
#include "core/canvas/window.h"
#include "core/exec/buffer.h"
#include "core/exec/graph.h"
#include "core/exec/touch_list.h"
#include "core/exec/workspace.h"

namespace wb {

/// Standard gravity in canvas cells/s^2 (9.81 m/s^2, 1 cell = 0.2 mm).
inline constexpr float kGravityCells = 49050.f;

/// What the brush feels besides its own pose (a_i of Eq. 2 and the surfaces).
struct BrushEnvironment {
  Vec3 gravity{0.f, 0.f, -kGravityCells};  ///< canvas frame, cells/s^2
  const DragField* drag = nullptr;          ///< paint flow for the drag term; null = none (air)
  SolidField solid{};                       ///< dried paint; solid.valid = false: none
  float friction = 0.5f;                    ///< fraction of a contact vertex's sliding removed per step, [0, 1]
};

/// Numerical parameters of the brush solver (not part of a brush preset).
struct BrushSolverParams {
  int iterations = 8;               ///< Gauss-Seidel sweeps per step (bending, length, collision)
  int density_iterations = 4;       ///< minimum-density Jacobi iterations per step (0 = off)
  /// Decay rate of the brush-frame velocity, 1/s: v^B loses 1 - exp(-damping dt) over a
  /// (sub-)step of dt, so the decay per second is the same whatever the sub-step count.
  float damping = 25.f;
  float min_spacing = -1.f;         ///< s_min, cells; < 0: 2 * bristle_radius, capped by the rest spacing
};

struct BrushStats {
  float max_stretch = 0.f;  ///< max over segments of |l - l0| / l0
  float min_z = 0.f;        ///< lowest canvas z of any vertex or sample, cells
  int64_t nonfinite = 0;    ///< steps whose result was non-finite and rolled back, since construction
};

class Brush {
 public:
  /// Builds the bristles of `spec` at rest at `pose`; throws wb::Error on a bad spec.
  Brush(const Device& device, const BrushSpec& spec, const BrushPose& pose, const BrushSolverParams& params = {});

  const Device& device() const { return device_; }
  const BrushSpec& spec() const { return spec_; }
  const BrushSolverParams& params() const { return params_; }
  const BristleLayout& layout() const { return layout_; }
  const BrushPose& pose() const { return pose_; }
  int bristles() const { return spec_.bristles; }
  int vertices_per_bristle() const { return spec_.vertices_per_bristle; }
  int64_t vertex_count() const { return int64_t(spec_.bristles) * spec_.vertices_per_bristle; }
  int64_t sample_count() const { return int64_t(spec_.bristles) * spec_.samples_per_bristle; }
  /// The spacing s_min the minimum-density constraint keeps between bristles, cells.
  float min_spacing() const { return s_min_; }

  /// Puts the bristles back at rest at `pose`, forgetting all motion.
  void reset(const BrushPose& pose);

  /// One step of length dt in `substeps` equal sub-steps ending at poses[0..substeps):
  /// brush-frame dynamics (Eq. 2), constraints and collisions per sub-step, then the samples
  /// once, with the motion they made over the whole step (v, omega from the step's start and
  /// end states, a, alpha from the previous step's), so that Eq. 9's rewind x - v dt is exact
  /// whatever the sub-step count. Allocates nothing. A non-finite sub-step is rolled back on
  /// the device (see rollback_counter()).
  void step(const BrushPose* poses, int substeps, float dt, const BrushEnvironment& env);
  void step(const BrushPose& pose, float dt, const BrushEnvironment& env) { step(&pose, 1, dt, env); }
  /// Sub-steps whose result was non-finite and rolled back, since construction, as far as the
  /// host has learnt (rolled_back, stats()); no device work.
  int64_t rollbacks() const { return rollbacks_; }
  /// The device's count of rolled-back sub-steps (one int64_t), for a caller that reads it with
  /// its own results and then calls rolled_back() with it.
  const int64_t* rollback_counter() const { return nonfinite_.data() + 2; }
  /// The device's count as read: forgets the undone motion if it grew.
  void rolled_back(int64_t total);

  /// Bristle density psi (occupied volume fraction, clamped to 1) and the psi-weighted
  /// mean bristle velocity (cells/s) on the cell-centred window at `window_origin`, sized
  /// `window_dims`. Device pointers, window_dims.x*y*z floats each; zeroed here, or, given the
  /// list of the cells the last raster into them reached, zeroed there and the list kept anew.
  void rasterize(Int3 window_origin, Int3 window_dims, float* psi, float* vx, float* vy, float* vz,
                 TouchListBuffers* cells = nullptr);

  /// Sets trace[(y - oy) * trace_w + (x - ox)] = 1 (device pointer) for every canvas cell
  /// (x, y) holding a sample less than contact_height above the canvas or the dried paint
  /// given (solid.valid = false: the canvas plane only); returns how many distinct cells of the
  /// trace this step touches. The solid field is passed, not kept: the canvas pool it points
  /// into may have grown since the last step.
  int64_t mark_contacts(int32_t* trace, int trace_w, int trace_h, int ox, int oy, float contact_height,
                        const SolidField& solid = {});
  /// mark_contacts with the count written to *count (a device pointer): no host read.
  void mark_contacts_into(int32_t* trace, int trace_w, int trace_h, int ox, int oy, float contact_height,
                          const SolidField& solid, double* count);
  /// stats().max_stretch written to *out (a device pointer): no host read.
  void max_stretch_into(float* out);

  BrushStats stats();
  /// Device view of the samples; valid until the brush is destroyed (the buffers never move).
  SampleView samples();

  /// Host copies for tests, images and tools.
  std::vector<Vec3> vertices_to_host() const;              ///< canvas frame
  std::vector<Vec3> vertices_brush_frame_to_host() const;  ///< brush frame
  std::vector<Vec3> vertex_velocities_to_host() const;     ///< canvas frame, cells/s
  std::vector<Vec3> samples_to_host() const;               ///< sample positions, canvas frame
  /// Every sample field, in WB_SAMPLE_FIELDS order.
  std::vector<std::vector<Vec3>> sample_fields_to_host() const;

 private:
  /// One sub-step of length dt ending at `pose`; returns the brush frame it ended in.
  BrushFrame substep(const BrushPose& pose, float dt, const BrushEnvironment& env);
  BristleState state_view();
  BristleRest rest_view() const;
  SamplePrev prev_view();
  BrushFrame frame_for(const BrushPose& pose) const;
  void update_samples(float dt, const BrushFrame& frame, const SolidField& solid);
  void apply_min_density(int iterations);

  Device device_;
  BrushSpec spec_;
  BrushSolverParams params_;
  BristleLayout layout_;
  Workspace ws_;
  float s_min_ = 0.f;

  // Pose history for the frame's velocities (Eq. 2).
  BrushPose pose_;
  Vec3 frame_v_{};      ///< canvas frame, cells/s
  Vec3 frame_omega_B_{};
  int pose_history_ = 0;
  int sample_history_ = 0;
  int64_t rollbacks_ = 0;

  // Per vertex.
  DeviceBuffer<Vec3> xb_, vb_, x_, v_, xb_old_, vb_old_, x_old_, v_old_, delta_;
  DeviceBuffer<float> seg_length_;
  // Per bristle.
  DeviceBuffer<Vec3> root_, dir_;
  DeviceBuffer<float> bend_k_;
  // Minimum-density hash grid.
  DeviceBuffer<uint32_t> grid_keys_, grid_ids_, cell_start_, cell_end_;
  DeviceBuffer<float> lambda_;
  LaunchGraph density_graph_;  ///< the minimum-density iterations, recorded (CUDA)
  uint32_t grid_mask_ = 0;
  int grid_bits_ = 0;
  // Samples and their previous values.
#define WB_X(type, name, doc) DeviceBuffer<type> s_##name##_;
  WB_SAMPLE_FIELDS(WB_X)
#undef WB_X
  DeviceBuffer<Vec3> prev_x_, prev_t_, prev_n_, prev_v_, prev_omega_;
  // Scratch: contact keys, reductions.
  DeviceBuffer<uint32_t> contact_keys_, contact_vals_;
  DeviceBuffer<float> scratch_a_, scratch_b_;
  DeviceBuffer<float> scan_w_[2];  ///< the frames' scan (FrameScan)
  DeviceBuffer<Vec3> scan_v_[2];
  DeviceBuffer<int64_t> nonfinite_;  ///< the sub-step's non-finite positions, velocities; rollbacks
  DeviceBuffer<double> count_;       ///< mark_contacts' count
};

}  // namespace wb
