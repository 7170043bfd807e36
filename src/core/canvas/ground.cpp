#include "core/canvas/ground.h"

#include <algorithm>
#include <cstdio>

#include "core/exec/error.h"

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

CanvasGround ground_from_json(const nlohmann::json& j, const std::string& what) {
  WB_REQUIRE(j.is_object(), what + ": the ground must be an object");
  CanvasGround g;
  auto number = [&](const char* key, float fallback, float lo, float hi) {
    if (!j.contains(key)) return fallback;
    const nlohmann::json& v = j.at(key);
    WB_REQUIRE(v.is_number(), what + ": " + key + " must be a number");
    const double x = v.get<double>();
    WB_REQUIRE(std::isfinite(x) && x >= lo && x <= hi, what + ": " + key + " = " + v.dump() + " is outside [" +
                                                         std::to_string(lo) + ", " + std::to_string(hi) + "] mm");
    return float(x);
  };
  if (j.contains("weave")) {
    WB_REQUIRE(j.at("weave").is_string(), what + ": weave must be a name");
    g = CanvasGround::of(weave_from_name(j.at("weave").get<std::string>(), what));
  }
  g.thread_mm = number("thread_mm", g.thread_mm, kThreadMmMin, kThreadMmMax);
  g.relief_mm = number("relief_mm", g.relief_mm, kReliefMmMin, kReliefMmMax);
  g.priming_mm = number("priming_mm", g.priming_mm, 0.f, kPrimingMmMax);
  for (const auto& [k, v] : j.items())
    WB_REQUIRE(k == "weave" || k == "thread_mm" || k == "relief_mm" || k == "priming_mm",
               what + ": unknown key '" + k + "'");
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
  const int tile = 16;  // kTileSize (tile_store.h): a tile holds every cell of its columns
  const uint64_t tiles = uint64_t((width + tile - 1) / tile) * uint64_t((height + tile - 1) / tile);
  const uint64_t bytes = tiles * tile * tile * uint64_t(depth) * 14;
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
