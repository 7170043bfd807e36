// Renderer dispatcher (paper §6): validates, prepares the empty-space maps and the particle
// layer, runs the per-pixel ray cast on the renderer's device, and keeps the incremental cache.
#include "core/render/renderer.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "core/color/ryb.h"
#include "core/exec/profile.h"
#include "core/render/ao_kernels.h"

namespace wb {

WB_DEFINE_DISPATCHERS(WB_RENDER_KERNELS)

namespace {

std::vector<int32_t> all_tiles(int w, int h, int tile_px) {
  const int n = ((w + tile_px - 1) / tile_px) * ((h + tile_px - 1) / tile_px);
  std::vector<int32_t> t(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) t[size_t(i)] = i;
  return t;
}

void check_params(const RenderParams& p) {
  WB_REQUIRE(p.step > 0.f && p.step <= 1.f, "render: step must be in (0, 1] cells");
  WB_REQUIRE(p.threshold > 0.f, "render: surface threshold must be positive");
  WB_REQUIRE(p.penetration_step > 0.f, "render: penetration step must be positive");
  WB_REQUIRE(p.ao_rays >= 0 && p.ao_rays <= 1024, "render: AO rays must be in [0, 1024]");
  WB_REQUIRE(p.ao_step > 0.f && p.ao_length >= 0.f, "render: AO step must be positive, length non-negative");
  WB_REQUIRE(length(p.light_dir) > 0.f && isfinite3(p.light_dir), "render: light direction must be non-zero");
  WB_REQUIRE(p.film_hiding > 0.f, "render: film hiding thickness must be positive");
  WB_REQUIRE(p.film_fade > 0.f, "render: film fade must be positive");
}
}  // namespace

Renderer::Renderer(const Device& device) : device_(device) {
  for (auto* b : {&top_, &block_top_}) b->set_device(device);
  film_.set_device(device);
  block_film_.set_device(device);
  for (auto* b : {&splat_d_, &splat_r_, &splat_y_, &splat_b_, &splat_oil_, &fout_}) b->set_device(device);
  ao_dirs_.set_device(device);
  tile_list_.set_device(device);
  rgba_.set_device(device);
}

void Renderer::prepare(TileStore& canvas, const Camera& camera, const std::vector<int32_t>& tiles, int tile_px,
                       PaintWindow* live, const ParticleOverlay* particles) {
  check_params(params_);
  WB_REQUIRE(camera.width > 0 && camera.height > 0 && camera.width <= 32768 && camera.height <= 32768,
             "render: image size must be in [1, 32768] pixels");
  WB_REQUIRE(camera.zoom > 0.f && std::isfinite(camera.zoom), "render: zoom must be positive");
  WB_REQUIRE(camera.kind == CameraKind::Top || (camera.elevation_deg >= 5.f && camera.elevation_deg <= 90.f),
             "render: oblique elevation must be in [5, 90] degrees");
  WB_REQUIRE(canvas.device() == device_, "render: canvas lives on another device than the renderer");
  WB_REQUIRE(!live || live->device() == device_, "render: live window lives on another device than the renderer");
  img_w_ = camera.width;
  img_h_ = camera.height;

  kparams_ = params_;
  kparams_.light_dir = normalize(params_.light_dir);
  kparams_.paper_ryb = rgb_to_ryb(params_.paper_rgb);

  vol_ = RenderVolume{};
  vol_.tiles = canvas.view();
  vol_.has_win = live ? 1 : 0;
  if (live) vol_.win = live->view();

  // Particles: splat into the temporary density layer (the window's box, or the overlay's).
  vol_.has_splat = 0;
  if (particles && particles->n > 0) {
    WB_REQUIRE(particles->x && particles->mass, "render: particle overlay needs positions and masses");
    const Int3 o = live ? live->origin() : particles->origin;
    const Int3 n = live ? live->dims() : particles->dims;
    WB_REQUIRE(n.x > 0 && n.y > 0 && n.z > 0 && int64_t(n.x) * n.y * n.z <= (int64_t(1) << 28),
               "render: particle overlay box must be given (or a live window) and not huge");
    const size_t cells = size_t(n.x) * n.y * n.z;
    for (auto* b : {&splat_d_, &splat_r_, &splat_y_, &splat_b_, &splat_oil_}) {
      b->resize(cells);
      b->fill_zero();
    }
    SplatView s{splat_d_.data(), splat_r_.data(), splat_y_.data(), splat_b_.data(), splat_oil_.data(),
                n.x, n.y, n.z, o.x, o.y, o.z};
    render_splat(device_, s, *particles);
    vol_.splat = s;
    vol_.has_splat = 1;
  }

  // Footprint of the listed image tiles on the canvas: every column a ray, its normal stencil
  // or its AO rays can touch. Columns outside it read as full depth (no skipping) and hold no
  // film, so the maps only have to be right where they exist.
  const CanvasDims dims = canvas.dims();
  const CameraBasis cam = camera_basis(camera);
  const int tiles_x = (img_w_ + tile_px - 1) / tile_px;
  float fx0 = 1e30f, fy0 = 1e30f, fx1 = -1e30f, fy1 = -1e30f;
  for (int32_t t : tiles) {
    const float px0 = float((t % tiles_x) * tile_px), py0 = float((t / tiles_x) * tile_px);
    for (int c = 0; c < 4; ++c) {
      const float i = px0 + ((c & 1) ? tile_px : 0), j = py0 + ((c & 2) ? tile_px : 0);
      const Vec3 g = cam.p00 + cam.du * i + cam.dv * j;
      for (float z : {0.f, float(dims.depth)}) {
        const Vec3 q = g - cam.dir * ((z - g.z) / -cam.dir.z);
        fx0 = std::min(fx0, q.x);
        fx1 = std::max(fx1, q.x);
        fy0 = std::min(fy0, q.y);
        fy1 = std::max(fy1, q.y);
      }
    }
  }
  const float margin = params_.ao_offset + params_.ao_length + params_.normal_eps + 3.f;
  const int x0 = std::max(0, int(std::floor(fx0 - margin))), y0 = std::max(0, int(std::floor(fy0 - margin)));
  const int x1 = std::min(dims.width, int(std::ceil(fx1 + margin))), y1 = std::min(dims.height, int(std::ceil(fy1 + margin)));
  const int w = std::max(0, x1 - x0), h = std::max(0, y1 - y0);
  vol_.top_x0 = x0;
  vol_.top_y0 = y0;
  vol_.top_w = w;
  vol_.top_h = h;
  const int bw = (w + kTopBlock - 1) / kTopBlock, bh = (h + kTopBlock - 1) / kTopBlock;
  vol_.blk_w = bw;
  vol_.blk_h = bh;
  vol_.z_top_max = 0;
  if (w > 0 && h > 0) {
    WB_PROFILE_SCOPE("render.top_map");
    top_.resize(size_t(w) * h);
    film_.resize(size_t(w) * h);
    block_top_.resize(size_t(bw) * bh);
    block_film_.resize(size_t(bw) * bh);
    render_top_map(device_, vol_, kparams_, x0, y0, w, h, top_.data(), film_.data());
    render_block_top(device_, top_.data(), film_.data(), w, h, block_top_.data(), block_film_.data(), bw, bh);
    host_blocks_.resize(size_t(bw) * bh);
    block_top_.copy_to_host(host_blocks_.data(), host_blocks_.size());
    for (uint16_t b : host_blocks_) vol_.z_top_max = std::max<int>(vol_.z_top_max, b);
  }
  vol_.top = top_.data();
  vol_.block_top = block_top_.data();
  vol_.film = film_.data();
  vol_.block_film = block_film_.data();
  if (vol_.has_splat) {
    // Splatted paint may stick out of the map (off-canvas): let oblique rays start above it.
    vol_.z_top_max = std::max(vol_.z_top_max, std::min(dims.depth, vol_.splat.oz + vol_.splat.nz));
  }

  if (int(ao_dirs_.size()) != params_.ao_rays) {
    std::vector<Vec3> d(size_t(params_.ao_rays));
    for (int k = 0; k < params_.ao_rays; ++k) d[size_t(k)] = ao_direction(k, params_.ao_rays);
    ao_dirs_.copy_from_host(d);
  }
  tile_list_.copy_from_host(tiles);
}

void Renderer::run(RenderOutput mode, const Camera& camera, int tile_px, int ntiles) {
  WB_PROFILE_SCOPE("render.raycast");
  const size_t n = size_t(ntiles) * tile_px * tile_px;
  if (mode == RenderOutput::Shaded) {
    rgba_.resize(n);
    fout_.resize(4);
  } else {
    fout_.resize(n * 4);
    rgba_.resize(1);
  }
  render_pixels(device_, vol_, kparams_, camera_basis(camera), ao_dirs_.data(), tile_list_.data(), ntiles, tile_px,
                img_w_, img_h_, int(mode), rgba_.data(), fout_.data());
  last_pixels_ = int64_t(n);
}

void Renderer::render_tiles(TileStore& canvas, const Camera& camera, const std::vector<int32_t>& tiles, int tile_px,
                            Image& image, PaintWindow* live, const ParticleOverlay* particles) {
  WB_REQUIRE(tile_px > 0 && tile_px <= 1024, "render: tile size must be in [1, 1024] pixels");
  WB_REQUIRE(image.width == camera.width && image.height == camera.height, "render: the image is not the camera's size");
  last_pixels_ = 0;
  if (tiles.empty()) return;
  prepare(canvas, camera, tiles, tile_px, live, particles);
  run(RenderOutput::Shaded, camera, tile_px, int(tiles.size()));
  // The kernel writes tile-major (packed little-endian RGBA8): read the tiles back and place
  // their rows in the image.
  std::vector<uint32_t>& compact = host_rgba_;
  compact.resize(size_t(tiles.size()) * tile_px * tile_px);
  rgba_.copy_to_host(compact.data(), compact.size());
  const int tiles_x = (img_w_ + tile_px - 1) / tile_px;
  const size_t per_tile = size_t(tile_px) * tile_px;
  for (size_t k = 0; k < tiles.size(); ++k) {
    const int tx = tiles[k] % tiles_x, ty = tiles[k] / tiles_x;
    for (int ly = 0; ly < tile_px; ++ly) {
      const int y = ty * tile_px + ly;
      if (y >= img_h_) break;
      const int x = tx * tile_px;
      const int cnt = std::min(tile_px, img_w_ - x);
      std::memcpy(image.at(x, y), &compact[k * per_tile + size_t(ly) * tile_px], size_t(cnt) * 4);
    }
  }
}

Image Renderer::render(TileStore& canvas, const Camera& camera, PaintWindow* live, const ParticleOverlay* particles) {
  WB_PROFILE_SCOPE("render.full");
  constexpr int kTile = 32;
  Image img(camera.width, camera.height);
  render_tiles(canvas, camera, all_tiles(camera.width, camera.height, kTile), kTile, img, live, particles);
  return img;
}

FloatImage Renderer::render_float(TileStore& canvas, PaintWindow* live, RenderOutput mode, int channels) {
  constexpr int kTile = 32;
  const Camera camera = Camera::top(canvas.dims());
  const auto tiles = all_tiles(camera.width, camera.height, kTile);
  prepare(canvas, camera, tiles, kTile, live, nullptr);
  run(mode, camera, kTile, int(tiles.size()));
  std::vector<float> compact(fout_.size());
  fout_.copy_to_host(compact.data(), compact.size());
  FloatImage out;
  out.width = camera.width;
  out.height = camera.height;
  out.channels = channels;
  out.data.assign(size_t(out.width) * out.height * channels, 0.f);
  const int tiles_x = (out.width + kTile - 1) / kTile;
  for (size_t k = 0; k < tiles.size(); ++k) {
    const int tx = tiles[k] % tiles_x, ty = tiles[k] / tiles_x;
    for (int l = 0; l < kTile * kTile; ++l) {
      const int x = tx * kTile + l % kTile, y = ty * kTile + l / kTile;
      if (x >= out.width || y >= out.height) continue;
      for (int c = 0; c < channels; ++c) out.at(x, y, c) = compact[(k * kTile * kTile + size_t(l)) * 4 + size_t(c)];
    }
  }
  return out;
}

std::optional<Vec3> Renderer::pigment_at(TileStore& canvas, int x, int y, PaintWindow* live) {
  constexpr int kTile = 32;
  const Camera camera = Camera::top(canvas.dims());
  if (x < 0 || y < 0 || x >= camera.width || y >= camera.height) return std::nullopt;
  const int tiles_x = (camera.width + kTile - 1) / kTile;
  prepare(canvas, camera, {int32_t((y / kTile) * tiles_x + x / kTile)}, kTile, live, nullptr);
  run(RenderOutput::Pigment, camera, kTile, 1);
  float px[4];
  fout_.copy_range_to_host(px, size_t((y % kTile) * kTile + x % kTile) * 4, 4);
  if (px[3] != 2.f) return std::nullopt;
  return Vec3(px[0], px[1], px[2]);
}

FloatImage Renderer::render_height_map(TileStore& canvas, PaintWindow* live) {
  return render_float(canvas, live, RenderOutput::Height, 1);
}
FloatImage Renderer::render_normal_map(TileStore& canvas, PaintWindow* live) {
  return render_float(canvas, live, RenderOutput::Normal, 3);
}
FloatImage Renderer::render_albedo(TileStore& canvas, PaintWindow* live) {
  return render_float(canvas, live, RenderOutput::Albedo, 3);
}

// --- incremental cache -----------------------------------------------------------------

CanvasImageCache::CanvasImageCache(Renderer& renderer, const Camera& camera, int tile_px)
    : renderer_(renderer), tile_px_(tile_px) {
  WB_REQUIRE(tile_px > 0 && tile_px <= 1024, "image cache: tile size must be in [1, 1024] pixels");
  set_camera(camera);
}

void CanvasImageCache::set_camera(const Camera& camera) {
  camera_ = camera;
  tiles_x_ = (camera.width + tile_px_ - 1) / tile_px_;
  tiles_y_ = (camera.height + tile_px_ - 1) / tile_px_;
  dirty_.assign(size_t(tiles_x_) * tiles_y_, 1);
  image_ = Image(camera.width, camera.height);
}

void CanvasImageCache::mark_all_dirty() { std::fill(dirty_.begin(), dirty_.end(), uint8_t(1)); }

void CanvasImageCache::mark_dirty(int x0, int y0, int x1, int y1) {
  if (x1 <= x0 || y1 <= y0) return;
  const RenderParams& p = renderer_.params();
  // A cell's paint shows in pixels up to the reach of the normal stencil and the AO rays away.
  const float m = p.ao_offset + p.ao_length + p.normal_eps + 2.f;
  float px0 = 1e30f, py0 = 1e30f, px1 = -1e30f, py1 = -1e30f;
  const float relief = camera_.kind == CameraKind::Top ? 0.f : 64.f;
  for (int c = 0; c < 8; ++c) {
    const Vec3 q((c & 1) ? x1 + m : x0 - m, (c & 2) ? y1 + m : y0 - m, (c & 4) ? relief : 0.f);
    float px, py;
    camera_project(camera_, q, px, py);
    px0 = std::min(px0, px);
    px1 = std::max(px1, px);
    py0 = std::min(py0, py);
    py1 = std::max(py1, py);
  }
  const int tx0 = std::max(0, int(std::floor(px0)) / tile_px_), ty0 = std::max(0, int(std::floor(py0)) / tile_px_);
  const int tx1 = std::min(tiles_x_ - 1, int(std::floor(px1)) / tile_px_);
  const int ty1 = std::min(tiles_y_ - 1, int(std::floor(py1)) / tile_px_);
  if (px1 < 0.f || py1 < 0.f) return;
  for (int ty = ty0; ty <= ty1; ++ty)
    for (int tx = tx0; tx <= tx1; ++tx) dirty_[size_t(ty) * tiles_x_ + tx] = 1;
}

void CanvasImageCache::mark_window_dirty(const PaintWindow& w) {
  mark_dirty(w.origin().x, w.origin().y, w.origin().x + w.dims().x, w.origin().y + w.dims().y);
}

int CanvasImageCache::dirty_tiles() const { return int(std::count(dirty_.begin(), dirty_.end(), uint8_t(1))); }

const Image& CanvasImageCache::update(TileStore& canvas, PaintWindow* live, const ParticleOverlay* particles) {
  WB_PROFILE_SCOPE("render.incremental");
  std::vector<int32_t>& tiles = dirty_list_;
  tiles.clear();
  for (size_t i = 0; i < dirty_.size(); ++i)
    if (dirty_[i]) tiles.push_back(int32_t(i));
  last_tiles_ = int(tiles.size());
  if (tiles.empty()) return image_;
  renderer_.render_tiles(canvas, camera_, tiles, tile_px_, image_, live, particles);
  std::fill(dirty_.begin(), dirty_.end(), uint8_t(0));
  return image_;
}

}  // namespace wb
