// The paint budget across bristles, particles and grid (paper §5; DESIGN "paint budget").
#include "core/transfer/paint_books.h"

#include <algorithm>
#include <cmath>

#include "core/exec/error.h"

namespace wb {

void PaintBooks::open(const PaintCensus& start) {
  WB_REQUIRE(std::isfinite(start.total()) && start.total() >= 0.0, "PaintBooks::open: the census is not finite");
  initial_ = start.total();
  external_total_ = pending_external_ = 0;
  last_drift_ = max_drift_ = 0;
  totals_ = TransferTotals{};
  steps_.clear();
}

void PaintBooks::external(double kg) {
  WB_REQUIRE(std::isfinite(kg), "PaintBooks::external: the amount is not finite");
  external_total_ += kg;
  pending_external_ += kg;
}

double PaintBooks::record(const TransferRecord& rec, const PaintCensus& after) {
  PaintStep s;
  s.transfer = rec;
  s.census = after;
  s.external = pending_external_;
  pending_external_ = 0;
  const double expected = expected_total();
  // Relative to the paint in the books; an empty system is measured in absolute kg.
  s.drift = expected > 0 ? (after.total() - expected) / expected : after.total() - expected;
  last_drift_ = s.drift;
  max_drift_ = std::max(max_drift_, std::fabs(s.drift));
  totals_.absorbed += rec.absorbed_from_particles;
  totals_.emitted += rec.emitted_from_bristles;
  totals_.to_particles += rec.to_particles_from_grid;
  totals_.to_grid += rec.to_grid_from_particles;
  totals_.absorbed_count += rec.absorbed_count;
  totals_.emitted_count += rec.emitted_count;
  totals_.to_particles_count += rec.to_particles_count;
  totals_.to_grid_count += rec.to_grid_count;
  totals_.max_closure_error = std::max(totals_.max_closure_error, rec.max_closure_error());
  steps_.push_back(s);
  while (steps_.size() > history_) steps_.pop_front();
  return s.drift;
}

PaintCensus PaintBooks::census(BristleLoad& load, ParticleStore& particles, double grid_density_cells,
                               const TransferParams& params, Workspace& ws) {
  PaintCensus c;
  c.bristles = load.total_mass(ws);
  c.particles = particles.total_mass(ws);
  c.grid = grid_density_cells * double(params.cell_mass());
  return c;
}

}  // namespace wb
