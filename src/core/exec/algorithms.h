// Device-wide primitives the stages need: radix sort of key/value pairs, exclusive
// scan, reductions and a finiteness count. Their dispatchers (algorithms.cpp) pick
// the OpenMP implementation or the CUB one; all pointers are device pointers.
#pragma once
#include <cstdint>

#include "core/exec/device.h"
#include "core/exec/dispatch.h"
#include "core/exec/error.h"
#include "core/exec/workspace.h"

namespace wb {

/// Arrays of floats (device pointers and lengths), passed whole to one kernel.
struct FloatArrays {
  static constexpr int kMax = 32;
  const float* ptr[kMax] = {};
  int64_t n[kMax] = {};
  int count = 0;
  void add(const float* p, int64_t size);
};

// The primitives, one list (core/exec/dispatch.h): wb::name(device, ...) checks the workspace's
// device, counts the launch (and the host read of a primitive that returns a value) and runs
// wb::cpu::name (algorithms_cpu.cpp, OpenMP) or wb::cuda::name (algorithms_cuda.cu, CUB).
//   sort_by_key             (key, value) pairs by the low `key_bits` bits of the key, stable, in place
//   exclusive_scan          out[i] = sum of in[0..i), out may alias in; returns the total
//   exclusive_scan_into     the same scan left on the device (not a host read): the kernels that
//                           follow read its prefixes, the host reads what it needs with more in one copy
//   reduce_sum              the sum in double precision (mass books need more than float accumulation)
//   reduce_sum_into         the same sum written to *out, a device pointer: it stays on the device for
//                           the kernels that use it, and the host does not wait for it
//   reduce_sum_count_into   the sum of the first *count of `capacity` values, *count device memory a
//                           kernel wrote (as parallel_for_count): neither is read by the host
//   reduce_sum_add_into     *out += the sum, on the device: a record the device keeps over a step
//   reduce_max, reduce_min  the extremes (reduce_max_into: to *out on the device, -inf for n = 0)
//   count_nonfinite         the number of NaN or infinite values
//   count_nonfinite_each_into  out[k] = the non-finite values of array k, every array in one launch
//                           (not a host read): the containment's check of the live state is one pass
#define WB_ALGORITHMS_KERNELS(X)                                                                                  \
  X(void, sort_by_key, (uint32_t* keys, uint32_t* values, int64_t n, int key_bits, Workspace& ws),                \
      (keys, values, n, key_bits, ws))                                                                            \
  X(uint32_t, exclusive_scan, (const uint32_t* in, uint32_t* out, int64_t n, Workspace& ws), (in, out, n, ws))    \
  X(void, exclusive_scan_into, (const uint32_t* in, uint32_t* out, int64_t n, Workspace& ws), (in, out, n, ws))   \
  X(double, reduce_sum, (const float* in, int64_t n, Workspace& ws), (in, n, ws))                                 \
  X(void, reduce_sum_into, (const float* in, int64_t n, double* out, Workspace& ws), (in, n, out, ws))            \
  X(void, reduce_sum_into, (const double* in, int64_t n, double* out, Workspace& ws), (in, n, out, ws))           \
  X(void, reduce_sum_count_into, (const double* in, const int64_t* count, int64_t capacity, double* out,          \
      Workspace& ws), (in, count, capacity, out, ws))                                                             \
  X(void, reduce_sum_add_into, (const float* in, int64_t n, double* out, Workspace& ws), (in, n, out, ws))        \
  X(float, reduce_max, (const float* in, int64_t n, Workspace& ws), (in, n, ws))                                  \
  X(void, reduce_max_into, (const float* in, int64_t n, float* out, Workspace& ws), (in, n, out, ws))             \
  X(float, reduce_min, (const float* in, int64_t n, Workspace& ws), (in, n, ws))                                  \
  X(int64_t, count_nonfinite, (const float* in, int64_t n, Workspace& ws), (in, n, ws))                           \
  X(void, count_nonfinite_each_into, (const FloatArrays& arrays, int64_t* out, Workspace& ws), (arrays, out, ws))
WB_DECLARE_KERNELS(WB_ALGORITHMS_KERNELS)

/// sort_by_key's arguments, checked by both backends.
inline void check_sort_args(int64_t n, int key_bits) {
  WB_REQUIRE(n >= 0 && key_bits > 0 && key_bits <= 32, "sort_by_key: bad size or key bit count");
}

}  // namespace wb
