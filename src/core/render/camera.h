// Cameras of the renderer (paper §6): orthographic views of the canvas. Top view at any zoom
// and pan (default one image pixel per canvas cell) and an oblique view that shows relief.
// A Camera is a host value; camera_basis() turns it into the POD the kernels use.
#pragma once
#include <cmath>

#include "core/canvas/tile_store.h"
#include "core/math/vec.h"

namespace wb {

enum class CameraKind : int { Top = 0, Oblique = 1 };

struct Camera {
  CameraKind kind = CameraKind::Top;
  int width = 0, height = 0;  ///< image size, pixels
  float zoom = 1.f;           ///< image pixels per canvas cell
  float center_x = 0.f, center_y = 0.f;  ///< canvas point (z = 0) at the image centre, cells
  float elevation_deg = 90.f;  ///< 90 = straight down; the oblique view looks towards -y

  /// The whole canvas from above, one pixel per cell.
  static Camera top(CanvasDims d) { return top_region(0.f, 0.f, float(d.width), float(d.height), 1.f); }
  /// The canvas rectangle [x0, x0+w) x [y0, y0+h) from above at `zoom` pixels per cell.
  static Camera top_region(float x0, float y0, float w, float h, float zoom) {
    Camera c;
    c.kind = CameraKind::Top;
    c.zoom = zoom;
    c.width = int(std::lround(w * zoom));
    c.height = int(std::lround(h * zoom));
    c.center_x = x0 + w * 0.5f;
    c.center_y = y0 + h * 0.5f;
    c.elevation_deg = 90.f;
    return c;
  }
  /// The whole canvas seen from `elevation_deg` above the horizon, `zoom` pixels per cell,
  /// with room for `relief` cells of paint height.
  static Camera oblique(CanvasDims d, float elevation_deg = 40.f, float zoom = 1.f, float relief = 16.f) {
    Camera c;
    c.kind = CameraKind::Oblique;
    c.zoom = zoom;
    c.elevation_deg = elevation_deg;
    const float e = elevation_deg * 3.14159265f / 180.f;
    c.width = int(std::ceil(d.width * zoom));
    c.height = int(std::ceil((d.height * std::sin(e) + relief * std::cos(e)) * zoom));
    c.center_x = d.width * 0.5f;
    // Shift the centre so that the relief above the far edge stays in the picture.
    c.center_y = d.height * 0.5f - 0.5f * relief * std::cos(e) * std::sin(e);
    return c;
  }
};

/// Kernel form of a camera: pixel (i, j) looks along `dir` through p00 + (i+.5) du + (j+.5) dv.
struct CameraBasis {
  Vec3 p00, du, dv, dir;
  int top;  ///< 1 for the straight-down view (per-pixel start height, no parallax)
};

inline CameraBasis camera_basis(const Camera& c) {
  CameraBasis b;
  const float e = c.elevation_deg * 3.14159265f / 180.f;
  const bool top = c.kind == CameraKind::Top || c.elevation_deg >= 89.999f;
  b.top = top ? 1 : 0;
  b.dir = top ? Vec3(0.f, 0.f, -1.f) : Vec3(0.f, -std::cos(e), -std::sin(e));
  b.du = Vec3(1.f / c.zoom, 0.f, 0.f);
  // Down the image: towards +y on the canvas and, when oblique, down in z (towards the viewer).
  b.dv = top ? Vec3(0.f, 1.f / c.zoom, 0.f) : Vec3(0.f, std::sin(e) / c.zoom, -std::cos(e) / c.zoom);
  b.p00 = Vec3(c.center_x, c.center_y, 0.f) - b.du * (0.5f * c.width) - b.dv * (0.5f * c.height);
  return b;
}

/// Image position (pixels, continuous) of a canvas point: the inverse of the pixel mapping.
inline void camera_project(const Camera& c, Vec3 p, float& px, float& py) {
  const CameraBasis b = camera_basis(c);
  const Vec3 q = p - b.p00;
  // du, dv and dir are orthogonal: project onto du and dv.
  px = dot(q, b.du) / dot(b.du, b.du);
  py = dot(q, b.dv) / dot(b.dv, b.dv);
}

}  // namespace wb
