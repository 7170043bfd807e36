#pragma once
#include "core/exec/atomics.h"
#include "core/exec/parallel_for.h"
#include "core/exec/selftest.h"

namespace wb::WB_BACKEND_NS {

/// n threads add 1 to acc4[i % 4], add 1 to iacc2[0] and take atomic max of i into iacc2[1].
void selftest_atomic_contention(float* acc4, int32_t* iacc2, int64_t n) {
  parallel_for(n, [=] WB_HD(int64_t i) {
    atomic_add(&acc4[i % 4], 1.0f);
    atomic_add(&iacc2[0], int32_t(1));
    atomic_max(&iacc2[1], int32_t(i));
  });
}

/// hits[i] += 1 for every i in [0, n).
void selftest_count_visits(int32_t* hits, int64_t n) {
  parallel_for(n, [=] WB_HD(int64_t i) { hits[i] += 1; });
}

/// x[i] = (i % 97) * 0.125 - 3.3 for the first *count of `capacity` entries, and *out = the sum of
/// x[i]^2 over them, formed as the pass goes (parallel_sum_count).
void selftest_sum_squares(const int64_t* count, int64_t capacity, double* x, double* out, SumScratch s) {
  parallel_sum_count(
      count, capacity,
      [=] WB_HD(int64_t i) {
        x[i] = double(i % 97) * 0.125 - 3.3;
        return x[i] * x[i];
      },
      out, s);
}

/// One thread: *left -= 1, and *go = 1 while some are left (a LaunchLoop's flag).
void selftest_count_down(int64_t* left, uint32_t* go) {
  parallel_for(1, [=] WB_HD(int64_t) {
    *left -= 1;
    *go = *left > 0 ? 1u : 0u;
  });
}

}  // namespace wb::WB_BACKEND_NS
