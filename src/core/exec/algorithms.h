// Device-wide primitives the stages need: radix sort of key/value pairs, exclusive
// scan, reductions and a finiteness count. One dispatcher (algorithms.cpp) picks
// the OpenMP implementation or the CUB one; all pointers are device pointers.
#pragma once
#include <cstdint>

#include "core/exec/device.h"
#include "core/exec/workspace.h"

namespace wb {

/// Sorts (key, value) pairs by the low `key_bits` bits of the key, stable, in place.
void sort_by_key(const Device& device, uint32_t* keys, uint32_t* values, int64_t n, int key_bits, Workspace& ws);
/// out[i] = sum of in[0..i), out may alias in; returns the total.
uint32_t exclusive_scan(const Device& device, const uint32_t* in, uint32_t* out, int64_t n, Workspace& ws);
/// The same scan left on the device (not a host read): the kernels that follow read its
/// prefixes, and the host reads what it needs of them with more in one copy.
void exclusive_scan_into(const Device& device, const uint32_t* in, uint32_t* out, int64_t n, Workspace& ws);
/// Sum in double precision (mass books need more than float accumulation).
double reduce_sum(const Device& device, const float* in, int64_t n, Workspace& ws);
/// The same sum written to *out, a device pointer: the result stays on the device for the
/// kernels that use it, and the host does not wait for it (not a host read).
void reduce_sum_into(const Device& device, const float* in, int64_t n, double* out, Workspace& ws);
void reduce_sum_into(const Device& device, const double* in, int64_t n, double* out, Workspace& ws);
/// The sum of the first *count of `capacity` values, *count device memory a kernel wrote (as
/// parallel_for_count): neither the count nor the sum is read by the host.
void reduce_sum_count_into(const Device& device, const double* in, const int64_t* count, int64_t capacity,
                           double* out, Workspace& ws);
/// *out += the sum, on the device (not a host read): a record the device keeps over a step.
void reduce_sum_add_into(const Device& device, const float* in, int64_t n, double* out, Workspace& ws);
float reduce_max(const Device& device, const float* in, int64_t n, Workspace& ws);
/// The same maximum written to *out, a device pointer (not a host read; -inf for n = 0).
void reduce_max_into(const Device& device, const float* in, int64_t n, float* out, Workspace& ws);
float reduce_min(const Device& device, const float* in, int64_t n, Workspace& ws);
/// Number of NaN or infinite values.
int64_t count_nonfinite(const Device& device, const float* in, int64_t n, Workspace& ws);
/// Arrays of floats (device pointers and lengths), passed whole to one kernel.
struct FloatArrays {
  static constexpr int kMax = 32;
  const float* ptr[kMax] = {};
  int64_t n[kMax] = {};
  int count = 0;
  void add(const float* p, int64_t size);
};
/// out[k] = the non-finite values of array k, for every array, in one launch (not a host read):
/// the containment's check of the whole live state costs one pass, not one launch an array.
void count_nonfinite_each_into(const Device& device, const FloatArrays& arrays, int64_t* out, Workspace& ws);

namespace cpu {
void count_nonfinite_each_into(const FloatArrays& arrays, int64_t* out, Workspace& ws);
void reduce_sum_count_into(const double* in, const int64_t* count, int64_t capacity, double* out, Workspace& ws);
void sort_by_key(uint32_t* keys, uint32_t* values, int64_t n, int key_bits, Workspace& ws);
uint32_t exclusive_scan(const uint32_t* in, uint32_t* out, int64_t n, Workspace& ws);
void exclusive_scan_into(const uint32_t* in, uint32_t* out, int64_t n, Workspace& ws);
double reduce_sum(const float* in, int64_t n, Workspace& ws);
void reduce_sum_into(const float* in, int64_t n, double* out, Workspace& ws);
void reduce_sum_into(const double* in, int64_t n, double* out, Workspace& ws);
void reduce_sum_add_into(const float* in, int64_t n, double* out, Workspace& ws);
float reduce_max(const float* in, int64_t n, Workspace& ws);
void reduce_max_into(const float* in, int64_t n, float* out, Workspace& ws);
float reduce_min(const float* in, int64_t n, Workspace& ws);
int64_t count_nonfinite(const float* in, int64_t n, Workspace& ws);
}  // namespace cpu
namespace cuda {
void count_nonfinite_each_into(const FloatArrays& arrays, int64_t* out, Workspace& ws);
void reduce_sum_count_into(const double* in, const int64_t* count, int64_t capacity, double* out, Workspace& ws);
void sort_by_key(uint32_t* keys, uint32_t* values, int64_t n, int key_bits, Workspace& ws);
uint32_t exclusive_scan(const uint32_t* in, uint32_t* out, int64_t n, Workspace& ws);
void exclusive_scan_into(const uint32_t* in, uint32_t* out, int64_t n, Workspace& ws);
double reduce_sum(const float* in, int64_t n, Workspace& ws);
void reduce_sum_into(const float* in, int64_t n, double* out, Workspace& ws);
void reduce_sum_into(const double* in, int64_t n, double* out, Workspace& ws);
void reduce_sum_add_into(const float* in, int64_t n, double* out, Workspace& ws);
float reduce_max(const float* in, int64_t n, Workspace& ws);
void reduce_max_into(const float* in, int64_t n, float* out, Workspace& ws);
float reduce_min(const float* in, int64_t n, Workspace& ws);
int64_t count_nonfinite(const float* in, int64_t n, Workspace& ws);
}  // namespace cuda

}  // namespace wb
