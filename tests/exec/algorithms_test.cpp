// The execution primitives on the backend under test: sort, scan, reductions,
// atomics under contention, parallel_for coverage.
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>

#include "backend_fixture.h"
#include "core/exec/algorithms.h"
#include "core/exec/buffer.h"
#include "core/exec/graph.h"
#include "core/exec/memory.h"
#include "core/exec/selftest.h"

namespace wb::test {

class AlgorithmsTest : public BackendTest {};

TEST_F(AlgorithmsTest, SortByKeyMatchesStableSort) {
  for (int64_t n : {0, 1, 7, 1000, 210000}) {
    std::mt19937 rng(unsigned(n) + 1);
    std::vector<uint32_t> keys(n), vals(n);
    for (int64_t i = 0; i < n; ++i) {
      keys[i] = rng() % 50000u;  // many duplicates, 16 key bits
      vals[i] = uint32_t(i);
    }
    DeviceBuffer<uint32_t> dk(device_, n), dv(device_, n);
    dk.copy_from_host(keys);
    dv.copy_from_host(vals);
    sort_by_key(device_, dk.data(), dv.data(), n, 16, ws_);
    std::vector<uint32_t> idx(n);
    std::iota(idx.begin(), idx.end(), 0u);
    std::stable_sort(idx.begin(), idx.end(), [&](uint32_t a, uint32_t b) { return keys[a] < keys[b]; });
    auto gk = dk.to_host(), gv = dv.to_host();
    for (int64_t i = 0; i < n; ++i) {
      ASSERT_EQ(gk[i], keys[idx[i]]) << "n=" << n << " i=" << i;
      ASSERT_EQ(gv[i], idx[i]) << "stability, n=" << n << " i=" << i;
    }
  }
}

TEST_F(AlgorithmsTest, SortFullWidthKeys) {
  const int64_t n = 150001;  // over the CPU's threshold for splitting the passes
  std::mt19937 rng(3);
  std::vector<uint32_t> keys(n), vals(n);
  for (int64_t i = 0; i < n; ++i) keys[i] = rng(), vals[i] = uint32_t(i);
  DeviceBuffer<uint32_t> dk(device_, n), dv(device_, n);
  dk.copy_from_host(keys);
  dv.copy_from_host(vals);
  sort_by_key(device_, dk.data(), dv.data(), n, 32, ws_);
  auto gk = dk.to_host(), gv = dv.to_host();
  EXPECT_TRUE(std::is_sorted(gk.begin(), gk.end()));
  for (int64_t i = 0; i < n; ++i) EXPECT_EQ(keys[gv[i]], gk[i]);
}

TEST_F(AlgorithmsTest, ExclusiveScanInPlaceAndTotal) {
  for (int64_t n : {1, 5, 100000, 300007}) {
    std::vector<uint32_t> in(n);
    for (int64_t i = 0; i < n; ++i) in[i] = uint32_t(i % 7);
    DeviceBuffer<uint32_t> d(device_, n);
    d.copy_from_host(in);
    const uint32_t total = exclusive_scan(device_, d.data(), d.data(), n, ws_);
    auto out = d.to_host();
    uint32_t run = 0;
    for (int64_t i = 0; i < n; ++i) {
      ASSERT_EQ(out[i], run);
      run += in[i];
    }
    EXPECT_EQ(total, run);
  }
}

TEST_F(AlgorithmsTest, ReductionsAndNonFinite) {
  const int64_t n = 300001;
  std::vector<float> v(n);
  double expect = 0.0;
  for (int64_t i = 0; i < n; ++i) {
    v[i] = float((i * 37) % 1001) * 1e-3f - 0.5f;
    expect += double(v[i]);
  }
  DeviceBuffer<float> d(device_, n);
  d.copy_from_host(v);
  EXPECT_NEAR(reduce_sum(device_, d.data(), n, ws_), expect, 1e-6 * n);
  EXPECT_FLOAT_EQ(reduce_max(device_, d.data(), n, ws_), *std::max_element(v.begin(), v.end()));
  EXPECT_FLOAT_EQ(reduce_min(device_, d.data(), n, ws_), *std::min_element(v.begin(), v.end()));
  EXPECT_EQ(count_nonfinite(device_, d.data(), n, ws_), 0);
  v[10] = std::numeric_limits<float>::quiet_NaN();
  v[n - 1] = std::numeric_limits<float>::infinity();
  d.copy_from_host(v);
  EXPECT_EQ(count_nonfinite(device_, d.data(), n, ws_), 2);
}

TEST_F(AlgorithmsTest, NonfiniteCountsOfManyArraysInOneLaunch) {
  // Arrays of very different lengths (empty, one element, many blocks' worth), NaN and both
  // infinities planted at known places; the counts stay on the device, in one launch.
  const std::vector<int64_t> sizes = {0, 1, 5, 300001, 77, 1 << 20};
  std::vector<DeviceBuffer<float>> bufs;
  std::vector<int64_t> expect;
  FloatArrays all;
  for (size_t k = 0; k < sizes.size(); ++k) {
    std::vector<float> v(size_t(sizes[k]), 0.5f);
    int64_t bad = 0;
    for (int64_t i = int64_t(k) % 3; i < sizes[k]; i += 9973 + int64_t(k)) {
      v[size_t(i)] = i % 3 == 0 ? std::numeric_limits<float>::quiet_NaN()
                                : (i % 3 == 1 ? 1.f : -1.f) * std::numeric_limits<float>::infinity();
      ++bad;
    }
    bufs.emplace_back(device_, std::max<size_t>(v.size(), 1));
    if (!v.empty()) bufs.back().copy_from_host(v);
    all.add(bufs.back().data(), sizes[k]);
    expect.push_back(bad);
  }
  DeviceBuffer<int64_t> out(device_, sizes.size());
  std::vector<int64_t> poison(sizes.size(), -7);
  out.copy_from_host(poison);
  const int64_t reads = mem::host_reads(), launches = mem::launches();
  count_nonfinite_each_into(device_, all, out.data(), ws_);
  EXPECT_EQ(mem::host_reads(), reads);
  EXPECT_EQ(mem::launches(), launches + 1);
  EXPECT_EQ(out.to_host(), expect);
  EXPECT_GT(expect[5], 100) << "the long array has many planted values";
  FloatArrays too_many;
  for (int k = 0; k < FloatArrays::kMax; ++k) too_many.add(bufs[1].data(), 1);
  EXPECT_THROW(too_many.add(bufs[1].data(), 1), Error);
}

TEST_F(AlgorithmsTest, SumIntoDeviceMemoryIsNotAHostRead) {
  // reduce_sum_into leaves its result on the device; every primitive that returns a value to
  // the host counts one host read, as does a copy to the host.
  const int64_t n = 100003;
  std::vector<float> v(static_cast<size_t>(n));
  for (int64_t i = 0; i < n; ++i) v[size_t(i)] = float(i % 7) - 3.f + 0.25f;
  DeviceBuffer<float> d(device_, static_cast<size_t>(n));
  d.copy_from_host(v);
  DeviceBuffer<double> out(device_, 3);
  out.fill_zero();
  const int64_t r0 = mem::host_reads();
  reduce_sum_into(device_, d.data(), n, out.data(), ws_);
  reduce_sum_into(device_, d.data(), 0, out.data() + 1, ws_);
  reduce_sum_add_into(device_, d.data(), n, out.data() + 2, ws_);  // accumulates: twice the sum
  reduce_sum_add_into(device_, d.data(), n, out.data() + 2, ws_);
  DeviceBuffer<float> top(device_, 1);
  reduce_max_into(device_, d.data(), n, top.data(), ws_);
  EXPECT_EQ(mem::host_reads(), r0);
  const double direct = reduce_sum(device_, d.data(), n, ws_);
  EXPECT_EQ(mem::host_reads(), r0 + 1);
  const std::vector<double> h = out.to_host();
  EXPECT_EQ(mem::host_reads(), r0 + 2);
  EXPECT_FLOAT_EQ(top.to_host()[0], *std::max_element(v.begin(), v.end()));
  double expect = 0.0;
  for (float x : v) expect += double(x);
  EXPECT_NEAR(h[0], expect, 1e-9 * double(n));
  EXPECT_NEAR(h[0], direct, 1e-9 * double(n));
  EXPECT_EQ(h[1], 0.0) << "the sum of nothing";
  EXPECT_NEAR(h[2], 2.0 * expect, 2e-9 * double(n));
}

TEST_F(AlgorithmsTest, FloatAtomicsUnderContention) {
  // 1M increments onto 4 addresses: every one must land.
  const int64_t n = 1 << 20;
  DeviceBuffer<float> acc(device_, 4);
  DeviceBuffer<int32_t> iacc(device_, 2);
  acc.fill_zero();
  iacc.fill_zero();
  selftest_atomic_contention(device_, acc.data(), iacc.data(), n);
  auto a = acc.to_host();
  auto ia = iacc.to_host();
  for (int k = 0; k < 4; ++k) EXPECT_FLOAT_EQ(a[k], float(n / 4));  // exact: integers below 2^24
  EXPECT_EQ(ia[0], n);
  EXPECT_EQ(ia[1], n - 1);  // atomic max of the indices
}

TEST_F(AlgorithmsTest, ParallelForVisitsEachIndexOnce) {
  const int64_t n = 100003;
  DeviceBuffer<int32_t> hits(device_, n);
  hits.fill_zero();
  selftest_count_visits(device_, hits.data(), n);
  auto h = hits.to_host();
  for (int64_t i = 0; i < n; ++i) ASSERT_EQ(h[i], 1) << i;
}

TEST_F(AlgorithmsTest, SumFormedInThePassIsTheSumAndRepeatsBitForBit) {
  // parallel_sum_count: the pass writes the first *count entries and no more, its sum is the
  // sum, and launches in a row (the ticket wrapping each time) give the same bits: the viscous
  // CG relies on that to keep r.z unchanged past convergence.
  DeviceBuffer<double> partial(device_, kSumBlocks);
  DeviceBuffer<uint32_t> ticket(device_, 1);
  ticket.fill_zero();
  const SumScratch scratch{partial.data(), ticket.data()};
  DeviceBuffer<int64_t> count(device_, 1);
  for (int64_t capacity : {int64_t(1), int64_t(300), int64_t(100003), int64_t(700001)}) {
    for (int64_t n : {int64_t(0), capacity / 2, capacity, capacity + 5}) {
      const int64_t used = std::min(n, capacity);
      std::vector<double> poison(size_t(capacity) + 1, -999.0);
      DeviceBuffer<double> x(device_, size_t(capacity) + 1);
      x.copy_from_host(poison);
      count.copy_from_host(&n, 1);
      constexpr int kRuns = 40;
      DeviceBuffer<double> out(device_, kRuns);
      out.fill_zero();
      const int64_t reads = mem::host_reads();
      for (int r = 0; r < kRuns; ++r) selftest_sum_squares(device_, count.data(), capacity, x.data(), out.data() + r, scratch);
      EXPECT_EQ(mem::host_reads(), reads) << "the sum stays on the device";
      const std::vector<double> got = out.to_host(), xs = x.to_host();
      long double expect = 0.0L;
      for (int64_t i = 0; i < used; ++i) {
        const double v = double(i % 97) * 0.125 - 3.3;  // the product exact: no FMA's rounding
        ASSERT_EQ(xs[size_t(i)], v) << "capacity " << capacity << " entry " << i;
        expect += (long double)v * v;
      }
      for (int64_t i = used; i <= capacity; ++i) ASSERT_EQ(xs[size_t(i)], -999.0) << "written past the count: " << i;
      // Sums of up to 7e5 terms in double, in the backend's order: within 1e-10 of the exact.
      EXPECT_NEAR(got[0], double(expect), 1e-10 * std::max(double(expect), 1.0)) << "capacity " << capacity << " count " << n;
      for (int r = 1; r < kRuns; ++r) ASSERT_EQ(got[size_t(r)], got[0]) << "run " << r << ", capacity " << capacity;
    }
  }
  EXPECT_EQ(ticket.to_host()[0], 0u) << "the ticket is back to zero between launches";
}

TEST_F(AlgorithmsTest, LaunchGraphReplaysItsLaunchesAndRecordsAgainForANewKey) {
  // The same launches run directly or through a LaunchGraph give the same results, counted as
  // the same launches; a new key (other buffers) records again, and the old buffers are left.
  const int64_t n = 50000;
  DeviceBuffer<int32_t> hits_a(device_, n), hits_b(device_, n);
  hits_a.fill_zero();
  hits_b.fill_zero();
  DeviceBuffer<double> partial(device_, kSumBlocks), x(device_, n), out(device_, 2);
  DeviceBuffer<uint32_t> ticket(device_, 1);
  DeviceBuffer<int64_t> count(device_, 1);
  ticket.fill_zero();
  out.fill_zero();
  count.copy_from_host(&n, 1);
  const SumScratch scratch{partial.data(), ticket.data()};
  LaunchGraph graph;
  const auto launches = [&](DeviceBuffer<int32_t>& hits, int slot) {
    selftest_count_visits(device_, hits.data(), n);
    selftest_sum_squares(device_, count.data(), n, x.data(), out.data() + slot, scratch);
  };
  const int64_t before = mem::launches();
  // A key's first run is direct, its second recorded, the rest replays.
  for (int r = 0; r < 5; ++r) graph.run(device_, launch_key({launch_key_of(hits_a.data())}), [&] { launches(hits_a, 0); });
  EXPECT_EQ(mem::launches() - before, 10) << "each replay counts the launches it holds";
  graph.run(device_, launch_key({launch_key_of(hits_b.data())}), [&] { launches(hits_b, 1); });
  const std::vector<int32_t> a = hits_a.to_host(), b = hits_b.to_host();
  for (int64_t i = 0; i < n; ++i) {
    ASSERT_EQ(a[size_t(i)], 5) << i;
    ASSERT_EQ(b[size_t(i)], 1) << i;
  }
  double expect = 0.0;
  for (int64_t i = 0; i < n; ++i) expect += (double(i % 97) * 0.125 - 3.3) * (double(i % 97) * 0.125 - 3.3);
  const std::vector<double> sums = out.to_host();
  EXPECT_NEAR(sums[0], expect, 1e-10 * expect);
  EXPECT_EQ(sums[1], sums[0]);
}

TEST_F(AlgorithmsTest, LaunchLoopRunsItsBodyUntilTheFlagStopsItWithoutAHostRead) {
  // A body that visits every element and counts down: it runs as many times as the count says,
  // whichever backend, and the host reads nothing (CUDA: a conditional while node, recorded at
  // the first run).
  const int64_t n = 50000;
  DeviceBuffer<int32_t> hits(device_, n);
  hits.fill_zero();
  DeviceBuffer<int64_t> left(device_, 1);
  DeviceBuffer<uint32_t> go(device_, 1);
  LaunchLoop loop;
  const uint64_t key = launch_key({launch_key_of(hits.data()), launch_key_of(left.data())});
  int64_t expect = 0;
  for (const int64_t passes : {int64_t(3), int64_t(7), int64_t(1), int64_t(12)}) {
    left.copy_from_host(&passes, 1);
    const int64_t reads = mem::host_reads();
    loop.run(device_, key, go.data(), [&] {
      selftest_count_visits(device_, hits.data(), n);
      selftest_count_down(device_, left.data(), go.data());
    });
    const int64_t made = mem::host_reads() - reads;
    expect += passes;
    EXPECT_EQ(made, 0) << passes << " passes";
    const std::vector<int32_t> h = hits.to_host();
    for (int64_t i = 0; i < n; i += 997) ASSERT_EQ(h[size_t(i)], expect) << i << " after " << passes << " passes";
    EXPECT_EQ(left.to_host()[0], 0);
  }
}

TEST(DeviceTest, ParseAndPrint) {
  EXPECT_EQ(Device::parse("cpu").to_string(), "cpu");
  EXPECT_TRUE(Device::parse("cpu") == Device(DeviceType::CPU));
  EXPECT_THROW(Device::parse("gpu"), Error);
  EXPECT_THROW(Device::parse("cuda:x"), Error);
  if (cuda_device_count() == 0) EXPECT_THROW(Device::parse("cuda"), Error);
  const Device a = Device::parse("auto");
  EXPECT_EQ(a.is_cuda(), cuda_compiled() && cuda_device_count() > 0);
  EXPECT_GE(list_devices().size(), 1u);
}

TEST(ErrorTest, MessageForTheUserHasNoSourceLocation) {
  try {
    WB_THROW("the file is not a painting");
  } catch (const Error& e) {
    EXPECT_EQ(e.message(), "the file is not a painting");
    EXPECT_EQ(user_message(e), "the file is not a painting");
    EXPECT_NE(std::string(e.what()).find(".cpp:"), std::string::npos) << "logs keep where it was raised";
    return;
  }
  FAIL() << "WB_THROW did not throw";
}

}  // namespace wb::test
