// Material maps of a painting for 3D tools (DESIGN "Files"), one pixel per canvas cell: a 16-bit
// height map in cells, a tangent-space normal map and the unlit colour. The one writer of these
// files: `wetbrush export` and the studio's File > Export both call it.
#pragma once
#include <string>

#include "core/canvas/tile_store.h"

namespace wb {

struct MaterialMapPaths {
  std::string height;  ///< 16-bit grey PNG: value = height / canvas depth * 65535 (the scale in its tEXt)
  std::string normal;  ///< RGB PNG: tangent-space normal, OpenGL convention (+Y up the image)
  std::string albedo;  ///< RGB PNG: unlit paint colour
};

/// Writes the maps whose paths are not empty, rendered from `canvas` with the default render
/// parameters (the maps describe the paint, not a view of it). Returns the height scale, units
/// per cell. Throws wb::Error naming the file on a failure.
double write_material_maps(const Device& device, TileStore& canvas, const MaterialMapPaths& paths);

}  // namespace wb
