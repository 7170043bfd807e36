// Relief exports of a painting (docs/FORMATS.md "Relief exports"): the surface height as a float
// OpenEXR in millimetres, a watertight STL solid for printing and a textured glTF 2.0 binary for
// 3D tools. The CLI's `wetbrush export` and the studio's File menu both call these; every file is
// written atomically (atomic_file.h).
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "core/canvas/tile_store.h"
#include "core/session/session.h"
#include "core/grid/grid_params.h"
#include "core/render/renderer.h"

namespace wb {

/// Size of one canvas cell, millimetres: the grid's cell (GridParams::cell_size, metres).
inline constexpr double kCellMm = double(GridParams{}.cell_size) * 1e3;

/// The paint surface as a triangle mesh over the canvas, decimated where flat. Vertices stand at
/// the cell centres and on the canvas border (the outer cells' heights carried to the edge), so
/// the mesh covers the whole canvas and passes through every height it keeps.
struct ReliefMesh {
  /// Per vertex: canvas x and y (cells, y down the image) and the height (cells).
  std::vector<float> x, y, h;
  /// Vertex indices, three per triangle, counter-clockwise seen from above the paint.
  std::vector<uint32_t> triangles;
  /// Vertex indices of the mesh's border, once round the canvas (counter-clockwise from above).
  std::vector<uint32_t> border;
  int grid_vertices = 0;  ///< vertices of the undecimated mesh, for comparison
  size_t vertex_count() const { return x.size(); }
  size_t triangle_count() const { return triangles.size() / 3; }
};

/// Triangulates a height map (cells, one pixel per cell) with a quadtree: a square of the
/// vertex grid (clipped to the grid at its far edges) becomes one patch when all its heights lie
/// within error_cells / 2 of a plane (or within error_cells of each other), so every height
/// differs from the mesh by at most `error_cells`. Patches of different sizes meet without cracks
/// (a patch takes in the vertices its smaller neighbours put on their shared edge and is fanned
/// from an inner vertex). error_cells = 0 merges exactly flat or planar regions only.
ReliefMesh decimate_height_map(const FloatImage& height_cells, double error_cells);

/// Writes the height (cells) as a single-channel 32-bit float OpenEXR in millimetres, channel
/// "Y", rows top to bottom as the PNG maps.
void write_height_exr(const std::string& path, const FloatImage& height_cells);

struct StlStats {
  size_t triangles = 0;
  double volume_mm3 = 0.0;  ///< the solid's volume (divergence theorem over its triangles)
};
/// Writes a closed binary STL solid in millimetres: the paint surface (decimated within
/// `error_mm`) standing `base_mm` above the base's flat bottom at z = 0, x along the canvas, y up
/// the image (canvas y reversed), z up. base_mm must be > 0.
StlStats write_relief_stl(const std::string& path, const FloatImage& height_cells, double base_mm, double error_mm);

struct GltfStats {
  size_t vertices = 0, triangles = 0;
  int grid_vertices = 0;
};
/// Writes a glTF 2.0 binary (.glb): the paint surface decimated within `error_mm`, positions in
/// metres (x along the canvas, y up out of the canvas, z down the image), per-vertex normals,
/// UVs and `albedo` (RGB floats in [0, 1], one pixel per cell) embedded as a PNG base colour.
GltfStats write_relief_glb(const std::string& path, const FloatImage& height_cells, const FloatImage& albedo,
                           double error_mm);

/// What to export; empty paths are skipped.
struct ReliefPaths {
  std::string exr, stl, glb;
};
struct ReliefOptions {
  double base_mm = 1.0;     ///< STL base thickness under the paint, mm
  double error_mm = 0.02;   ///< most the decimated STL and glTF surfaces may differ from the height map, mm
};
struct ReliefStats {
  StlStats stl;
  GltfStats glb;
};
/// Renders the painting's height map (and albedo for glTF) and writes the requested files.
/// Throws wb::Error naming the file on a failure.
ReliefStats write_relief_exports(const Device& device, TileStore& canvas, const ReliefPaths& paths,
                                 const ReliefOptions& options = {});
/// The same for a session's painting at rest (`wetbrush export`, the studio's File > Export).
ReliefStats write_relief_exports(Session& session, const ReliefPaths& paths, const ReliefOptions& options = {});

}  // namespace wb
