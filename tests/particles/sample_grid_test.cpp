// Sample grid (paper §6, Green 2010): the nearest-sample query against brute force.
#include <random>

#include "backend_fixture.h"
#include "core/particles/sample_grid.h"
#include "core/particles/particle_store.h"
#include "particles/sample_fixture.h"

namespace wb::test {

class SampleGridTest : public BackendTest {};

namespace {
ParticleHost particles_at(const std::vector<Vec3>& x) {
  ParticleHost h;
  h.resize(x.size());
  h.x = x;
  return h;
}
}  // namespace

TEST_F(SampleGridTest, NearestSampleEqualsBruteForce) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> U(0.f, 1.f);
  // 40 curved bristles of 64 samples in an 80-cell box, plus particles spread around it
  // (some beyond every range), so both hits and misses are exercised.
  HostSamples hs;
  hs.resize(40, 64);
  for (int b = 0; b < 40; ++b) {
    Vec3 p(1000.f + 60.f * U(rng), 2000.f + 60.f * U(rng), 20.f + 60.f * U(rng));
    Vec3 dir = normalize(Vec3(U(rng) - 0.5f, U(rng) - 0.5f, -1.f));
    for (int j = 0; j < 64; ++j) {
      hs.x[size_t(b) * 64 + j] = p;
      dir = normalize(dir + Vec3(U(rng) - 0.5f, U(rng) - 0.5f, U(rng) - 0.5f) * 0.2f);
      p += dir * 0.8f;
    }
  }
  std::vector<Vec3> px(8000);
  for (auto& x : px) x = Vec3(960.f + 140.f * U(rng), 1960.f + 140.f * U(rng), -20.f + 140.f * U(rng));
  // As many again within a cell or two of a sample, as most particles of a stroke lie.
  for (int k = 0; k < 8000; ++k)
    px.push_back(hs.x[size_t(k * 7) % hs.x.size()] + Vec3(U(rng) - 0.5f, U(rng) - 0.5f, U(rng) - 0.5f) * 3.f);
  DeviceSamples ds(device_);
  ds.upload(hs);
  ParticleStore store(device_);
  store.append(particles_at(px));
  SampleGrid grid(device_);
  // Ranges within a cell and over many cells, as the absorption's load sphere, Eq. 10's D1
  // and D0 use them.
  for (float h : {2.f, 4.f, 15.f}) {
    for (float range : {0.75f, 5.f, 15.f, 50.f}) {
      const Region r = region_around(px, range);
      grid.build(ds.view(), h, r.lo, r.hi, ws_);
      grid.query_nearest(store.view(), range);
      const auto nearest = store.nearest.to_host();
      const auto dB = store.d_B.to_host();
      int misses = 0;
      for (size_t k = 0; k < px.size(); ++k) {
        const NearestSample ref = nearest_sample_brute_force(hs.x.data(), int64_t(hs.x.size()), px[k], range);
        ASSERT_EQ(nearest[k], ref.index) << "h=" << h << " range=" << range << " particle " << k;
        ASSERT_NEAR(dB[k], ref.dist, 1e-5f * std::max(1.f, ref.dist)) << "h=" << h << " particle " << k;
        misses += ref.index < 0;
      }
      // The set-up must exercise both outcomes.
      EXPECT_GT(misses, 100);
      if (range >= 15.f) EXPECT_LT(misses, int(px.size()) - 100);
    }
  }
  // A region that cuts the brush: the particles of one corner, the region their box grown by
  // the range. The samples outside it are not filed, and the answers stay exact.
  std::vector<Vec3> corner;
  for (const Vec3& x : px)
    if (x.x < 1020.f && x.y < 2030.f) corner.push_back(x);
  ASSERT_GT(corner.size(), 500u);
  ParticleStore some(device_);
  some.append(particles_at(corner));
  const Region r = region_around(corner, 15.f);
  grid.build(ds.view(), 2.f, r.lo, r.hi, ws_);
  EXPECT_LT(grid.cell_capacity(), 60 * 60 * 60) << "the region's cells, not the samples'";
  grid.query_nearest(some.view(), 15.f);
  const auto nearest = some.nearest.to_host();
  int hits = 0;
  for (size_t k = 0; k < corner.size(); ++k) {
    const NearestSample ref = nearest_sample_brute_force(hs.x.data(), int64_t(hs.x.size()), corner[k], 15.f);
    ASSERT_EQ(nearest[k], ref.index) << "corner particle " << k;
    hits += ref.index >= 0;
  }
  EXPECT_GT(hits, 100);
}

