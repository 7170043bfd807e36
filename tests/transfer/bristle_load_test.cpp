// The paint on the brush (paper §5.1): loading, dipping (dirty brush), wiping, cleaning, the
// UI sums, and the paint books' arithmetic.
#include <gtest/gtest.h>

#include <cmath>

#include "core/color/ryb.h"
#include "core/exec/error.h"
#include "transfer/transfer_fixture.h"

namespace wb::test {
namespace {

class BristleLoadTest : public TransferTest {
 protected:
  static PaintLoad paint(Vec3 ryb, float oil, float level) {
    PaintLoad p;
    p.ryb[0] = ryb.x;
    p.ryb[1] = ryb.y;
    p.ryb[2] = ryb.z;
    p.oil = oil;
    p.load = level;
    return p;
  }
};

TEST_F(BristleLoadTest, FillLoadsToTheFractionOfCapacity) {
  TransferParams prm;
  const int64_t n = 3000;
  BristleLoad load(device_, n, prm);
  EXPECT_EQ(load.total_mass(ws_), 0.0);
  load.fill(paint(Vec3(0.1f, 0.15f, 0.85f), 0.3f, 0.8f));
  const double added = load.take_change();
  EXPECT_NEAR(load.total_mass(ws_), double(n) * 0.8 * prm.M_max, 1e-6 * n * prm.M_max);
  EXPECT_NEAR(added, load.total_mass(ws_), 1e-6 * added);
  const Vec3 c = load.mean_color(ws_);
  EXPECT_NEAR(c.x, 0.1f, 1e-4f);
  EXPECT_NEAR(c.y, 0.15f, 1e-4f);
  EXPECT_NEAR(c.z, 0.85f, 1e-4f);
  EXPECT_NEAR(load.mean_oil(ws_), 0.3f, 1e-5f);
  // After a capacity pass under compression, fill uses the potential capacity M'.
  BristleLoadHost h = load.to_host();
  for (float& m : h.potential) m = 0.5f * prm.M_max;
  load.from_host(h);
  load.fill(paint(Vec3(0.f, 1.f, 0.f), 0.1f, 1.f));
  EXPECT_NEAR(load.total_mass(ws_), double(n) * 0.5 * prm.M_max, 1e-6 * n * prm.M_max);
}

TEST_F(BristleLoadTest, DipMixesIntoWhatIsThere) {
  TransferParams prm;
  BristleLoad load(device_, 100, prm);
  const Vec3 blue(0.f, 0.f, 1.f), yellow(0.f, 1.f, 0.f);
  load.fill(paint(blue, 0.2f, 0.5f));
  (void)load.take_change();
  load.dip(paint(yellow, 0.6f, 1.f));
  const double added = load.take_change();
  EXPECT_NEAR(added, 100.0 * 0.5 * prm.M_max, 1e-6 * 100 * prm.M_max);
  EXPECT_NEAR(load.total_mass(ws_), 100.0 * prm.M_max, 1e-6 * 100 * prm.M_max);
  const Vec3 ref = color_mix(blue, yellow, 0.5f, 0.5f);
  const BristleLoadHost h = load.to_host();
  for (size_t j = 0; j < h.m.size(); ++j) {
    EXPECT_NEAR(h.pigment_y[j], ref.y, 1e-4f);
    EXPECT_NEAR(h.pigment_b[j], ref.z, 1e-4f);
    EXPECT_NEAR(h.oil[j], 0.4f, 1e-5f);
  }
  const Vec3 rgb = ryb_to_rgb(load.mean_color(ws_));
  EXPECT_GT(rgb.y, rgb.x);
  EXPECT_GT(rgb.y, rgb.z);
  // As one well (what a recording starting with this brush loads): the mix, its oil, full.
  const PaintLoad well = load.mean_paint(ws_, paint(blue, 0.2f, 0.5f));
  const Vec3 mean = load.mean_color(ws_);
  EXPECT_NEAR(well.ryb[1], mean.y, 1e-6f);
  EXPECT_NEAR(well.ryb[2], mean.z, 1e-6f);
  EXPECT_NEAR(well.oil, 0.4f, 1e-5f);
  EXPECT_NEAR(well.load, 1.f, 1e-5f);
  // A full brush takes no more paint, and its colour stays.
  load.dip(paint(Vec3(1.f, 0.f, 0.f), 0.3f, 0.7f));
  EXPECT_EQ(load.take_change(), 0.0);
  EXPECT_NEAR(load.to_host().pigment_r[0], 0.f, 1e-6f);
}

// The share x_j the well reaches is replaced by the well's paint, then the sample is topped up;
// the rest of its paint stays, and the brush's mass changes only by the top-up.
TEST_F(BristleLoadTest, DipReplacesTheShareTheWellReaches) {
  TransferParams prm;
  BristleLoad load(device_, 4, prm);
  const Vec3 red(1.f, 0.f, 0.f), blue(0.f, 0.f, 1.f);
  load.fill(paint(red, 0.2f, 1.f));
  BristleLoadHost h = load.to_host();
  h.m[1] *= 0.5f, h.m[3] *= 0.5f;  // half-empty samples
  load.from_host(h);
  load.set_dip_exchange({0.f, 0.f, 0.6f, 0.6f});
  (void)load.take_change();
  load.dip(paint(blue, 0.6f, 1.f));
  const double added = load.take_change();
  EXPECT_NEAR(added, prm.M_max, 1e-6 * prm.M_max) << "two half-empty samples topped up";
  h = load.to_host();
  const float M = prm.M_max;
  EXPECT_NEAR(h.m[0], M, 1e-6f * M);
  EXPECT_EQ(h.pigment_r[0], 1.f) << "a full sample the well does not reach keeps its paint";
  EXPECT_NEAR(h.pigment_b[1], color_mix(red, blue, 0.5f, 0.5f).z, 1e-5f) << "topped up only";
  const Vec3 c2 = color_mix(red, blue, 0.4f, 0.6f);  // full, 0.6 of it replaced
  EXPECT_NEAR(h.pigment_r[2], c2.x, 1e-5f);
  EXPECT_NEAR(h.pigment_b[2], c2.z, 1e-5f);
  EXPECT_NEAR(h.oil[2], 0.4f * 0.2f + 0.6f * 0.6f, 1e-5f);
  const Vec3 c3 = color_mix(red, blue, 0.2f, 0.8f);  // half full: 0.3 replaced, 0.5 added
  EXPECT_NEAR(h.pigment_b[3], c3.z, 1e-5f);
  for (float m : h.m) EXPECT_NEAR(m, M, 1e-6f * M);
  EXPECT_THROW(load.set_dip_exchange({0.f, 0.f, 1.5f, 0.f}), Error);
  EXPECT_THROW(load.set_dip_exchange({0.f}), Error);
}

TEST_F(BristleLoadTest, WipeRemovesTheFractionAndCleanEmpties) {
  TransferParams prm;
  BristleLoad load(device_, 500, prm);
  load.fill(paint(Vec3(0.7f, 0.2f, 0.1f), 0.3f, 0.9f));
  const double before = load.total_mass(ws_);
  (void)load.take_change();
  load.wipe(0.3f);
  const double removed = -load.take_change();
  EXPECT_NEAR(removed, 0.3 * before, 1e-6 * before);
  EXPECT_NEAR(load.total_mass(ws_), 0.7 * before, 1e-6 * before);
  const Vec3 c = load.mean_color(ws_);
  EXPECT_NEAR(c.x, 0.7f, 1e-4f) << "wiping keeps the colour";
  const double left = load.total_mass(ws_);
  load.clean();
  EXPECT_NEAR(-load.take_change(), left, 1e-6 * left);
  EXPECT_EQ(load.total_mass(ws_), 0.0);
  const Vec3 w = load.mean_color(ws_);
  EXPECT_EQ(w.x + w.y + w.z, 0.f);
  EXPECT_EQ(load.mean_oil(ws_), 0.f);
  const PaintLoad clean = load.mean_paint(ws_, paint(Vec3(0.f, 1.f, 0.f), 0.6f, 0.8f));
  EXPECT_EQ(clean.load, 0.f) << "a clean brush carries no paint";
  EXPECT_EQ(clean.ryb[1], 1.f) << "and keeps the well's colour for its next load";
  EXPECT_EQ(clean.oil, 0.6f);
}

TEST_F(BristleLoadTest, BadInputIsRejected) {
  TransferParams prm;
  BristleLoad load(device_, 10, prm);
  EXPECT_THROW(load.fill(paint(Vec3(0.f, 0.f, 1.f), 0.3f, 1.5f)), Error);
  EXPECT_THROW(load.dip(paint(Vec3(0.f, 2.f, 1.f), 0.3f, 0.5f)), Error);
  EXPECT_THROW(load.wipe(-0.1f), Error);
  EXPECT_THROW(load.wipe(std::nanf("")), Error);
  BristleLoadHost h = load.to_host();
  h.m[3] = -1.f;
  EXPECT_THROW(load.from_host(h), Error);
  h.m.resize(4);
  EXPECT_THROW(load.from_host(h), Error);
  TransferParams bad;
  bad.mu = 2.f;
  EXPECT_THROW(Transfer(device_, bad), Error);
}

TEST(PaintBooks, DriftIsMeasuredAgainstInitialPlusExternal) {
  PaintBooks books(3);
  books.open(PaintCensus{1e-6, 2e-6, 7e-6});
  EXPECT_DOUBLE_EQ(books.initial_total(), 1e-5);
  TransferRecord rec;
  rec.absorbed_from_particles = rec.absorbed_into_bristles = 1e-7;
  EXPECT_NEAR(books.record(rec, PaintCensus{1.1e-6, 1.9e-6, 7e-6}), 0.0, 1e-12);
  books.external(5e-6);  // a dip
  EXPECT_NEAR(books.record(rec, PaintCensus{6.1e-6, 1.9e-6, 7e-6}), 0.0, 1e-12);
  EXPECT_NEAR(books.record(rec, PaintCensus{6.1e-6, 1.9e-6, 7.15e-6}), 0.01, 1e-9);  // 1% appeared
  EXPECT_NEAR(books.max_drift(), 0.01, 1e-9);
  books.record(rec, PaintCensus{6.1e-6, 1.9e-6, 7e-6});
  EXPECT_EQ(books.steps().size(), 3u) << "history is bounded";
  EXPECT_NEAR(books.totals().absorbed, 4e-7, 1e-15);
  EXPECT_EQ(books.steps().back().external, 0.0);
  TransferRecord bad;
  bad.to_grid_from_particles = 1.0;
  bad.to_grid_into_grid = 0.99;
  EXPECT_NEAR(bad.max_closure_error(), 0.01, 1e-12);
}

}  // namespace
}  // namespace wb::test
