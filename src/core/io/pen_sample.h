// A stylus sample as recorded: time, position on the canvas, pressure, tilt and twist.
#pragma once

namespace wb {

struct PenSample {
  double t = 0.0;        ///< seconds from the stroke's start
  float x = 0.f;         ///< canvas cells
  float y = 0.f;         ///< canvas cells
  float pressure = 0.f;  ///< 0 (touching, or lifted when the pen is up) .. 1 (deepest press)
  float tilt_x = 0.f;    ///< degrees, handle tilted toward +x (Qt QTabletEvent::xTilt convention)
  float tilt_y = 0.f;    ///< degrees, toward +y
  float twist = 0.f;     ///< degrees, rotation of the handle about its own axis
  bool down = true;      ///< pen on the canvas (MyPaint dumps: pressure > 0)
};

}  // namespace wb