TEST_F(SampleGridTest, NeighbouringParticlesQueriedTogetherEqualBruteForce) {
  // The CPU queries runs of neighbouring particles together (kQueryLanes): particles sorted by
  // cell, many to a cell, as the simulator keeps them, with exact ties (a bristle's samples
  // filed twice: the lower index wins) and non-finite points among them.
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> U(0.f, 1.f);
  HostSamples hs;
  hs.resize(24, 32);
  for (int b = 0; b < 24; ++b) {
    Vec3 p(500.f + 30.f * U(rng), 500.f + 30.f * U(rng), 10.f + 20.f * U(rng));
    for (int j = 0; j < 32; ++j) {
      hs.x[size_t(b) * 32 + j] = b >= 20 ? hs.x[size_t(b - 20) * 32 + j] : p;  // 20..23 repeat 0..3
      p += normalize(Vec3(U(rng) - 0.5f, U(rng) - 0.5f, -1.f)) * 0.8f;
    }
  }
  std::vector<Vec3> px;
  for (int k = 0; k < 16000; ++k) {
    // Dense clusters (several particles a cell) around samples and sparse ones between them.
    const Vec3 c = hs.x[size_t(k / 40 * 5) % hs.x.size()];
    px.push_back(c + Vec3(U(rng) - 0.5f, U(rng) - 0.5f, U(rng) - 0.5f) * (k % 4 == 0 ? 30.f : 2.5f));
  }
  px[100] = Vec3(NAN, 0.f, 0.f);
  px[2001] = Vec3(INFINITY, 500.f, 10.f);
  DeviceSamples ds(device_);
  ds.upload(hs);
  ParticleStore store(device_);
  store.append(particles_at(px));
  store.sort_by_cell(Int3(450, 450, -40), Int3(140, 140, 120), ws_);
  std::vector<Vec3> sorted = store.x.to_host();
  sorted.resize(px.size());  // the buffer may hold more than the particles
  SampleGrid grid(device_);
  int ties = 0;
  for (float h : {1.f, 2.f, 4.f}) {
    for (float range : {1.f, 6.f, 15.f}) {
      grid.build(ds.view(), h, Vec3(420.f, 420.f, -60.f), Vec3(620.f, 620.f, 120.f), ws_);
      grid.query_nearest(store.view(), range);
      const auto nearest = store.nearest.to_host();
      const auto dB = store.d_B.to_host();
      for (size_t k = 0; k < sorted.size(); ++k) {
        const NearestSample ref = nearest_sample_brute_force(hs.x.data(), int64_t(hs.x.size()), sorted[k], range);
        ASSERT_EQ(nearest[k], ref.index) << "h=" << h << " range=" << range << " particle " << k;
        ASSERT_NEAR(dB[k], ref.dist, 1e-5f * std::max(1.f, ref.dist)) << "h=" << h << " particle " << k;
        ties += ref.index >= 0 && ref.index < 4 * 32;  // its twin 20 bristles on is as near
      }
    }
  }
  EXPECT_GT(ties, 1000);
}

TEST_F(SampleGridTest, RewindFilesStartOfStepPositions) {
  // A bristle that moved by v dt: with rewind the particle at the old place is on it.
  HostSamples hs;
  hs.resize(1, 32);
  straight_bristle(hs, 0, Vec3(110.f, 100.f, 40.f), Vec3(0, 1, 0), Vec3(0, 0, 1), 0.8f, Vec3(600.f, 0, 0), Vec3());
  DeviceSamples ds(device_);
  ds.upload(hs);
  ParticleStore store(device_);
  store.append(particles_at({Vec3(100.f, 108.f, 40.f)}));
  SampleGrid grid(device_);
  const Region r = region_around({Vec3(100.f, 108.f, 40.f)}, 50.f);
  grid.build(ds.view(), 4.f, r.lo, r.hi, ws_);
  grid.query_nearest(store.view(), 50.f);
  EXPECT_NEAR(store.d_B.to_host()[0], 10.f, 1e-4f);
  grid.build(ds.view(), 4.f, r.lo, r.hi, ws_, 1.f / 60.f);
  grid.query_nearest(store.view(), 50.f);
  EXPECT_NEAR(store.d_B.to_host()[0], 0.f, 1e-4f);
  EXPECT_EQ(store.nearest.to_host()[0], 10);
}

TEST_F(SampleGridTest, EmptySamplesAndBadInput) {
  HostSamples hs;
  hs.resize(0, 128);
  DeviceSamples ds(device_);
  ds.upload(hs);
  ParticleStore store(device_);
  store.append(particles_at({Vec3(1, 2, 3), Vec3(4, 5, 6)}));
  SampleGrid grid(device_);
  EXPECT_THROW(grid.query_nearest(store.view(), 15.f), Error);  // not built
  const Region r = region_around({Vec3(1, 2, 3), Vec3(4, 5, 6)}, 15.f);
  grid.build(ds.view(), 4.f, r.lo, r.hi, ws_);
  grid.query_nearest(store.view(), 15.f);
  for (int k = 0; k < 2; ++k) {
    EXPECT_EQ(store.nearest.to_host()[k], -1);
    EXPECT_EQ(store.d_B.to_host()[k], 15.f);
  }
  EXPECT_THROW(grid.build(ds.view(), 0.f, r.lo, r.hi, ws_), Error);
  EXPECT_THROW(grid.build(ds.view(), 4.f, r.hi, r.lo, ws_), Error);                         // empty region
  EXPECT_THROW(grid.build(ds.view(), 0.01f, Vec3(-1e4f, -1e4f, -1e4f), Vec3(1e4f, 1e4f, 1e4f), ws_), Error);         // too many cells
  EXPECT_THROW(grid.query_nearest(store.view(), -1.f), Error);
}

}  // namespace wb::test
