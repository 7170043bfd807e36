// Particle store (paper §4.3, §5): growth, append, flag-and-compact removal.
#include <numeric>
#include <random>

#include "backend_fixture.h"
#include "core/particles/particle_store.h"

namespace wb::test {

class ParticleStoreTest : public BackendTest {};

namespace {
// Particle i carries values derived from id, so survivors can be recognised.
ParticleHost make_batch(int first_id, int n) {
  ParticleHost h;
  h.resize(size_t(n));
  for (int i = 0; i < n; ++i) {
    const float id = float(first_id + i);
    h.x[i] = Vec3(id, 2.f * id, 0.5f);
    h.v[i] = Vec3(-id, 1.f, 3.f);
    h.m[i] = 1e-9f * (1.f + float((first_id + i) % 7));
    h.pigment_r[i] = 0.001f * id;
    h.pigment_y[i] = 0.5f;
    h.pigment_b[i] = 1.f - 0.0001f * id;
    h.oil[i] = 0.25f;
    h.dryness[i] = 0.01f * float((first_id + i) % 100);
  }
  return h;
}
}  // namespace

TEST_F(ParticleStoreTest, GrowsWithoutLosingData) {
  ParticleStore store(device_, 100000);
  int total = 0;
  int64_t last_cap = 0, growths = 0;
  for (int batch = 0; batch < 12; ++batch) {
    const int n = 700 + 300 * batch;
    EXPECT_EQ(store.append(make_batch(total, n)), total);
    total += n;
    if (store.capacity() != last_cap) ++growths, last_cap = store.capacity();
    ASSERT_GE(store.capacity(), store.size());
  }
  EXPECT_LE(growths, 6);  // geometric: a handful of reallocations for 12 appends
  const ParticleHost h = store.to_host();
  const ParticleHost ref = make_batch(0, total);
  ASSERT_EQ(h.size(), size_t(total));
  for (int i = 0; i < total; ++i) {
    ASSERT_EQ(h.x[i].y, ref.x[i].y) << i;
    ASSERT_EQ(h.v[i].x, ref.v[i].x) << i;
    ASSERT_EQ(h.m[i], ref.m[i]) << i;
    ASSERT_EQ(h.pigment_b[i], ref.pigment_b[i]) << i;
    ASSERT_EQ(h.dryness[i], ref.dryness[i]) << i;
  }
  // New particles start with no sample and not dead.
  auto nearest = store.nearest.to_host();
  auto dead = store.dead.to_host();
  for (int i = 0; i < total; ++i) ASSERT_TRUE(nearest[i] == -1 && dead[i] == 0u) << i;
}

TEST_F(ParticleStoreTest, CompactionKeepsSurvivorsAndMass) {
  ParticleStore store(device_);
  const int n = 10000;
  store.append(make_batch(0, n));
  const double mass0 = store.total_mass(ws_);
  std::vector<uint32_t> dead(n, 0u);
  double removed = 0.0;
  const ParticleHost ref = make_batch(0, n);
  for (int i = 0; i < n; ++i)
    if (i % 3 == 0 || (i > 5000 && i < 5100)) dead[i] = 1u, removed += ref.m[i];
  store.dead.copy_range_from_host(dead.data(), 0, n);
  const int64_t gone = store.compact(ws_);
  const int64_t expect_gone = std::accumulate(dead.begin(), dead.end(), int64_t(0));
  EXPECT_EQ(gone, expect_gone);
  EXPECT_EQ(store.size(), n - expect_gone);
  EXPECT_NEAR(store.total_mass(ws_), mass0 - removed, 1e-6 * mass0);
  const ParticleHost h = store.to_host();
  size_t s = 0;
  for (int i = 0; i < n; ++i) {
    if (dead[i]) continue;
    ASSERT_EQ(h.x[s].x, ref.x[i].x) << "survivor " << s << " should be particle " << i;
    ASSERT_EQ(h.v[s].x, ref.v[i].x);
    ASSERT_EQ(h.m[s], ref.m[i]);
    ASSERT_EQ(h.pigment_r[s], ref.pigment_r[i]);
    ASSERT_EQ(h.dryness[s], ref.dryness[i]);
    ++s;
  }
  for (uint32_t d : store.dead.to_host()) ASSERT_EQ(d, 0u);
  // Compacting again without flags removes nothing.
  EXPECT_EQ(store.compact(ws_), 0);
  EXPECT_EQ(store.size(), n - expect_gone);
  // Removing everything leaves an empty store.
  std::vector<uint32_t> all(size_t(store.size()), 1u);
  store.dead.copy_range_from_host(all.data(), 0, all.size());
  store.compact(ws_);
  EXPECT_EQ(store.size(), 0);
  EXPECT_EQ(store.total_mass(ws_), 0.0);
}

TEST_F(ParticleStoreTest, LimitAndBadBatches) {
  ParticleStore store(device_, 2000);
  store.append(make_batch(0, 1500));
  EXPECT_THROW(store.append(make_batch(0, 501)), Error);
  EXPECT_EQ(store.size(), 1500);
  EXPECT_LE(store.capacity(), 2000);
  ParticleHost bad = make_batch(0, 10);
  bad.oil.pop_back();
  EXPECT_THROW(store.append(bad), Error);
  EXPECT_THROW(store.set_limit(1000), Error);
  EXPECT_THROW(ParticleStore(device_, 0), Error);
  EXPECT_EQ(ParticleStore(device_).limit(), 2000000);
}

}  // namespace wb::test

