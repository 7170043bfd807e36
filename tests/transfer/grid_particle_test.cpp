// Grid <-> particle transfer (paper §5.2, Eq. 15-16) and the books of a whole transfer step:
// exact mass conservation (also where the clamp of Eq. 15 bites), cells beyond D0 untouched,
// brightness-preserving colour mixing into the grid, the coarse distance field.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <cmath>
#include <limits>

#include "core/color/ryb.h"
#include "core/exec/memory.h"
#include "transfer/transfer_fixture.h"

namespace wb::test {
namespace {

class GridParticleTest : public TransferTest {
 protected:
  /// A POD view of host copies of the window (for evaluating kernels on the host).
  static PaintWindowView host_view(WindowFields& f, const PaintWindow& w) {
    PaintWindowView v{};
    v.density = f[0].data();
    v.pigment_r = f[1].data();
    v.pigment_y = f[2].data();
    v.pigment_b = f[3].data();
    v.oil = f[4].data();
    v.dryness = f[5].data();
    v.nx = w.dims().x;
    v.ny = w.dims().y;
    v.nz = w.dims().z;
    v.ox = w.origin().x;
    v.oy = w.origin().y;
    v.oz = w.origin().z;
    return v;
  }
  PaintWindow books_window() {
    return make_window({48, 48, 12}, {0, 0, 0}, [](int i, int, int k) { return k < 2 && i > 20 ? 0.9f : 0.f; },
                       Vec3(0.f, 1.f, 0.f), 0.3f);
  }
  /// Eq. 15 over the window near one vertical bristle above (x, 8.5, 3), D0 10: the particles
  /// made, into p; the step's sums into rec.
  void grid_near_one_bristle(PaintWindow& w, float x, ParticleStore& p, TransferRecord& rec) {
    HostSamples h = vertical_brush(1, 4, 0.8f, x, 8.5f, 3.f, 1.f);
    DeviceSamples s(device_);
    s.upload(h);
    Transfer t(device_, TransferParams{});
    TransferEnv env = env_for(w, 10.f);
    t.update_distance(s.view(), env);
    t.grid_to_particles(p, env, rec);
    t.collect(rec);
  }
  static float min_distance(const HostSamples& h, Vec3 p) {
    float d = std::numeric_limits<float>::max();
    for (const Vec3& x : h.x) d = std::min(d, length(x - p));
    return d;
  }
};

TEST_F(GridParticleTest, DistanceFieldMatchesBruteForceOverBlocks) {
  HostSamples h;
  h.resize(1, 7);
  const Vec3 pts[7] = {Vec3(110, 210, 3), Vec3(131, 240, 1), Vec3(100, 200, 0), Vec3(147.5f, 215, 7.9f),
                       Vec3(125, 225, 30), Vec3(90, 190, 2), Vec3(300, 300, 2)};
  for (int i = 0; i < 7; ++i) h.x[size_t(i)] = pts[i];
  DeviceSamples s(device_);
  s.upload(h);
  PaintWindow w = make_window({48, 48, 8}, {100, 200, 0}, [](int, int, int) { return 0.f; }, Vec3());
  TransferParams prm;
  prm.distance_block = 4;
  Transfer t(device_, prm);
  t.update_distance(s.view(), env_for(w, 12.f));
  const DistanceBlocks db = t.distance_view();
  const std::vector<float> d = t.distance_to_host();
  // Brute force: block-centre distances to the blocks holding samples (inside the grid).
  std::vector<int64_t> occupied;
  for (const Vec3& x : h.x) {
    const int64_t b = db.block_of(Vec3(x.x - 100.f, x.y - 200.f, x.z));
    if (b >= 0) occupied.push_back(b);
  }
  ASSERT_FALSE(occupied.empty());
  auto coords = [&](int64_t b, int& i, int& j, int& k) {
    i = int(b % db.bx);
    j = int((b / db.bx) % db.by);
    k = int(b / (int64_t(db.bx) * db.by));
  };
  for (int64_t b = 0; b < int64_t(d.size()); ++b) {
    int i, j, k;
    coords(b, i, j, k);
    double best = 1e30;
    for (int64_t o : occupied) {
      int a, c, e;
      coords(o, a, c, e);
      best = std::min(best, std::sqrt(double((i - a) * (i - a) + (j - c) * (j - c) + (k - e) * (k - e))) * db.block);
    }
    ASSERT_NEAR(d[size_t(b)], best, 1e-3 * (1 + best)) << "block " << b;
  }
}

TEST_F(GridParticleTest, DistanceFieldTravelsWithTheBrush) {
  // The blocks' lattice lies on the brush (TransferEnv::lattice_anchor): a brush moved by d, its
  // anchor with it, gives at p + d the distance it gave at p, to rounding, whatever d and the
  // window. A lattice held by the window (or shifted over the steps) gives up to a block's error
  // that changes as the brush crosses its edges: the D0 front jumps (docs/TRANSFER.md "Ribs on
  // slow strokes").
  const HostSamples h0 = vertical_brush(3, 12, 0.8f, 124.f, 224.f, 3.f, 1.f);
  PaintWindow w = make_window(
      {48, 48, 8}, {100, 200, 0}, [](int, int, int) { return 0.f; }, Vec3());
  TransferParams prm;
  prm.distance_block = 4;
  const float D0 = 12.f;
  const auto field = [&](Transfer& t, Vec3 d, bool on_brush) {
    HostSamples h = h0;
    for (Vec3& x : h.x) x = x + d;
    DeviceSamples s(device_);
    s.upload(h);
    TransferEnv env = env_for(w, D0);
    env.lattice_anchor = on_brush ? Vec3(124.f, 224.f, 3.f) + d : Vec3();
    t.update_distance(s.view(), env);
    return t.distance_view();
  };
  Transfer at_rest(device_, prm), moved(device_, prm), held(device_, prm);
  const DistanceBlocks a = field(at_rest, Vec3(), true);
  double worst_on_brush = 0.0, worst_on_window = 0.0;
  for (const Vec3 d : {Vec3(0.4f, 0.f, 0.f), Vec3(1.3f, 0.f, 0.f), Vec3(2.5f, -0.7f, 0.f), Vec3(3.9f, 1.1f, 0.f)}) {
    const DistanceBlocks b = field(moved, d, true), c = field(held, d, false);
    for (float x = 6.f; x < 42.f; x += 0.75f)
      for (float z = 0.5f; z < 6.f; z += 1.f) {
        const Vec3 p(x, 24.f, z), q = p + d;  // window positions (the window's origin is its own)
        const float da = a.distance(p);
        if (!(da < 2.f * D0)) continue;
        worst_on_brush = std::max(worst_on_brush, double(std::fabs(b.distance(q) - da)));
        worst_on_window = std::max(worst_on_window, double(std::fabs(c.distance(q) - da)));
      }
  }
  std::printf("distance at the moved point: off by %.4f cells with the lattice on the brush, %.2f on the window\n",
              worst_on_brush, worst_on_window);
  EXPECT_LT(worst_on_brush, 1e-3);
  EXPECT_GT(worst_on_window, 0.5) << "the test must see a lattice held still";
}

TEST_F(GridParticleTest, LayerNearTheBristlesBecomesParticlesWithExactMass) {
  const Int3 origin{100, 200, 0};
  PaintWindow w = make_window({48, 48, 8}, origin, [](int, int, int k) { return k < 2 ? 0.8f : 0.f; },
                              Vec3(0.f, 1.f, 0.f), 0.2f);
  HostSamples h = vertical_brush(1, 10, 0.8f, 124.f, 224.f, 3.f, 1.f);
  DeviceSamples s(device_);
  s.upload(h);
  TransferParams prm;
  prm.distance_block = 2;
  const float D0 = 12.f;
  Transfer t(device_, prm);
  ParticleStore p(device_);
  WindowFields before = w.to_host();
  TransferEnv env = env_for(w, D0);
  t.update_distance(s.view(), env);
  TransferRecord rec;
  t.grid_to_particles(p, env, rec);
  t.collect(rec);
  ASSERT_GT(rec.to_particles_count, 0);
  EXPECT_EQ(p.size(), rec.to_particles_count);
  EXPECT_EQ(rec.to_particles_dropped, 0);
  EXPECT_LT(rec.max_closure_error(), 1e-6);
  WindowFields after = w.to_host();
  const double cm = prm.cell_mass();
  double removed = 0;
  const float slack = 2.f * float(prm.distance_block) * std::sqrt(3.f);
  int far_cells = 0, near_cells = 0;
  for (int k = 0; k < 8; ++k)
    for (int j = 0; j < 48; ++j)
      for (int i = 0; i < 48; ++i) {
        const size_t c = (size_t(k) * 48 + j) * 48 + i;
        EXPECT_GE(after[0][c], 0.f);
        removed += double(before[0][c]) - double(after[0][c]);
        const Vec3 centre(float(origin.x + i) + 0.5f, float(origin.y + j) + 0.5f, float(k) + 0.5f);
        const float dist = min_distance(h, centre);
        if (dist > D0 + slack + 2.f) {  // +2: the kernel reaches the next cell
          ++far_cells;
          EXPECT_EQ(after[0][c], before[0][c]) << "cell beyond D0 changed";
        }
        if (k < 2 && dist < D0 - slack - 1.f) {
          ++near_cells;
          EXPECT_LT(after[0][c], 0.5f * before[0][c]) << "cell near the bristles kept its paint";
        }
      }
  EXPECT_GT(far_cells, 1000);
  EXPECT_GT(near_cells, 10);
  const ParticleHost ph = p.to_host();
  const double particle_mass = sum(ph.m);
  EXPECT_NEAR(particle_mass, removed * cm, 1e-6 * particle_mass);
  EXPECT_NEAR(rec.to_particles_from_grid, removed * cm, 1e-6 * particle_mass);
  // Each particle: in a cell that was within D0 (up to the block slack), the cell's colour and
  // oil, and at most its nominal mass rho(p) cell_mass / n^3; the clamp bites at the layer's top.
  // The cells are 0.8 full: 8 candidates of at least 1/27 of a full cell each, not 27.
  const int n = cell_candidate_split(0.8f, prm.candidate_split);
  ASSERT_EQ(n, 2);
  PaintWindowView hv = host_view(before, w);
  int clamped = 0;
  for (size_t k = 0; k < ph.size(); ++k) {
    EXPECT_LE(min_distance(h, ph.x[k]), D0 + slack + 1.f);
    EXPECT_FLOAT_EQ(ph.pigment_y[k], 1.f);
    EXPECT_FLOAT_EQ(ph.oil[k], 0.2f);
    const Vec3 q(ph.x[k].x - float(origin.x), ph.x[k].y - float(origin.y), ph.x[k].z);
    const float nominal = liquid_density_at(hv, q, 0.95f) * float(cm) / float(n * n * n);
    EXPECT_LE(ph.m[k], nominal * (1.f + 1e-5f));
    if (ph.m[k] < nominal * (1.f - 1e-3f)) ++clamped;
  }
  EXPECT_GT(clamped, 0) << "the max(., 0) of Eq. 15 never bit: the test does not cover it";
}

TEST_F(GridParticleTest, ClampOnAnIsolatedCellCreatesNoPaint) {
  PaintWindow w = make_window({16, 16, 8}, {0, 0, 0},
                              [](int i, int j, int k) { return i == 8 && j == 8 && k == 2 ? 0.3f : 0.f; },
                              Vec3(1.f, 0.f, 0.f));
  const TransferParams prm;
  ParticleStore p(device_);
  TransferRecord rec;
  grid_near_one_bristle(w, 8.5f, p, rec);
  EXPECT_EQ(rec.to_particles_count, 8) << "a cell 0.3 full: 8 candidates of at least 1/27 of a cell";
  const WindowFields after = w.to_host();
  const size_t c = (size_t(2) * 16 + 8) * 16 + 8;
  const double removed = (0.3 - double(after[0][c])) * prm.cell_mass();
  const double created = p.total_mass(ws_);
  EXPECT_NEAR(created, removed, 1e-6 * created);
  EXPECT_LT(rec.max_closure_error(), 1e-6);
  EXPECT_GT(after[0][c], 0.f) << "most of the demand fell on empty neighbours: the cell keeps paint";
  for (size_t i = 0; i < after[0].size(); ++i)
    if (i != c) EXPECT_EQ(after[0][i], 0.f);
}

TEST_F(GridParticleTest, CandidateSplitSetsTheParticlesACellGives) {
  // A full cell among full cells, near a bristle: split^3 candidates, one in each sub-cell of the
  // n x n x n split, each carrying its share; the paint they take is the paint the cells lose.
  for (int split = 1; split <= 3; ++split) {
    PaintWindow w = make_window({16, 16, 8}, {0, 0, 0},
                                [](int i, int j, int k) { return i >= 6 && i <= 10 && j >= 6 && j <= 10 && k <= 4 ? 1.f : 0.f; },
                                Vec3(1.f, 0.f, 0.f));
    HostSamples h = vertical_brush(1, 4, 0.8f, 8.5f, 8.5f, 3.f, 1.f);
    DeviceSamples s(device_);
    s.upload(h);
    TransferParams prm;
    prm.candidate_split = split;
    Transfer t(device_, prm);
    ParticleStore p(device_);
    TransferEnv env = env_for(w, 4.f);  // within a distance block of the bristle (the field's resolution)
    const double before = w.total_density(ws_) * prm.cell_mass();
    t.update_distance(s.view(), env);
    TransferRecord rec;
    t.grid_to_particles(p, env, rec);
    t.collect(rec);
    ASSERT_GT(rec.to_particles_count, 0) << split;
    const ParticleHost ph = p.to_host();
    // The particles of the centre cell (8, 8, 2): one per sub-cell.
    std::vector<int> per_sub(size_t(split * split * split), 0);
    int in_cell = 0;
    for (const Vec3& x : ph.x) {
      if (int(std::floor(x.x)) != 8 || int(std::floor(x.y)) != 8 || int(std::floor(x.z)) != 2) continue;
      ++in_cell;
      const int a = int((x.x - 8.f) * float(split)), b = int((x.y - 8.f) * float(split)), c = int((x.z - 2.f) * float(split));
      ++per_sub[size_t((c * split + b) * split + a)];
    }
    EXPECT_EQ(in_cell, split * split * split) << split;
    for (int n : per_sub) EXPECT_EQ(n, 1) << "split " << split;
    const double after = w.total_density(ws_) * prm.cell_mass();
    EXPECT_NEAR(p.total_mass(ws_), before - after, 1e-5 * before) << split;
    EXPECT_LT(rec.max_closure_error(), 1e-6) << split;
  }
}

TEST(GridParticleCandidates, AThinCellGivesFewerCandidatesEachAtLeastAFullCellsShare) {
  for (int n = 1; n <= 3; ++n) {
    EXPECT_EQ(cell_candidate_split(1.f, n), n) << "a full cell: the n^3 of Eq. 15";
    EXPECT_EQ(cell_candidate_split(1e-3f, n), 1) << "a trace: one candidate";
    for (float rho = 0.01f; rho <= 1.f; rho += 0.01f) {
      const int s = cell_candidate_split(rho, n);
      ASSERT_GE(s, 1);
      ASSERT_LE(s, n);
      if (s > 1) EXPECT_GE(rho / float(s * s * s), 1.f / float(n * n * n) * (1.f - 1e-6f)) << rho;
      if (s < n) EXPECT_LT(rho / float((s + 1) * (s + 1) * (s + 1)), 1.f / float(n * n * n)) << rho << ": could split finer";
    }
  }
}

TEST_F(GridParticleTest, ThinPaintNearTheBristlesGivesOneCandidateACell) {
  // A trace (2 % of a cell) and a half-full layer near a bristle: a cell of the trace gives one
  // particle holding its paint, one of the layer 8 (rho 27 >= 8); the books close.
  PaintWindow w = make_window({16, 16, 8}, {0, 0, 0},
                              [](int i, int, int k) { return k > 1 ? 0.f : (i < 8 ? 0.02f : 0.5f); },
                              Vec3(1.f, 0.f, 0.f));
  const TransferParams prm;
  const double before = w.total_density(ws_) * prm.cell_mass();
  ParticleStore p(device_);
  TransferRecord rec;
  grid_near_one_bristle(w, 8.f, p, rec);
  const ParticleHost ph = p.to_host();
  std::map<int, int> per_cell;
  for (const Vec3& x : ph.x) ++per_cell[(int(std::floor(x.z)) * 16 + int(std::floor(x.y))) * 16 + int(std::floor(x.x))];
  int thin = 0, half = 0;
  for (const auto& [c, count] : per_cell) {
    if (c % 16 < 8) {
      EXPECT_EQ(count, 1) << "trace cell " << c;
      ++thin;
    } else {
      EXPECT_EQ(count, 8) << "half-full cell " << c;
      ++half;
    }
  }
  EXPECT_GT(thin, 4);
  EXPECT_GT(half, 4);
  EXPECT_NEAR(p.total_mass(ws_), before - w.total_density(ws_) * prm.cell_mass(), 1e-5 * before);
  EXPECT_LT(rec.max_closure_error(), 1e-6);
}

TEST_F(GridParticleTest, SlowFarParticlesReturnAndMixColour) {
  // Yellow paint, half full, in k = 0..1; blue particles at rest at the centres of k = 1 cells.
  PaintWindow w = make_window({16, 16, 8}, {0, 0, 0}, [](int, int, int k) { return k < 2 ? 0.5f : 0.f; },
                              Vec3(0.f, 1.f, 0.f), 0.2f, 0.1f);
  TransferParams prm;
  prm.kernel_h = 0.5f;  // each particle falls into its own cell only
  const double cm = prm.cell_mass();
  std::vector<Vec3> xs;
  for (int j = 4; j < 12; ++j)
    for (int i = 4; i < 12; ++i) xs.push_back(Vec3(float(i) + 0.5f, float(j) + 0.5f, 1.5f));
  ParticleStore p(device_);
  p.append(particles_at(xs, float(0.5 * cm), Vec3(0.f, 0.f, 1.f), 0.8f));
  // One fast particle stays a particle.
  p.append(particles_at({Vec3(2.5f, 2.5f, 1.5f)}, float(0.5 * cm), Vec3(0.f, 0.f, 1.f), 0.8f, Vec3(0.f, 500.f, 0.f)));
  HostSamples none;
  none.resize(0, 0);
  DeviceSamples s(device_);
  s.upload(none);
  Transfer t(device_, prm);
  TransferEnv env = env_for(w, 10.f);
  const double grid_before = w.total_density(ws_) * cm, part_before = p.total_mass(ws_);
  t.update_distance(s.view(), env);
  TransferRecord rec;
  t.particles_to_grid(p, env);
  t.collect(rec);
  EXPECT_EQ(rec.to_grid_count, int64_t(xs.size()));
  EXPECT_LT(rec.max_closure_error(), 1e-6);
  p.compact(ws_);
  EXPECT_EQ(p.size(), 1);
  EXPECT_NEAR(w.total_density(ws_) * cm + p.total_mass(ws_), grid_before + part_before, 1e-6 * grid_before);
  const WindowFields after = w.to_host();
  for (int j = 4; j < 12; ++j)
    for (int i = 4; i < 12; ++i) {
      const size_t c = (size_t(1) * 16 + j) * 16 + i;
      EXPECT_NEAR(after[0][c], 1.f, 1e-6f);
      const Vec3 ryb(after[1][c], after[2][c], after[3][c]);
      const Vec3 rgb = ryb_to_rgb(ryb);
      EXPECT_GT(rgb.y, rgb.x) << "blue into yellow: green dominates";
      EXPECT_GT(rgb.y, rgb.z);
      const Vec3 ref = color_mix(Vec3(0.f, 1.f, 0.f), Vec3(0.f, 0.f, 1.f), 0.5f, 0.5f);
      EXPECT_NEAR(ryb.y, ref.y, 1e-4f);
      EXPECT_NEAR(ryb.z, ref.z, 1e-4f);
      EXPECT_NEAR(after[4][c], 0.5f, 1e-6f) << "oil: (0.5 * 0.2 + 0.5 * 0.8) / 1";
      EXPECT_NEAR(after[5][c], 0.05f, 1e-6f) << "dryness: (0.5 * 0.1 + 0.5 * 0) / 1";
    }
}

TEST_F(GridParticleTest, ParticlesReturnedInFlightLandOnThePaintBelow) {
  // A wet layer 2 cells deep; particles high above it leave the keep box (the window is about to
  // move off them). Given the paint's surface, they land on it; without it (a Transfer used on
  // its own) they go to the grid where they are, as air-cell paint that nothing moves.
  for (bool with_surface : {true, false}) {
    PaintWindow w = make_window({16, 16, 16}, {0, 0, 0}, [](int, int, int k) { return k < 2 ? 1.f : 0.f; },
                                Vec3(0.f, 1.f, 0.f), 0.2f, 0.f);
    TransferParams prm;
    prm.kernel_h = 0.5f;
    const double cm = prm.cell_mass();
    std::vector<Vec3> xs;
    for (int i = 2; i < 6; ++i) xs.push_back(Vec3(float(i) + 0.5f, 8.5f, 12.5f));
    ParticleStore p(device_);
    p.append(particles_at(xs, float(0.5 * cm), Vec3(0.f, 0.f, 1.f), 0.8f, Vec3(0.f, 0.f, -300.f)));
    Transfer t(device_, prm);
    TransferEnv env = env_for(w, 10.f);
    env.keep = KeepBox::of(Int3{8, 0, 0}, Int3{16, 16, 16});  // x < 8 is leaving
    env.only_leaving = true;  // no distance field: no samples needed
    DeviceBuffer<float> surface;
    surface.set_device(device_);
    surface.resize(16 * 16);
    const std::vector<float> top(16 * 16, 2.f);
    surface.copy_from_host(top.data(), top.size());
    if (with_surface) env.surface = surface.data();
    TransferRecord rec;
    t.particles_to_grid(p, env);
    t.collect(rec);
    EXPECT_EQ(rec.to_grid_count, int64_t(xs.size()));
    const WindowFields after = w.to_host();
    double high = 0, landed = 0;
    for (int k = 0; k < 16; ++k)
      for (int i = 2; i < 6; ++i) {
        const double added = after[0][(size_t(k) * 16 + 8) * 16 + i] - (k < 2 ? 1.0 : 0.0);
        (k >= 4 ? high : landed) += added;
      }
    if (with_surface) {
      EXPECT_NEAR(landed, 2.0, 1e-5) << "four half cells on the layer's top";
      EXPECT_EQ(high, 0.0);
    } else {
      EXPECT_NEAR(high, 2.0, 1e-5) << "without the surface: where they were";
    }
  }
}

TEST_F(GridParticleTest, ParticlesNearTheBristlesStay) {
  PaintWindow w = make_window({32, 32, 8}, {0, 0, 0}, [](int, int, int) { return 0.f; }, Vec3());
  HostSamples h = vertical_brush(1, 8, 0.8f, 16.f, 16.f, 2.f, 1.f);
  DeviceSamples s(device_);
  s.upload(h);
  ParticleStore p(device_);
  p.append(particles_at({Vec3(17.f, 16.f, 1.f), Vec3(20.f, 16.f, 1.f), Vec3(30.5f, 30.5f, 0.5f)}, 1e-10f,
                        Vec3(0.f, 0.f, 1.f)));
  TransferParams prm;
  Transfer t(device_, prm);
  TransferEnv env = env_for(w, 8.f);
  t.update_distance(s.view(), env);
  TransferRecord rec;
  t.particles_to_grid(p, env);
  t.collect(rec);
  EXPECT_EQ(rec.to_grid_count, 1) << "only the particle 20 cells away goes back";
  const std::vector<uint32_t> dead = p.dead.to_host();
  EXPECT_EQ(dead[0], 0u);
  EXPECT_EQ(dead[1], 0u);
  EXPECT_EQ(dead[2], 1u);
}

/// Paint on the canvas beside a loaded brush, with slow particles far from it (they go back)
/// and near it (absorbed or kept): a transfer step moves paint every way.
struct BooksScene {
  Device device;
  PaintWindow w;
  DeviceSamples s;
  TransferParams prm;
  BristleLoad load;
  ParticleStore p;
  Transfer t;
  BooksScene(const Device& d, PaintWindow&& window, int64_t limit, bool with_particles = true)
      : device(d), w(std::move(window)), s(brush(d)), load(d, s.view().count(), prm), p(d, limit), t(d, prm) {
    load.fill(PaintLoad{});  // default: deep blue, 0.8 of the capacity
    if (!with_particles) return;
    std::vector<Vec3> xs;
    for (int i = 0; i < 30; ++i) xs.push_back(Vec3(40.f + 0.2f * i, 40.f, 2.5f));
    for (int i = 0; i < 30; ++i) xs.push_back(Vec3(22.f + 0.1f * i, 24.3f, 1.5f + 0.3f * i));
    p.append(particles_at(xs, 2e-10f, Vec3(1.f, 0.f, 0.f)));
  }
  static DeviceSamples brush(const Device& d) {
    DeviceSamples s(d);
    s.upload(vertical_brush(3, 24, 0.8f, 22.f, 24.f, 1.2f, 2.f, Vec3(40.f, 0.f, 0.f)));
    return s;
  }
  TransferRecord step(Workspace& ws) {
    SampleGrid grid(device);
    const Region r = region_around(p.to_host().x, 12.f);
    grid.build(s.view(), 2.f, r.lo, r.hi, ws);
    grid.query_nearest(p.view(), 12.f);
    TransferEnv env;
    env.paint = w.view();
    env.D0 = 12.f;
    const int64_t before = mem::host_reads();
    TransferRecord rec = t.step(s.view(), load, p, env);
    t.collect(rec);
    step_reads = mem::host_reads() - before;
    return rec;
  }
  int64_t step_reads = 0;  ///< host reads of the last Transfer::step and its collect
  PaintCensus census(Workspace& ws) { return PaintBooks::census(load, p, w.total_density(ws), prm, ws); }
};

TEST_F(GridParticleTest, WholeStepsKeepTheBooks) {
  BooksScene sc(device_, books_window(), 2000000);
  PaintBooks books;
  auto census = [&] { return sc.census(ws_); };
  books.open(census());
  const double start = books.initial_total();
  ASSERT_GT(start, 0.0);
  int64_t moved_any = 0;
  for (int step = 0; step < 6; ++step) {
    TransferRecord rec = sc.step(ws_);
    EXPECT_LT(rec.max_closure_error(), 1e-6) << "step " << step;
    moved_any += rec.absorbed_count + rec.emitted_count + rec.to_grid_count + rec.to_particles_count;
    const double drift = books.record(rec, census());
    EXPECT_LT(std::fabs(drift), 1e-5) << "step " << step;
  }
  EXPECT_GT(books.totals().to_particles_count, 0);
  EXPECT_GT(books.totals().to_grid_count, 0);
  EXPECT_GT(books.totals().emitted_count + books.totals().absorbed_count, 0);
  EXPECT_GT(moved_any, 0);
  EXPECT_LT(books.max_drift(), 1e-5);
  EXPECT_EQ(books.steps().size(), 6u);
}

// The compaction and both batches of new particles share one scan, whose ends come back with the
// step's sums in one host read (collect): the survivors keep their order at the front, the
// emission follows, then Eq. 15's candidates; a store at its limit serves the emission first and
// drops the rest, and the books still close.
TEST_F(GridParticleTest, AStepRemovesAndAddsParticlesWithOneRead) {
  BooksScene with(device_, books_window(), 2000000);
  const std::vector<Vec3> at_start = with.p.to_host().x;
  const TransferRecord first = with.step(ws_);
  EXPECT_EQ(with.step_reads, 1);
  const int64_t kept = with.p.size() - first.emitted_count - first.to_particles_count;
  EXPECT_GT(first.absorbed_count + first.to_grid_count, 0) << "some particles die";
  EXPECT_EQ(kept, 60 - first.absorbed_count - first.to_grid_count);
  // The survivors lead the store, in their order (the transfer moves no particle).
  const std::vector<Vec3> after = with.p.to_host().x;
  size_t next = 0;
  for (int64_t k = 0; k < kept; ++k) {
    while (next < at_start.size() && !(at_start[next].x == after[size_t(k)].x && at_start[next].z == after[size_t(k)].z))
      ++next;
    ASSERT_LT(next, at_start.size()) << "survivor " << k << " out of order";
    ++next;
  }
  // The same step from no particles, with room for all, then at limits that cut the candidates
  // and the emission.
  BooksScene free(device_, books_window(), 2000000, false);
  const TransferRecord all = free.step(ws_);
  ASSERT_GT(all.emitted_count, 4);
  ASSERT_GT(all.to_particles_count, 4);
  const ParticleHost ref = free.p.to_host();
  for (const int64_t limit : {all.emitted_count + all.to_particles_count / 2, all.emitted_count / 2}) {
    BooksScene cut(device_, books_window(), limit, false);
    const double before = cut.census(ws_).total();
    const TransferRecord rec = cut.step(ws_);
    const int64_t emitted = std::min(all.emitted_count, limit);
    EXPECT_EQ(cut.p.size(), limit);
    EXPECT_EQ(rec.emitted_count, emitted);
    EXPECT_EQ(rec.emission_dropped, all.emitted_count - emitted);
    EXPECT_EQ(rec.to_particles_count, limit - emitted);
    EXPECT_EQ(rec.to_particles_dropped, all.to_particles_count - rec.to_particles_count);
    EXPECT_LT(rec.max_closure_error(), 1e-6);
    EXPECT_NEAR(cut.census(ws_).total(), before, 1e-6 * before) << "dropped particles leave their paint where it was";
    const ParticleHost h = cut.p.to_host();
    for (size_t k = 0; k < size_t(limit); ++k) {
      EXPECT_EQ(h.x[k].x, ref.x[k].x) << k;
      EXPECT_EQ(h.x[k].z, ref.x[k].z) << k;
    }
  }
}

}  // namespace
}  // namespace wb::test
