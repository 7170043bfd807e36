// CPU (OpenMP) implementations of the device-wide primitives.
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include "core/exec/algorithms.h"
#include "core/exec/parallel_for.h"

namespace wb::cpu {

namespace {
// The most threads the sort and the scan split their work over (their per-thread tables).
constexpr int kMaxSlices = 64;
// Up to a sum's serial size a primitive runs on one thread: a team's start costs more than it saves.
int threads_for(int64_t n) { return n > kMinParallelSum ? std::min(omp_get_max_threads(), kMaxSlices) : 1; }
}  // namespace

// LSD radix sort, 8 bits a pass, only as many passes as key_bits needs. A generic
// comparison sort over OpenMP is an order of magnitude slower on the per-step path. Each pass
// counts each thread's slice, and each thread scatters its slice after the slices before it in
// every digit, so the sort is stable and its result the same for any number of threads.
void sort_by_key(uint32_t* keys, uint32_t* values, int64_t n, int key_bits, Workspace& ws) {
  check_sort_args(n, key_bits);
  if (n <= 1) return;
  const int passes = std::max(1, (std::min(key_bits, 32) + 7) / 8);
  const int threads = threads_for(n);
  auto* scratch = static_cast<uint32_t*>(ws.get(size_t(n) * 2 * sizeof(uint32_t) + sizeof(size_t) * 256 * kMaxSlices));
  auto* count = reinterpret_cast<size_t*>(scratch + 2 * n);  // 256 a thread; 2n uint32 keep it aligned
  uint32_t* k_src = keys;
  uint32_t* v_src = values;
  uint32_t* k_dst = scratch;
  uint32_t* v_dst = scratch + n;
  for (int pass = 0; pass < passes; ++pass) {
    const int shift = pass * 8;
#pragma omp parallel num_threads(threads)
    {
      const int t = omp_get_thread_num(), nt = omp_get_num_threads();
      int64_t lo, hi;
      thread_slice(n, t, nt, lo, hi);
      size_t* c = count + 256 * t;
      std::fill(c, c + 256, size_t(0));
      for (int64_t i = lo; i < hi; ++i) ++c[(k_src[i] >> shift) & 0xFFu];
#pragma omp barrier
#pragma omp single
      {
        size_t at = 0;  // digit by digit, thread by thread: each slice's first slot of each digit
        for (int b = 0; b < 256; ++b)
          for (int u = 0; u < nt; ++u) {
            const size_t m = count[256 * u + b];
            count[256 * u + b] = at;
            at += m;
          }
      }
      for (int64_t i = lo; i < hi; ++i) {
        const size_t dst = c[(k_src[i] >> shift) & 0xFFu]++;
        k_dst[dst] = k_src[i];
        v_dst[dst] = v_src[i];
      }
    }
    std::swap(k_src, k_dst);
    std::swap(v_src, v_dst);
  }
  if (k_src != keys) {
    std::memcpy(keys, k_src, size_t(n) * sizeof(uint32_t));
    std::memcpy(values, v_src, size_t(n) * sizeof(uint32_t));
  }
}

// Two passes over the slices: each thread sums its own, then scans it from the sum of those
// before it. In place (in == out) too: a slice's elements are read before they are written.
uint32_t exclusive_scan(const uint32_t* in, uint32_t* out, int64_t n, Workspace&) {
  uint32_t part[kMaxSlices + 1] = {}, total = 0;
#pragma omp parallel num_threads(threads_for(n))
  {
    const int t = omp_get_thread_num(), nt = omp_get_num_threads();
    int64_t lo, hi;
    thread_slice(n, t, nt, lo, hi);
    uint32_t sum = 0;
    for (int64_t i = lo; i < hi; ++i) sum += in[i];
    part[t + 1] = sum;
#pragma omp barrier
#pragma omp single
    {
      for (int u = 0; u < nt; ++u) part[u + 1] += part[u];
      total = part[nt];
    }
    uint32_t running = part[t];
    for (int64_t i = lo; i < hi; ++i) {
      const uint32_t v = in[i];
      out[i] = running;
      running += v;
    }
  }
  return total;
}

void exclusive_scan_into(const uint32_t* in, uint32_t* out, int64_t n, Workspace& ws) { exclusive_scan(in, out, n, ws); }

double reduce_sum(const float* in, int64_t n, Workspace&) {
  // simd: each thread keeps a vector of partial sums, so the loop runs at the memory's speed and
  // not at one add's latency an element; the order is fixed for a given thread count.
  double s = 0.0;
#pragma omp parallel for simd reduction(+ : s) schedule(static) if (n > 65536)
  for (int64_t i = 0; i < n; ++i) s += double(in[i]);
  return s;
}

void reduce_sum_into(const float* in, int64_t n, double* out, Workspace& ws) { *out = reduce_sum(in, n, ws); }

void reduce_sum_into(const double* in, int64_t n, double* out, Workspace&) {
  double s = 0.0;
#pragma omp parallel for simd reduction(+ : s) schedule(static) if (n > 65536)
  for (int64_t i = 0; i < n; ++i) s += in[i];
  *out = s;
}

void reduce_sum_count_into(const double* in, const int64_t* count, int64_t capacity, double* out, Workspace& ws) {
  reduce_sum_into(in, *count < capacity ? *count : capacity, out, ws);  // device memory is the host's
}

void reduce_sum_add_into(const float* in, int64_t n, double* out, Workspace& ws) { *out += reduce_sum(in, n, ws); }

float reduce_max(const float* in, int64_t n, Workspace&) {
  float m = -std::numeric_limits<float>::infinity();
#pragma omp parallel for reduction(max : m) schedule(static) if (n > 65536)
  for (int64_t i = 0; i < n; ++i) m = std::max(m, in[i]);
  return m;
}

void reduce_max_into(const float* in, int64_t n, float* out, Workspace& ws) { *out = reduce_max(in, n, ws); }

float reduce_min(const float* in, int64_t n, Workspace&) {
  float m = std::numeric_limits<float>::infinity();
#pragma omp parallel for reduction(min : m) schedule(static) if (n > 65536)
  for (int64_t i = 0; i < n; ++i) m = std::min(m, in[i]);
  return m;
}

namespace {
// Non-finite floats of in[0, n): an exponent of all ones, tested on the bits so that the loop
// vectorises.
uint32_t nonfinite_in(const float* in, int64_t n) {
  const auto* bits = reinterpret_cast<const uint32_t*>(in);
  uint32_t c = 0;
#pragma omp simd reduction(+ : c)
  for (int64_t i = 0; i < n; ++i) c += (bits[i] & 0x7f800000u) == 0x7f800000u ? 1u : 0u;
  return c;
}
}  // namespace

// Every array's blocks in one parallel loop (a census is some 24 arrays a step: a loop each woke
// the threads 24 times), each block's count kept apart and an array's blocks summed after.
void count_nonfinite_each_into(const FloatArrays& arrays, int64_t* out, Workspace&) {
  if (arrays.count == 0) return;
  constexpr int64_t kMaxBlocks = 4096;
  int64_t total = 0;
  for (int k = 0; k < arrays.count; ++k) total += arrays.n[k];
  // Blocks of at least 64 Ki floats, and few enough for the table here (each under 2^32).
  const int64_t block = std::max(int64_t(1) << 16, (total + kMaxBlocks / 2 - 1) / (kMaxBlocks / 2));
  int64_t first[FloatArrays::kMax + 1] = {};
  for (int k = 0; k < arrays.count; ++k) first[k + 1] = first[k] + (arrays.n[k] + block - 1) / block;
  const int64_t blocks = first[arrays.count];  // at most kMaxBlocks / 2 + kMax
  uint32_t per_block[kMaxBlocks];
#pragma omp parallel for schedule(static) if (blocks > 1)
  for (int64_t b = 0; b < blocks; ++b) {
    int k = 0;
    while (first[k + 1] <= b) ++k;
    const int64_t lo = (b - first[k]) * block, hi = std::min(arrays.n[k], lo + block);
    per_block[b] = nonfinite_in(arrays.ptr[k] + lo, hi - lo);
  }
  for (int k = 0; k < arrays.count; ++k) {
    int64_t c = 0;
    for (int64_t b = first[k]; b < first[k + 1]; ++b) c += per_block[b];
    out[k] = c;
  }
}

int64_t count_nonfinite(const float* in, int64_t n, Workspace& ws) {
  FloatArrays one;
  one.add(in, n);
  int64_t c = 0;
  count_nonfinite_each_into(one, &c, ws);
  return c;
}

}  // namespace wb::cpu
