// The active window (paper §4.2 last paragraph, DESIGN step 3): a dense block of the
// sparse canvas (default 128 x 128 x 32 cells) that follows the brush. It owns the paint
// fields (PaintWindow) and the MAC velocity; moving it scatters the paint back to the
// canvas, gathers it at the new origin and shifts the velocity of the overlap (velocity is
// not stored in the canvas: it is zero where newly gathered). Mass books: see total_mass().
#pragma once
#include "core/canvas/tile_store.h"
#include "core/canvas/window.h"
#include "core/exec/buffer.h"
#include "core/grid/grid_fields.h"
#include "core/math/vec.h"

namespace wb {

class ActiveWindow {
 public:
  /// Gathers `dims` cells at `origin` (canvas cells) from `canvas`, velocity zero.
  ActiveWindow(TileStore& canvas, Int3 dims = {128, 128, 32}, Int3 origin = {0, 0, 0});

  const Device& device() const { return canvas_->device(); }
  TileStore& canvas() { return *canvas_; }
  Int3 dims() const { return paint_.dims(); }
  Int3 origin() const { return paint_.origin(); }
  GridDims grid_dims() const { return GridDims{paint_.dims().x, paint_.dims().y, paint_.dims().z}; }
  PaintWindow& paint() { return paint_; }
  /// MAC velocity component c (0 = u: (nx+1) ny nz, 1 = v, 2 = w), cells/s.
  DeviceBuffer<float>& velocity(int c) { return vel_[c]; }

  /// Scatters the window to the canvas, shifts the velocity (and every buffer registered with
  /// carry_faces/carry_cells) by the move, and gathers at `new_origin`. No-op if unchanged.
  void move_to(Int3 new_origin);
  /// Origin that centres the window on `brush` (canvas cells, x and y), snapped to multiples of
  /// `snap` cells; z stays as it is.
  Int3 origin_for(Vec3 brush, int snap) const;
  /// move_to(origin_for(brush, snap)); returns whether the window moved.
  bool recentre_on(Vec3 brush, int snap);
  /// Writes the window to the canvas without moving (the canvas is then up to date).
  void flush();
  /// Puts back the window a flush (or a settle) started from: its paint, as `host` holds it
  /// (PaintWindow::to_host), and the mass it had gathered, so the books read as before.
  void restore(const std::vector<std::vector<float>>& host, double gathered_mass);
  /// Re-reads the window from the canvas (after the canvas changed, e.g. dry_all); velocity kept.
  void reload();

  /// Sum of density in the window now.
  double window_mass(Workspace& ws) const { return paint_.total_density(ws); }
  /// Density the canvas holds in the window's region (as last gathered or flushed). Summed on
  /// the device at a gather; read once, here or with a caller's results (gathered_sum).
  double gathered_mass() const;
  /// That sum on the device (one double), for a caller that reads it with its own results and
  /// then gives the value read to set_gathered_mass.
  const double* gathered_sum() const { return gathered_dev_.data(); }
  void set_gathered_mass(double m) const {
    gathered_mass_ = m;
    gathered_pending_ = false;
  }
  /// All paint: canvas + window - the canvas copy of the window region. Unchanged by moves.
  double total_mass(Workspace& ws) const;
  /// total_mass with the window's density sum already known (read with other sums).
  double total_mass_with(double window_density) const;

 private:
  void shift_faces(int c, int dx, int dy, int dz);

  TileStore* canvas_;
  PaintWindow paint_;
  DeviceBuffer<float> vel_[3];
  DeviceBuffer<float> shift_tmp_;
  Workspace ws_;
  DeviceBuffer<double> gathered_dev_;  ///< the window region's density sum at the last gather
  mutable double gathered_mass_ = 0;   ///< its value as last read
  mutable bool gathered_pending_ = false;
  void sum_gathered();  ///< into gathered_dev_, no host wait
};

}  // namespace wb
