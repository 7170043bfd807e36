#include "core/canvas/ground.h"

#include <algorithm>

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
