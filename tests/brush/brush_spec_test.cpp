// Brush presets and the bristle model (paper §4.1): shape names, preset sizes, the
// shape-dependent layout (lengths, rest directions), determinism from the seed and
// spec validation.
#include <math.h>

#include <algorithm>
#include <gtest/gtest.h>
#include <string>

#include "core/brush/brush_model.h"
#include "core/brush/brush_spec.h"
#include "core/exec/error.h"

namespace wb::test {

constexpr BrushShape kAllShapes[] = {BrushShape::Round,   BrushShape::Flat, BrushShape::Fan,   BrushShape::Filbert,
                                     BrushShape::Angular, BrushShape::Mop,  BrushShape::Rigger};

TEST(BrushSpecTest, ShapeNamesRoundTrip) {
  for (BrushShape s : kAllShapes) EXPECT_EQ(brush_shape_from_string(to_string(s)), s);
}

TEST(BrushSpecTest, UnknownShapeListsValidNames) {
  try {
    brush_shape_from_string("sponge");
    FAIL() << "no error";
  } catch (const Error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("sponge"), std::string::npos) << m;
    for (BrushShape s : kAllShapes) EXPECT_NE(m.find(to_string(s)), std::string::npos) << m;
  }
}

TEST(BrushSpecTest, PresetsAreWithinThePaperRanges) {
  for (BrushShape s : kAllShapes) {
    const BrushSpec b = default_brush(s);
    EXPECT_EQ(b.shape, s);
    EXPECT_GE(b.bristles, 40) << to_string(s);
    EXPECT_LE(b.bristles, 600) << to_string(s);
    EXPECT_GE(b.length, 75.f) << to_string(s);
    EXPECT_LE(b.length, 125.f) << to_string(s);
    EXPECT_EQ(b.vertices_per_bristle, 10);
    EXPECT_EQ(b.samples_per_bristle, 128);
    EXPECT_NO_THROW(build_bristle_layout(b)) << to_string(s);
  }
  const BrushSpec rigger = default_brush(BrushShape::Rigger), mop = default_brush(BrushShape::Mop);
  const BrushSpec flat = default_brush(BrushShape::Flat), fan = default_brush(BrushShape::Fan);
  for (BrushShape s : kAllShapes) {
    const BrushSpec b = default_brush(s);
    if (s != BrushShape::Rigger) {
      EXPECT_GT(rigger.length, b.length) << "rigger is the longest";
      EXPECT_LT(rigger.bristles, b.bristles) << "rigger has the fewest bristles";
      EXPECT_LT(rigger.width, b.width);
    }
    if (s != BrushShape::Mop) {
      EXPECT_GT(mop.width * mop.thickness, b.width * b.thickness) << "mop is the biggest";
      EXPECT_LT(mop.stiffness, b.stiffness) << "mop is the softest";
    }
  }
  EXPECT_GT(flat.width, 4.f * flat.thickness);
  EXPECT_GT(fan.width, 6.f * fan.thickness);
}

TEST(BrushModelTest, LayoutIsDeterministicFromTheSeed) {
  BrushSpec spec = default_brush(BrushShape::Round);
  const BristleLayout a = build_bristle_layout(spec), b = build_bristle_layout(spec);
  ASSERT_EQ(a.rest.size(), b.rest.size());
  for (size_t i = 0; i < a.rest.size(); ++i) {
    ASSERT_EQ(a.rest[i].x, b.rest[i].x);
    ASSERT_EQ(a.rest[i].y, b.rest[i].y);
    ASSERT_EQ(a.rest[i].z, b.rest[i].z);
  }
  spec.seed = 2;
  const BristleLayout c = build_bristle_layout(spec);
  int differ = 0;
  for (size_t k = 0; k < a.length.size(); ++k) differ += a.length[k] != c.length[k];
  EXPECT_GT(differ, int(a.length.size()) / 2) << "another seed gives other per-bristle variation";
}

