// Self-test kernels of the execution layer: used by the test suite and by
// `wetbrush devices --check` to prove a backend runs (atomics, parallel_for).
#pragma once
#include <cstdint>
#include <string>

#include "core/exec/device.h"
#include "core/exec/dispatch.h"
#include "core/exec/hd.h"

namespace wb {
/// Runs both on the device and returns an empty string, or what went wrong.
std::string selftest_run(const Device& d);

// The self-test's backend drivers (selftest_impl.h, where each is described), one list
// (core/exec/dispatch.h).
#define WB_SELFTEST_KERNELS(X)                                                                                  \
  X(void, selftest_atomic_contention, (float* acc4, int32_t* iacc2, int64_t n), (acc4, iacc2, n))               \
  X(void, selftest_count_visits, (int32_t* hits, int64_t n), (hits, n))                                         \
  X(void, selftest_sum_squares, (const int64_t* count, int64_t capacity, double* x, double* out, SumScratch s), \
      (count, capacity, x, out, s))                                                                             \
  X(void, selftest_count_down, (int64_t * left, uint32_t* go), (left, go))
WB_DECLARE_KERNELS(WB_SELFTEST_KERNELS)
}  // namespace wb
