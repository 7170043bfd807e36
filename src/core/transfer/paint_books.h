// The paint budget (paper §5, DESIGN "Every step keeps a paint budget"): total paint =
// bristle loads + particle masses + grid density x rho0 cell^3, in kg. PaintBooks keeps the
// initial total, what entered or left from outside (loading, wiping, cleaning), every step's
// transfers (TransferRecord, both sides of each) and the drift of the census from the books.
#pragma once
#include <cstdint>
#include <deque>

#include "core/exec/workspace.h"
#include "core/particles/particle_store.h"
#include "core/transfer/bristle_load.h"
#include "core/transfer/transfer.h"
#include "core/transfer/transfer_params.h"

namespace wb {

/// Where the paint is, kg.
struct PaintCensus {
  double bristles = 0;
  double particles = 0;
  double grid = 0;  ///< canvas + window (ActiveWindow::total_mass) x cell mass
  double total() const { return bristles + particles + grid; }
};

/// One step in the books.
struct PaintStep {
  TransferRecord transfer;
  PaintCensus census;   ///< after the step
  double external = 0;  ///< kg that entered (+) or left (-) from outside since the previous step
  double drift = 0;     ///< (census total - expected total) / expected total after the step
};

/// Running sums of what the transfers moved, kg (source side).
struct TransferTotals {
  double absorbed = 0;
  double emitted = 0;
  double to_particles = 0;
  double to_grid = 0;
  int64_t absorbed_count = 0, emitted_count = 0, to_particles_count = 0, to_grid_count = 0;
  double max_closure_error = 0;  ///< largest per-transfer mismatch of any step
};

class PaintBooks {
 public:
  /// Steps kept in steps() (older ones are dropped; the totals keep everything).
  explicit PaintBooks(size_t history = 100000) : history_(history) {}

  /// Opens the books on a census: its total is the initial total; clears the history.
  void open(const PaintCensus& start);
  /// Paint entering (+) or leaving (-) from outside the transfers (fill, dip, wipe, clean), kg;
  /// counted in the next record (the simulator enters the brush's with the step record that
  /// brings it back from the device).
  void external(double kg);
  /// Records one step's transfers and the census after the step; returns its drift.
  double record(const TransferRecord& rec, const PaintCensus& after);

  /// Initial total plus every external change, kg.
  double expected_total() const { return initial_ + external_total_; }
  double initial_total() const { return initial_; }
  double external_total() const { return external_total_; }
  /// Drift of the last recorded step (0 before any).
  double drift() const { return last_drift_; }
  /// Largest |drift| of any recorded step.
  double max_drift() const { return max_drift_; }
  const TransferTotals& totals() const { return totals_; }
  const std::deque<PaintStep>& steps() const { return steps_; }

  /// A census of the three reservoirs: the bristle loads, the particle masses and a grid density
  /// sum (cells, e.g. ActiveWindow::total_mass) converted with params.cell_mass().
  static PaintCensus census(BristleLoad& load, ParticleStore& particles, double grid_density_cells,
                            const TransferParams& params, Workspace& ws);

 private:
  size_t history_;
  double initial_ = 0;
  double external_total_ = 0;
  double pending_external_ = 0;
  double last_drift_ = 0;
  double max_drift_ = 0;
  TransferTotals totals_;
  std::deque<PaintStep> steps_;
};

}  // namespace wb