TEST(BrushModelTest, RootsInsideTheFerruleAndLengthsVaryAsSpecified) {
  for (BrushShape s : kAllShapes) {
    const BrushSpec spec = default_brush(s);
    const BristleLayout L = build_bristle_layout(spec);
    ASSERT_EQ(int(L.root.size()), spec.bristles);
    for (int k = 0; k < spec.bristles; ++k) {
      const Vec3 r = L.root[size_t(k)];
      EXPECT_LE(fabsf(r.x), 0.5f * spec.width + 1e-3f) << to_string(s);
      EXPECT_LE(fabsf(r.y), 0.5f * spec.thickness + 1e-3f) << to_string(s);
      EXPECT_EQ(r.z, 0.f);
      const float profile = shape_length_profile(s, r.x, spec.width);
      EXPECT_LE(L.length[size_t(k)], spec.length * profile * (1.f + spec.length_variation) * 1.0001f);
      EXPECT_GE(L.length[size_t(k)], spec.length * profile * (1.f - spec.length_variation) * 0.9999f);
      EXPECT_NEAR(length(L.dir[size_t(k)]), 1.f, 1e-5f);
      EXPECT_LT(L.dir[size_t(k)].z, 0.f) << "bristles hang below the ferrule";
      // Straight rest bristles of the stated length.
      const int V = spec.vertices_per_bristle;
      EXPECT_NEAR(length(L.rest[size_t(k) * V + V - 1] - r), L.length[size_t(k)], 1e-3f);
    }
  }
}

TEST(BrushModelTest, ShapeProfiles) {
  // Angular: length falls linearly across the width; filbert: an oval tip (edges shorter).
  EXPECT_NEAR(shape_length_profile(BrushShape::Angular, -30.f, 60.f), 1.f, 1e-6f);
  EXPECT_NEAR(shape_length_profile(BrushShape::Angular, 0.f, 60.f), 0.8f, 1e-6f);
  EXPECT_NEAR(shape_length_profile(BrushShape::Angular, 30.f, 60.f), 0.6f, 1e-6f);
  EXPECT_NEAR(shape_length_profile(BrushShape::Filbert, 0.f, 56.f), 1.f, 1e-6f);
  EXPECT_LT(shape_length_profile(BrushShape::Filbert, 27.f, 56.f), 0.85f);
  EXPECT_EQ(shape_length_profile(BrushShape::Flat, 27.f, 56.f), 1.f);

  // Fan tips spread far wider than the ferrule; round tips converge inside it.
  auto tip_extent = [](BrushShape s) {
    const BrushSpec spec = default_brush(s);
    const BristleLayout L = build_bristle_layout(spec);
    float lo = 1e9f, hi = -1e9f;
    for (int k = 0; k < spec.bristles; ++k) {
      const float x = L.rest[size_t(k) * spec.vertices_per_bristle + spec.vertices_per_bristle - 1].x;
      lo = std::min(lo, x);
      hi = std::max(hi, x);
    }
    return (hi - lo) / spec.width;
  };
  EXPECT_GT(tip_extent(BrushShape::Fan), 2.f);
  EXPECT_LT(tip_extent(BrushShape::Round), 0.6f);
  EXPECT_GT(tip_extent(BrushShape::Mop), 1.1f);
}

TEST(BrushModelTest, BadSpecsAreRejectedWithTheField) {
  auto expect_error = [](BrushSpec spec, const char* field) {
    try {
      build_bristle_layout(spec);
      ADD_FAILURE() << "no error for " << field;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
    }
  };
  BrushSpec b = default_brush(BrushShape::Round);
  b.bristles = 0;
  expect_error(b, "bristles");
  b = default_brush(BrushShape::Round);
  b.length = -3.f;
  expect_error(b, "length");
  b = default_brush(BrushShape::Round);
  b.stiffness = 1.5f;
  expect_error(b, "stiffness");
  b = default_brush(BrushShape::Round);
  b.length = 200.f;  // 128 samples would be more than a cell apart
  expect_error(b, "samples_per_bristle");
  b = default_brush(BrushShape::Round);
  b.vertices_per_bristle = 2;
  expect_error(b, "vertices_per_bristle");
}

}  // namespace wb::test
