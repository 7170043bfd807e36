// CUDA implementations of the device-wide primitives, on CUB with scratch from the
// caller's Workspace (no allocation once warm). Results come back with one sync.
#include <cub/device/device_radix_sort.cuh>
#include <cub/device/device_reduce.cuh>
#include <cub/device/device_scan.cuh>
#include <thrust/iterator/counting_iterator.h>
#include <thrust/iterator/transform_iterator.h>

#include <cuda/std/limits>

#include "core/exec/algorithms.h"
#include "core/exec/cuda_check.h"
#include "core/exec/stream.h"

namespace wb::cuda {
namespace {

struct ToDouble {
  __host__ __device__ double operator()(float v) const { return double(v); }
};
// in[i] below the device's count, else 0: a reduction over the capacity sums the first *count.
struct CountedDouble {
  const double* in;
  const int64_t* count;
  __host__ __device__ double operator()(int64_t i) const { return i < *count ? in[i] : 0.0; }
};
struct NonFinite {
  __host__ __device__ long long operator()(float v) const { return isfinite(v) ? 0 : 1; }
};
struct MaxOp {
  __host__ __device__ float operator()(float a, float b) const { return a > b ? a : b; }
};
struct MinOp {
  __host__ __device__ float operator()(float a, float b) const { return a < b ? a : b; }
};

// Layout of the workspace: [result slot 256 B][CUB temp storage][extra].
template <typename T>
T fetch_result(void* slot) {
  T host{};
  WB_CUDA_CHECK(cudaMemcpyAsync(&host, slot, sizeof(T), cudaMemcpyDeviceToHost, wb::cuda_stream()));
  WB_CUDA_CHECK(cudaStreamSynchronize(wb::cuda_stream()));
  return host;
}

// The reduction into device memory at `out`, or, for out == nullptr, into the workspace's first
// 256-byte slot (CUB's scratch follows it); returns where the result is. CUB writes init for n == 0.
template <typename InputIt, typename T, typename Op>
T* reduce_to(InputIt in, int64_t n, Op op, T init, T* out, Workspace& ws) {
  size_t temp = 0;
  WB_CUDA_CHECK(cub::DeviceReduce::Reduce(nullptr, temp, in, static_cast<T*>(nullptr), n, op, init, wb::cuda_stream()));
  const size_t skip = out ? 0 : 256;
  auto* base = static_cast<unsigned char*>(ws.get(skip + temp));
  if (!out) out = reinterpret_cast<T*>(base);
  WB_CUDA_CHECK(cub::DeviceReduce::Reduce(base + skip, temp, in, out, n, op, init, wb::cuda_stream()));
  return out;
}

// The reduction's value on the host: into the workspace's first slot, then one copy.
template <typename InputIt, typename T, typename Op>
T reduce(InputIt in, int64_t n, Op op, T init, Workspace& ws) {
  return fetch_result<T>(reduce_to(in, n, op, init, static_cast<T*>(nullptr), ws));
}

}  // namespace

void sort_by_key(uint32_t* keys, uint32_t* values, int64_t n, int key_bits, Workspace& ws) {
  check_sort_args(n, key_bits);
  if (n <= 1) return;
  const int end_bit = key_bits < 1 ? 1 : (key_bits > 32 ? 32 : key_bits);
  const size_t pair_bytes = size_t(n) * sizeof(uint32_t);
  const size_t aligned = (pair_bytes + 255) & ~size_t(255);
  size_t temp = 0;
  cub::DoubleBuffer<uint32_t> k(keys, nullptr), v(values, nullptr);
  WB_CUDA_CHECK(cub::DeviceRadixSort::SortPairs(nullptr, temp, k, v, n, 0, end_bit, wb::cuda_stream()));
  auto* base = static_cast<unsigned char*>(ws.get(2 * aligned + temp));
  k = cub::DoubleBuffer<uint32_t>(keys, reinterpret_cast<uint32_t*>(base));
  v = cub::DoubleBuffer<uint32_t>(values, reinterpret_cast<uint32_t*>(base + aligned));
  WB_CUDA_CHECK(cub::DeviceRadixSort::SortPairs(base + 2 * aligned, temp, k, v, n, 0, end_bit, wb::cuda_stream()));
  if (k.Current() != keys) {
    WB_CUDA_CHECK(cudaMemcpyAsync(keys, k.Current(), pair_bytes, cudaMemcpyDeviceToDevice, wb::cuda_stream()));
    WB_CUDA_CHECK(cudaMemcpyAsync(values, v.Current(), pair_bytes, cudaMemcpyDeviceToDevice, wb::cuda_stream()));
  }
}

uint32_t exclusive_scan(const uint32_t* in, uint32_t* out, int64_t n, Workspace& ws) {
  if (n <= 0) return 0;
  // The last input is read before the scan so that out may alias in.
  uint32_t last_in = 0;
  WB_CUDA_CHECK(cudaMemcpyAsync(&last_in, in + n - 1, sizeof(uint32_t), cudaMemcpyDeviceToHost, wb::cuda_stream()));
  size_t temp = 0;
  WB_CUDA_CHECK(cub::DeviceScan::ExclusiveSum(nullptr, temp, in, out, n, wb::cuda_stream()));
  void* base = ws.get(temp);
  WB_CUDA_CHECK(cub::DeviceScan::ExclusiveSum(base, temp, in, out, n, wb::cuda_stream()));
  uint32_t last_out = 0;
  WB_CUDA_CHECK(cudaMemcpyAsync(&last_out, out + n - 1, sizeof(uint32_t), cudaMemcpyDeviceToHost, wb::cuda_stream()));
  WB_CUDA_CHECK(cudaStreamSynchronize(wb::cuda_stream()));
  return last_out + last_in;
}

void exclusive_scan_into(const uint32_t* in, uint32_t* out, int64_t n, Workspace& ws) {
  if (n <= 0) return;
  size_t temp = 0;
  WB_CUDA_CHECK(cub::DeviceScan::ExclusiveSum(nullptr, temp, in, out, n, wb::cuda_stream()));
  void* base = ws.get(temp);
  WB_CUDA_CHECK(cub::DeviceScan::ExclusiveSum(base, temp, in, out, n, wb::cuda_stream()));
}

double reduce_sum(const float* in, int64_t n, Workspace& ws) {
  if (n <= 0) return 0.0;
  return reduce(thrust::make_transform_iterator(in, ToDouble{}), n, ::cuda::std::plus<double>{}, 0.0, ws);
}

void reduce_sum_into(const float* in, int64_t n, double* out, Workspace& ws) {
  reduce_to(thrust::make_transform_iterator(in, ToDouble{}), n, ::cuda::std::plus<double>{}, 0.0, out, ws);
}

void reduce_sum_into(const double* in, int64_t n, double* out, Workspace& ws) {
  reduce_to(in, n, ::cuda::std::plus<double>{}, 0.0, out, ws);
}

void reduce_sum_count_into(const double* in, const int64_t* count, int64_t capacity, double* out, Workspace& ws) {
  reduce_to(thrust::make_transform_iterator(thrust::counting_iterator<int64_t>(0), CountedDouble{in, count}), capacity,
            ::cuda::std::plus<double>{}, 0.0, out, ws);
}

namespace {
__global__ void add_to(double* out, const double* v) { *out += *v; }
}  // namespace

void reduce_sum_add_into(const float* in, int64_t n, double* out, Workspace& ws) {
  // The sum into the workspace's first slot, then one thread adds it (stream order, no wait).
  const double* sum = reduce_to(thrust::make_transform_iterator(in, ToDouble{}), n, ::cuda::std::plus<double>{}, 0.0,
                                static_cast<double*>(nullptr), ws);
  add_to<<<1, 1, 0, wb::cuda_stream()>>>(out, sum);
  WB_CUDA_CHECK(cudaGetLastError());
}


namespace {
// Block y counts array y: a strided pass, a warp sum, one integer atomic a warp (exact in any order).
__global__ void count_nonfinite_each(FloatArrays a, unsigned long long* out) {
  const int k = blockIdx.y;
  const int64_t n = a.n[k];
  const float* p = a.ptr[k];
  unsigned long long c = 0;
  const int64_t stride = int64_t(blockDim.x) * gridDim.x;
  for (int64_t i = int64_t(blockIdx.x) * blockDim.x + threadIdx.x; i < n; i += stride) c += isfinite(p[i]) ? 0 : 1;
  for (int off = 16; off > 0; off >>= 1) c += __shfl_down_sync(0xffffffffu, c, off);
  if ((threadIdx.x & 31) == 0 && c) atomicAdd(out + k, c);
}
}  // namespace

void count_nonfinite_each_into(const FloatArrays& arrays, int64_t* out, Workspace&) {
  if (arrays.count == 0) return;
  static_assert(sizeof(int64_t) == sizeof(unsigned long long), "count type");
  int64_t most = 0;
  for (int k = 0; k < arrays.count; ++k) most = arrays.n[k] > most ? arrays.n[k] : most;
  WB_CUDA_CHECK(cudaMemsetAsync(out, 0, size_t(arrays.count) * sizeof(int64_t), wb::cuda_stream()));
  constexpr int kThreads = 256;
  const int64_t blocks = (most + kThreads - 1) / kThreads;
  const dim3 grid(unsigned(blocks < 1 ? 1 : blocks > 512 ? 512 : blocks), unsigned(arrays.count));
  count_nonfinite_each<<<grid, kThreads, 0, wb::cuda_stream()>>>(arrays, reinterpret_cast<unsigned long long*>(out));
  WB_CUDA_CHECK(cudaGetLastError());
}

float reduce_max(const float* in, int64_t n, Workspace& ws) {
  return reduce(in, n, MaxOp{}, -::cuda::std::numeric_limits<float>::infinity(), ws);
}

void reduce_max_into(const float* in, int64_t n, float* out, Workspace& ws) {
  reduce_to(in, n, MaxOp{}, -::cuda::std::numeric_limits<float>::infinity(), out, ws);
}

float reduce_min(const float* in, int64_t n, Workspace& ws) {
  return reduce(in, n, MinOp{}, ::cuda::std::numeric_limits<float>::infinity(), ws);
}

int64_t count_nonfinite(const float* in, int64_t n, Workspace& ws) {
  if (n <= 0) return 0;
  return reduce(thrust::make_transform_iterator(in, NonFinite{}), n, ::cuda::std::plus<long long>{}, 0LL, ws);
}

}  // namespace wb::cuda
