#include "core/canvas/ground.h"

#include <algorithm>
#include <cstdio>

#include "core/canvas/tile_store.h"
#include "core/exec/error.h"
#include "core/io/json_reader.h"

namespace wb {

const char* to_string(Weave w) {
  switch (w) {
    case Weave::Smooth: return "smooth";
    case Weave::Linen: return "linen";
    case Weave::CottonDuck: return "cotton_duck";
  }
  return "smooth";
}

Weave weave_from_name(const std::string& name, const std::string& what) {
  for (Weave w : {Weave::Smooth, Weave::Linen, Weave::CottonDuck})
    if (name == to_string(w)) return w;
  WB_THROW(what + ": unknown weave '" + name + "' (smooth, linen or cotton_duck)");
}

CanvasGround CanvasGround::of(Weave w) {
  CanvasGround g;
  g.weave = w;
  if (w == Weave::CottonDuck) {
    g.thread_mm = 0.8f;
    g.relief_mm = 0.2f;
  }
  return g;
}

nlohmann::json ground_to_json(const CanvasGround& g) {
  return {{"weave", to_string(g.weave)}, {"thread_mm", g.thread_mm}, {"relief_mm", g.relief_mm},
          {"priming_mm", g.priming_mm}};
}

CanvasGround ground_from_json(const nlohmann::json& j, const std::string& source, const std::string& path) {
  ObjectReader r(j, source, path);
  CanvasGround g;
  if (r.has("weave")) g = CanvasGround::of(weave_from_name(r.string("weave"), source + ": " + r.where("weave")));
  g.thread_mm = float(r.number_or("thread_mm", g.thread_mm, kThreadMmMin, kThreadMmMax));
  g.relief_mm = float(r.number_or("relief_mm", g.relief_mm, kReliefMmMin, kReliefMmMax));
  g.priming_mm = float(r.number_or("priming_mm", g.priming_mm, 0.f, kPrimingMmMax));
  r.refuse_unknown();
  return g;
}

std::string ground_refusal(const CanvasGround& g, int width, int height, int depth, float cell_size_m) {
  if (g.weave == Weave::Smooth) return {};
  const WeaveField w = weave_field(g, cell_size_m, Vec3{});
  char buf[256];
  // The crowns reach base + relief times the thickest thread; paint needs room above.
  if (w.base + w.relief * (1.f + kThreadVariation) > 0.5f * float(depth)) {
    std::snprintf(buf, sizeof buf,
                  "the ground (%.2f mm of primer under %.2f mm of relief) is thicker than half the canvas's paint "
                  "depth (%d cells, %.1f mm)",
                  g.priming_mm, g.relief_mm, depth, double(depth) * cell_size_m * 1e3);
    return buf;
  }
  // A tile holds every cell of its columns.
  const uint64_t tiles = uint64_t((width + kTileSize - 1) / kTileSize) * uint64_t((height + kTileSize - 1) / kTileSize);
  const uint64_t bytes = tiles * kTileSize * kTileSize * uint64_t(depth) * kCellBytes;
  if (bytes > kMaxGroundBytes) {
    std::snprintf(buf, sizeof buf,
                  "a woven ground fills the whole canvas: %d x %d x %d cells would hold %.1f GiB of paint, more than "
                  "a painting may (%.0f GiB)",
                  width, height, depth, double(bytes) / double(1 << 30), double(kMaxGroundBytes) / double(1 << 30));
    return buf;
  }
  return {};
}

WeaveField weave_field(const CanvasGround& g, float cell_size_m, Vec3 priming_ryb) {
  const float mm = 1e-3f / cell_size_m;  // cells per mm
  WeaveField w;
  w.spacing = g.thread_mm * mm;
  w.relief = g.relief_mm * mm;
  w.base = g.priming_mm * mm;
  w.unevenness = g.weave == Weave::Linen ? 1.f : 0.f;
  w.ryb = priming_ryb;
  return w;
}

}  // namespace wb
