// The renderer (paper §6 "Liquid rendering", DESIGN step 9): ray casts the sparse canvas, the
// live window and the particles near the brush into an image, on either backend. Also the
// incremental per-tile image cache and the material exports (height, normal, albedo maps).
#pragma once
#include <cstdint>
#include <optional>
#include <vector>

#include "core/canvas/tile_store.h"
#include "core/canvas/window.h"
#include "core/exec/buffer.h"
#include "core/exec/dispatch.h"
#include "core/math/vec.h"
#include "core/render/camera.h"
#include "core/render/raycast_kernels.h"
#include "core/render/render_params.h"

namespace wb {

/// An 8-bit RGBA image, rows top to bottom, 4 bytes per pixel.
struct Image {
  int width = 0, height = 0;
  std::vector<uint8_t> rgba;
  Image() = default;
  Image(int w, int h) : width(w), height(h), rgba(size_t(w) * h * 4, 0) {}
  uint8_t* at(int x, int y) { return &rgba[(size_t(y) * width + x) * 4]; }
  const uint8_t* at(int x, int y) const { return &rgba[(size_t(y) * width + x) * 4]; }
};

/// A float image with 1 to 4 channels, rows top to bottom.
struct FloatImage {
  int width = 0, height = 0, channels = 1;
  std::vector<float> data;
  float& at(int x, int y, int c = 0) { return data[(size_t(y) * width + x) * channels + c]; }
  float at(int x, int y, int c = 0) const { return data[(size_t(y) * width + x) * channels + c]; }
};

/// Liquid particles near the brush, drawn as a surface: device pointers (SoA), nullable.
/// Positions are canvas cells; `mass` is paint volume in cell volumes (the unit of density).
struct ParticleOverlay {
  const Vec3* x = nullptr;
  const float* mass = nullptr;
  const float *r = nullptr, *y = nullptr, *b = nullptr;  ///< RYB pigment
  const float* oil = nullptr;
  int64_t n = 0;
  float radius = 1.5f;  ///< splat kernel radius, cells
  /// Box of the temporary density layer; used only when no live window is given
  /// (with a live window the layer is the window's box).
  Int3 origin{}, dims{};
};

enum class RenderOutput : int { Shaded = 0, Height = 1, Normal = 2, Albedo = 3, Pigment = 4 };

class Renderer {
 public:
  explicit Renderer(const Device& device);

  const Device& device() const { return device_; }
  RenderParams& params() { return params_; }
  const RenderParams& params() const { return params_; }

  /// Shaded RGBA8 image of the canvas seen by `camera`. `live` (the current dense window)
  /// replaces the tiles' cells inside its box; `particles` are splatted on top.
  Image render(TileStore& canvas, const Camera& camera, PaintWindow* live = nullptr,
               const ParticleOverlay* particles = nullptr);

  /// Height of the paint surface per cell (top view, one pixel per cell), in cells; 0 = bare canvas.
  FloatImage render_height_map(TileStore& canvas, PaintWindow* live = nullptr);
  /// Tangent-space (canvas-space, z up) unit normals per cell, 3 channels.
  FloatImage render_normal_map(TileStore& canvas, PaintWindow* live = nullptr);
  /// Unlit colour per cell (pigment blended below the surface, no light, no AO), 3 channels.
  FloatImage render_albedo(TileStore& canvas, PaintWindow* live = nullptr);
  /// The pigment (RYB) behind the top view's colour at cell (x, y): what render_albedo shows
  /// there, before the conversion to RGB (a glaze's includes the paper it lets through). Empty
  /// where the ray meets bare canvas or misses it. Renders one image tile.
  std::optional<Vec3> pigment_at(TileStore& canvas, int x, int y, PaintWindow* live = nullptr);

  /// Renders the pixels of the listed image tiles (tile id = ty * tiles_x + tx, tiles of
  /// `tile_px` pixels) into their places in `image` (the camera's size). Used by the cache.
  void render_tiles(TileStore& canvas, const Camera& camera, const std::vector<int32_t>& tiles, int tile_px,
                    Image& image, PaintWindow* live = nullptr, const ParticleOverlay* particles = nullptr);

