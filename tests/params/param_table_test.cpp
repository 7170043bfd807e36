// The parameter table: defaults in range, validation, JSON round trip.
#include <gtest/gtest.h>

#include <set>
#include <string>

#include <nlohmann/json.hpp>

#include "core/params/param_table.h"

namespace wb::test {

TEST(ParamTable, EveryDefaultIsInRangeAndIdsAreUnique) {
  std::set<std::string> ids;
  for (const ParamInfo& p : param_table()) {
    EXPECT_TRUE(ids.insert(p.id).second) << "duplicate " << p.id;
    const double d = p.default_value();
    EXPECT_GE(d, p.min) << p.id;
    EXPECT_LE(d, p.max) << p.id;
    EXPECT_FALSE(p.label.empty()) << p.id;
    EXPECT_FALSE(p.tooltip.empty()) << p.id;
  }
  EXPECT_GT(ids.size(), 30u);
}

TEST(ParamTable, PaperDefaults) {
  const SimParams p{};
  EXPECT_EQ(find_param("grid.jacobi_L")->get(p), 3.0);   // Algorithm 1: L = 3
  EXPECT_EQ(find_param("grid.alpha")->get(p), 1.0);      // alpha = 1
  EXPECT_FLOAT_EQ(float(find_param("particles.gamma")->get(p)), 0.8f);  // Eq. 11
  EXPECT_FLOAT_EQ(float(find_param("particles.D1")->get(p)), 15.f);     // 0.3 cm
  EXPECT_FLOAT_EQ(float(find_param("particles.D0")->get(p)), 50.f);     // 1 cm
}

TEST(ParamTable, ValidationRejectsBadValues) {
  SimParams p;
  EXPECT_THROW(set_param(p, "grid.nope", 1), Error);
  EXPECT_THROW(set_param(p, "particles.beta_L", 0.5), Error);  // Table 1 range [0, 0.2]
  EXPECT_THROW(set_param(p, "grid.jacobi_L", 2.5), Error);
  EXPECT_THROW(set_param(p, "grid.alpha", std::nan("")), Error);
  EXPECT_THROW(apply_param_assignment(p, "grid.alpha"), Error);
  EXPECT_THROW(apply_param_assignment(p, "grid.alpha=abc"), Error);
  apply_param_assignment(p, "grid.jacobi_L=5");
  EXPECT_EQ(p.grid.jacobi_L, 5);
  apply_param_assignment(p, "grid.projection_norms=true");
  EXPECT_TRUE(p.grid.projection_norms);
}

TEST(ParamTable, JsonRoundTripAndUnknownKeys) {
  SimParams a;
  a.grid.jacobi_L = 7;
  a.particles.beta_L = 0.05f;
  a.render.light_dir.x = 0.25f;
  const nlohmann::json j = params_to_json(a);
  SimParams b;
  std::vector<std::string> warnings;
  params_from_json(b, j, warnings);
  EXPECT_TRUE(warnings.empty());
  EXPECT_EQ(params_to_json(b), j);
  nlohmann::json extra = {{"grid", {{"jacobi_L", 2}, {"bogus", 1}}}};
  params_from_json(b, extra, warnings);
  EXPECT_EQ(b.grid.jacobi_L, 2);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("grid.bogus"), std::string::npos);
  EXPECT_THROW(params_from_json(b, nlohmann::json{{"grid", {{"alpha", "x"}}}}, warnings), Error);
}

// A parameter file nesting objects a million deep (a hostile or broken file) reads as one
// warning in bounded time: the reader never descends deeper than the deepest parameter id
// (render.light_dir.x), so its stack stays small.
TEST(ParamTable, DeeplyNestedFileIsOneWarning) {
  const int depth = 1000000;
  std::string text;
  text.reserve(size_t(depth) * 6 + 16);
  for (int i = 0; i < depth; ++i) text += "{\"a\":";
  text += "1";
  text.append(size_t(depth), '}');
  const nlohmann::json j = nlohmann::json::parse(text);
  SimParams p;
  std::vector<std::string> warnings;
  params_from_json(p, j, warnings);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("unknown parameter group 'a.a.a'"), std::string::npos) << warnings[0];
  EXPECT_EQ(params_to_json(p), params_to_json(SimParams{}));
}

}  // namespace wb::test
