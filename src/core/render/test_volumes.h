// Analytic paint volumes for the renderer's tests, its documentation images and its timings
// (paper §6). Each fills a TileStore through whole tiles, so any canvas size works.
#pragma once
#include <functional>
#include <string>
#include <vector>

#include "core/canvas/tile_store.h"

namespace wb {

/// Writes fn(x, y, z) into every cell of the tiles covering [x0, x1) x [y0, y1); cells whose
/// density is 0 are left empty. Tiles that end up empty are not allocated.
void fill_volume(TileStore& canvas, int x0, int y0, int x1, int y1,
                 const std::function<PaintCell(int x, int y, int z)>& fn);

/// Density of a smooth surface: 0.5 + signed distance / width (cells, positive inside), clamped to
/// [0, 1], so the 0.5 level set is the analytic surface and the gradient is its normal.
float sdf_density(float signed_distance, float width = 1.f);

/// Names of the built-in test volumes.
std::vector<std::string> test_volume_names();
/// Canvas size a test volume is made for.
CanvasDims test_volume_dims(const std::string& name);
/// Fills `canvas` (of test_volume_dims(name)) with the named volume; throws on unknown names.
/// flat: 4-cell red layer; hemisphere: radius 24 dome; ridges: two parallel ridges with a
/// crease; glaze: thin oily and thick opaque blue over red; swatches: colour and oil swatches;
/// films: thin films 0.01 to 2 cells thick and paint rising from none to thick;
/// impasto-1024: a 1024^2 canvas covered with thick strokes (the timing volume).
void make_test_volume(TileStore& canvas, const std::string& name);

}  // namespace wb