namespace wb::test {

TEST_F(ParticleStoreTest, SortByCellOrdersByHalfCellAndKeepsEachParticleWhole) {
  // 3000 particles over a 20 x 16 x 8 window at (100, 50, 0) and a few cells around it (those
  // outside go last), each carrying its index in its pigment so that it can be followed.
  const Int3 origin{100, 50, 0}, dims{20, 16, 8};
  std::mt19937 rng(4);
  std::uniform_real_distribution<float> U(0.f, 1.f);
  const int n = 3000;
  ParticleHost h;
  h.resize(n);
  for (int i = 0; i < n; ++i) {
    h.x[i] = Vec3(97.f + 26.f * U(rng), 47.f + 22.f * U(rng), -2.f + 12.f * U(rng));
    h.v[i] = Vec3(float(i), 0.f, 1.f);
    h.m[i] = 1e-9f;
    h.pigment_r[i] = float(i);
  }
  ParticleStore store(device_);
  store.append(h);
  Workspace ws(device_);
  store.sort_by_cell(origin, dims, ws);
  ASSERT_EQ(store.size(), n);
  const ParticleHost s = store.to_host();
  auto key = [&](Vec3 x) -> int64_t {
    const float q[3] = {x.x - origin.x, x.y - origin.y, x.z - origin.z};
    const int e[3] = {dims.x, dims.y, dims.z};
    int64_t k = 0;
    for (int a = 2; a >= 0; --a) {
      if (!(q[a] >= 0.f && q[a] < float(e[a]))) return int64_t(8) * dims.x * dims.y * dims.z;
      k = k * (2 * e[a]) + int64_t(2.f * q[a]);
    }
    return k;
  };
  std::vector<int> seen(n, 0);
  int outside = 0;
  for (int i = 0; i < n; ++i) {
    const int id = int(s.pigment_r[i]);
    ASSERT_GE(id, 0);
    ASSERT_LT(id, n);
    ++seen[id];
    // Every field moved with its particle.
    EXPECT_EQ(s.x[i].x, h.x[id].x);
    EXPECT_EQ(s.x[i].z, h.x[id].z);
    EXPECT_EQ(s.v[i].x, float(id));
    outside += key(s.x[i]) == int64_t(8) * dims.x * dims.y * dims.z;
    if (i == 0) continue;
    const int64_t k0 = key(s.x[i - 1]), k1 = key(s.x[i]);
    ASSERT_LE(k0, k1) << "half cells in order, x fastest: " << i;
    if (k0 == k1) EXPECT_LT(int(s.pigment_r[i - 1]), id) << "stable within a half cell";
  }
  for (int id = 0; id < n; ++id) EXPECT_EQ(seen[id], 1) << id;
  EXPECT_GT(outside, 100);
  EXPECT_LT(outside, n - 100);
}

}  // namespace wb::test