  /// Pixels shaded by the last call (for tests and statistics).
  int64_t last_pixels() const { return last_pixels_; }

 private:
  void prepare(TileStore& canvas, const Camera& camera, const std::vector<int32_t>& tiles, int tile_px,
               PaintWindow* live, const ParticleOverlay* particles);
  void run(RenderOutput mode, const Camera& camera, int tile_px, int ntiles);
  FloatImage render_float(TileStore& canvas, PaintWindow* live, RenderOutput mode, int channels);

  Device device_;
  RenderParams params_;
  RenderVolume vol_{};
  RenderParams kparams_{};
  DeviceBuffer<uint16_t> top_, block_top_;
  DeviceBuffer<FilmColumn> film_;
  DeviceBuffer<uint8_t> block_film_;
  DeviceBuffer<float> splat_d_, splat_r_, splat_y_, splat_b_, splat_oil_;
  DeviceBuffer<Vec3> ao_dirs_;
  DeviceBuffer<int32_t> tile_list_;
  DeviceBuffer<uint32_t> rgba_;
  DeviceBuffer<float> fout_;
  std::vector<uint16_t> host_blocks_;
  std::vector<uint32_t> host_rgba_;  ///< the rendered tiles, tile-major, as read back
  int img_w_ = 0, img_h_ = 0;
  int64_t last_pixels_ = 0;
};

/// Incremental rendering: keeps the image of one camera and re-renders only the image tiles
/// whose paint changed. The caller marks what changed: the window region each step, and
/// wherever drying changed the look. A fresh cache (or a new camera) renders everything once.
class CanvasImageCache {
 public:
  CanvasImageCache(Renderer& renderer, const Camera& camera, int tile_px = 32);

  const Camera& camera() const { return camera_; }
  void set_camera(const Camera& camera);
  /// Marks the canvas rectangle [x0, x1) x [y0, y1) (cells) changed; the affected image tiles
  /// grow by the reach of normals, AO and (oblique) parallax.
  void mark_dirty(int x0, int y0, int x1, int y1);
  void mark_window_dirty(const PaintWindow& window);
  void mark_all_dirty();
  int dirty_tiles() const;

  /// Re-renders the dirty tiles and returns the image.
  const Image& update(TileStore& canvas, PaintWindow* live = nullptr, const ParticleOverlay* particles = nullptr);
  const Image& image() const { return image_; }
  /// Image tiles re-rendered by the last update.
  int last_rendered_tiles() const { return last_tiles_; }

 private:
  Renderer& renderer_;
  Camera camera_;
  int tile_px_;
  int tiles_x_ = 0, tiles_y_ = 0;
  std::vector<uint8_t> dirty_;
  std::vector<int32_t> dirty_list_;  ///< the dirty tiles' ids of an update (kept: no allocation a frame)
  Image image_;
  int last_tiles_ = 0;
};

// The renderer's backend drivers (render_impl.h), one list (core/exec/dispatch.h).
#define WB_RENDER_KERNELS(X)                                                                                       \
  X(void, render_top_map, (RenderVolume v, RenderParams P, int x0, int y0, int w, int h, uint16_t* top,            \
      FilmColumn* film), (v, P, x0, y0, w, h, top, film))                                                          \
  X(void, render_block_top, (const uint16_t* top, const FilmColumn* film, int w, int h, uint16_t* blocks,          \
      uint8_t* block_film, int bw, int bh), (top, film, w, h, blocks, block_film, bw, bh))                         \
  X(void, render_splat, (SplatView s, ParticleOverlay p), (s, p))                                                  \
  X(void, render_pixels, (RenderVolume v, RenderParams P, CameraBasis cam, const Vec3* ao_dirs,                    \
      const int32_t* tiles, int ntiles, int tile_px, int img_w, int img_h, int mode, uint32_t* rgba, float* fout), \
      (v, P, cam, ao_dirs, tiles, ntiles, tile_px, img_w, img_h, mode, rgba, fout))
WB_DECLARE_KERNELS(WB_RENDER_KERNELS)

}  // namespace wb
