// A recording's pause: the pen in the air, the paint at rest. The replay passes over it in one
// call (Simulator::rest): the paint dries for the pause, nothing else happens, and an hour's
// pause costs what a step does.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>

#include "core/io/stroke.h"
#include "core/io/stroke_player.h"
#include "core/session/session.h"
#include "sim/sim_fixture.h"

namespace wb::test {
namespace {

class ReplayPauseTest : public SimulatorTest {
 protected:
  /// Two short dabs 80 cells apart, `pause` seconds between the first's lift and the second's
  /// landing, with no sample between (as a tablet records a pause).
  Stroke two_dabs(double pause) const {
    const SimConfig c = small_config();
    Stroke s;
    s.canvas = c.canvas;
    s.brush = c.brush;
    s.paint = red();
    s.source = "two dabs";
    const auto pen = [](double t, float x, float p, bool down = true) {
      PenSample q;
      q.t = t, q.x = x, q.y = 128.f, q.pressure = p, q.down = down;
      return q;
    };
    s.samples = {pen(0.0, 60.f, 0.5f), pen(0.3, 80.f, 0.5f), pen(0.31, 80.f, 0.f, false),
                 pen(0.31 + pause, 160.f, 0.5f), pen(0.61 + pause, 180.f, 0.5f)};
    return s;
  }

  struct Run {
    int64_t steps = 0, simulated = 0, rests = 0;
    double rest_seconds = 0.0, drift = 0.0;
    float first_dab_dryness = 0.f;  ///< least dryness of the first dab's painted cells, at the end
  };

  Run replay(const Stroke& stroke) const {
    Session session(small_config(), start_pose(stroke));
    session.begin_replay(stroke);
    while (session.advance()) {}
    session.settle();
    Simulator& sim = session.sim();
    Run out;
    out.steps = session.replay()->step_count();
    out.simulated = sim.counters().steps;
    out.rests = sim.counters().rests;
    out.rest_seconds = sim.counters().rest_seconds;
    out.drift = sim.books().max_drift();
    out.first_dab_dryness = 1.f;
    sim.with_settled_canvas([&](TileStore& canvas) {
      for (int id : canvas.allocated_tile_ids()) {
        const TileData t = canvas.read_tile(id);
        for (size_t i = 0; i < t.density.size(); ++i) {
          const int x = t.tile_x * kTileSize + int(i % kTileSize);
          if (t.density[i] > 0.1f && x < 120) out.first_dab_dryness = std::min(out.first_dab_dryness, t.dryness[i] / 65535.f);
        }
      }
    });
    return out;
  }
};

TEST_F(ReplayPauseTest, AnHoursPauseCostsAStepAndDriesThePaint) {
  const Run hour = replay(two_dabs(3600.0)), short_pause = replay(two_dabs(3.0));
  std::printf("hour: %lld steps on the clock, %lld simulated, %lld rests (%.1f s); first dab's least dryness %.3f\n",
              static_cast<long long>(hour.steps), static_cast<long long>(hour.simulated),
              static_cast<long long>(hour.rests), hour.rest_seconds, hour.first_dab_dryness);
  std::printf("3 s: %lld steps, %lld simulated, %lld rests (%.1f s); least dryness %.3f\n",
              static_cast<long long>(short_pause.steps), static_cast<long long>(short_pause.simulated),
              static_cast<long long>(short_pause.rests), short_pause.rest_seconds, short_pause.first_dab_dryness);
  // The pause is passed over once, for almost all of its length; the steps simulated are the
  // dabs', the lift, the paint coming to rest and the landing: under 1 % of the clock's.
  EXPECT_EQ(hour.rests, 1);
  EXPECT_GT(hour.rest_seconds, 3590.0);
  EXPECT_LT(hour.rest_seconds, 3600.0);
  EXPECT_LT(double(hour.simulated), 0.01 * double(hour.steps));
  EXPECT_LT(hour.simulated, short_pause.simulated + 60) << "the hour costs about what 3 s do";
  // Drying ran for the hour (0.002 /s: dry after 500 s) and not for the short pause.
  EXPECT_GE(hour.first_dab_dryness, small_config().params.grid.dry_threshold);
  EXPECT_LT(short_pause.first_dab_dryness, 0.05f);
  EXPECT_LT(std::abs(hour.drift), 1e-4);
  EXPECT_LT(std::abs(short_pause.drift), 1e-4);
}

}  // namespace
}  // namespace wb::test
