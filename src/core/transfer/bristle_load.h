// The paint on the brush (paper §5.1): per bristle sample its liquid load m_j (kg), pigment
// c_j (RYB) and oil, and the capacity the last transfer step computed (M'_j of Eq. 12, M_j
// of Eq. 13, the load radius R_j). Loading, dipping, wiping and cleaning act on the whole
// brush; the transfer stage (transfer.h) moves paint between samples and particles.
#pragma once
#include <cstdint>
#include <vector>

#include "core/exec/buffer.h"
#include "core/exec/device.h"
#include "core/exec/workspace.h"
#include "core/transfer/paint_load.h"
#include "core/math/vec.h"
#include "core/transfer/transfer_params.h"

// X(name, description); all float, one entry per bristle sample.
#define WB_BRISTLE_LOAD_FIELDS(X)                                              \
  X(m, "liquid load m_j, kg")                                                \
  X(pigment_r, "RYB pigment c_j, red in [0, 1]")                             \
  X(pigment_y, "RYB pigment c_j, yellow in [0, 1]")                          \
  X(pigment_b, "RYB pigment c_j, blue in [0, 1]")                            \
  X(oil, "oil fraction of the load in [0, 1]")                               \
  X(potential, "potential capacity M'_j of Eq. 12, kg (last transfer step)") \
  X(capacity, "capacity M_j of Eq. 13, kg (last transfer step)")             \
  X(radius, "load radius R_j, cells (last transfer step)")                  \
  X(gap, "distance to the solid below (canvas, dried paint), cells, in [0, R_j] (last transfer step)") \
  X(sweep, "swept contact: the capacity pass's rate sigma_j (per step), then the wick's deposit, kg")

namespace wb {

/// POD view of the brush's load: device pointers plus the sample count. Passed by value.
struct BristleLoadView {
#define WB_X(name, doc) float* name;
  WB_BRISTLE_LOAD_FIELDS(WB_X)
#undef WB_X
  int64_t count;
};

/// Host copy of every field.
struct BristleLoadHost {
#define WB_X(name, doc) std::vector<float> name;
  WB_BRISTLE_LOAD_FIELDS(WB_X)
#undef WB_X
};

class BristleLoad {
 public:
  BristleLoad() = default;
  /// An empty (clean) brush of `samples` samples; capacities start at params.M_max (psi = 0,
  /// no surface near) until the first transfer step computes them.
  BristleLoad(const Device& device, int64_t samples, const TransferParams& params = {});

  const Device& device() const { return device_; }
  int64_t size() const { return count_; }
  BristleLoadView view();

  // Loading, dipping, wiping and cleaning add the net kg the brush gains (negative where it
  // loses) to a double in device memory, with no host read: the load's own, read by
  // take_change(), or the caller's (set_change_sink: the simulator's step record, read with it).

  /// A fresh brush loaded with `paint`: m_j = paint.load * M'_j (the potential capacity of
  /// Eq. 12 from the last transfer step, M_max before it), colour paint.ryb, oil paint.oil.
  /// The change is what entered minus what it replaced.
  void fill(const PaintLoad& paint);
  /// Dips the brush into a well of `paint` (dirty brush): the well's paint replaces the share
  /// x_j (set_dip_exchange) of each sample's paint, then tops the sample up to paint.load * M'_j;
  /// the old and the new paint mix (Algorithm 2 by mass, oil by mass). The replaced paint stays
  /// in the well.
  void dip(const PaintLoad& paint);
  /// The share x_j in [0, 1] of each sample's paint a dip replaces (dip_exposure times
  /// TransferParams::dip_exchange); size() values. Until set, a dip only tops up.
  void set_dip_exchange(const std::vector<float>& x);
  /// Wipes the brush on a rag: removes `fraction` (in [0, 1]) of every sample's load.
  void wipe(float fraction);
  /// Cleans the brush in solvent: no load, no pigment, no oil.
  void clean();
  /// Where the changes go: a double on this device that the caller reads (and zeroes) with its
  /// own record; nullptr: the load's own.
  void set_change_sink(double* device_kg) { sink_ = device_kg; }
  /// Reads and zeroes the load's own sum of changes since the last take, kg (a host read).
  double take_change();

  /// Sum of the loads, kg (double).
  double total_mass(Workspace& ws) const;
  /// Mass-weighted pigment of the whole brush (Algorithm 2 over all samples), for the UI;
  /// zero (white) when the brush is clean.
  Vec3 mean_color(Workspace& ws);
  /// Mass-weighted oil fraction of the load (0 when clean).
  float mean_oil(Workspace& ws);
  /// The whole load as one well of paint: mean_color, mean_oil and the fill of the brush's
  /// capacity (sum of M_j over sum of M'_j, Eq. 12). A clean brush keeps `clean`'s pigment and oil
  /// with no load.
  PaintLoad mean_paint(Workspace& ws, const PaintLoad& clean);

  BristleLoadHost to_host() const;
  /// Replaces every field (each size() long); throws wb::Error on a size mismatch or a
  /// negative / non-finite load.
  void from_host(const BristleLoadHost& h);

#define WB_X(name, doc) DeviceBuffer<float> name;
  WB_BRISTLE_LOAD_FIELDS(WB_X)
#undef WB_X

 private:
  /// mean_color and mean_oil of a load of w kg (total_mass).
  Vec3 mean_color(double w, Workspace& ws);
  float mean_oil(double w, Workspace& ws);
  /// fill (replace) and dip (top up and mix) in one pass.
  void load(const PaintLoad& paint, bool replace, const char* what);
  double* sink() { return sink_ ? sink_ : change_.data(); }
  Device device_;
  int64_t count_ = 0;
  DeviceBuffer<float> scratch_;
  DeviceBuffer<float> exchange_;  ///< x_j of dip(); empty: a dip only tops up
  Workspace ws_;  ///< reduction scratch of fill / dip / wipe / clean, kept between calls
  DeviceBuffer<double> change_;  ///< the load's own sum of changes (take_change)
  double* sink_ = nullptr;       ///< the caller's, where set
};

}  // namespace wb
