// Self-test kernels of the execution layer: used by the test suite and by
// `wetbrush devices --check` to prove a backend runs (atomics, parallel_for).
#pragma once
#include <cstdint>

#include "core/exec/device.h"
#include "core/exec/hd.h"

namespace wb {
/// n threads add 1 to acc4[i % 4], add 1 to iacc2[0] and take atomic max of i into iacc2[1].
void selftest_atomic_contention(const Device& d, float* acc4, int32_t* iacc2, int64_t n);
/// hits[i] += 1 for every i in [0, n).
void selftest_count_visits(const Device& d, int32_t* hits, int64_t n);
/// x[i] = (i % 97) * 0.125 - 3.3 for the first *count of `capacity` entries, and *out = the sum of
/// x[i]^2 over them, formed as the pass goes (parallel_sum_count).
void selftest_sum_squares(const Device& d, const int64_t* count, int64_t capacity, double* x, double* out,
                          SumScratch s);
/// Runs both on the device and returns an empty string, or what went wrong.
std::string selftest_run(const Device& d);

namespace cpu {
void selftest_atomic_contention(float* acc4, int32_t* iacc2, int64_t n);
void selftest_count_visits(int32_t* hits, int64_t n);
void selftest_sum_squares(const int64_t* count, int64_t capacity, double* x, double* out, SumScratch s);
}  // namespace cpu
namespace cuda {
void selftest_atomic_contention(float* acc4, int32_t* iacc2, int64_t n);
void selftest_count_visits(int32_t* hits, int64_t n);
void selftest_sum_squares(const int64_t* count, int64_t capacity, double* x, double* out, SumScratch s);
}  // namespace cuda
}  // namespace wb
