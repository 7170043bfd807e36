// Float and integer atomics usable from WB_HD code on both backends. Used only where
// the paper accumulates (rasterisation of particles and samples, transfer budgets).
#pragma once
#include <cstdint>

#include "core/exec/hd.h"
#if !defined(__CUDA_ARCH__)
#include <atomic>
#endif

namespace wb {

WB_HD WB_INLINE float atomic_add(float* addr, float v) {
#if defined(__CUDA_ARCH__)
  return atomicAdd(addr, v);
#else
  return std::atomic_ref<float>(*addr).fetch_add(v, std::memory_order_relaxed);
#endif
}

WB_HD WB_INLINE int32_t atomic_add(int32_t* addr, int32_t v) {
#if defined(__CUDA_ARCH__)
  return atomicAdd(reinterpret_cast<int*>(addr), v);
#else
  return std::atomic_ref<int32_t>(*addr).fetch_add(v, std::memory_order_relaxed);
#endif
}

WB_HD WB_INLINE int64_t atomic_add(int64_t* addr, int64_t v) {
#if defined(__CUDA_ARCH__)
  // Two's complement: the unsigned 64-bit add is the signed one.
  return int64_t(atomicAdd(reinterpret_cast<unsigned long long*>(addr), static_cast<unsigned long long>(v)));
#else
  return std::atomic_ref<int64_t>(*addr).fetch_add(v, std::memory_order_relaxed);
#endif
}

WB_HD WB_INLINE uint32_t atomic_add(uint32_t* addr, uint32_t v) {
#if defined(__CUDA_ARCH__)
  return atomicAdd(reinterpret_cast<unsigned*>(addr), v);
#else
  return std::atomic_ref<uint32_t>(*addr).fetch_add(v, std::memory_order_relaxed);
#endif
}

WB_HD WB_INLINE int32_t atomic_max(int32_t* addr, int32_t v) {
#if defined(__CUDA_ARCH__)
  return atomicMax(reinterpret_cast<int*>(addr), v);
#else
  std::atomic_ref<int32_t> a(*addr);
  int32_t cur = a.load(std::memory_order_relaxed);
  while (cur < v && !a.compare_exchange_weak(cur, v, std::memory_order_relaxed)) {
  }
  return cur;
#endif
}

WB_HD WB_INLINE int32_t atomic_min(int32_t* addr, int32_t v) {
#if defined(__CUDA_ARCH__)
  return atomicMin(reinterpret_cast<int*>(addr), v);
#else
  std::atomic_ref<int32_t> a(*addr);
  int32_t cur = a.load(std::memory_order_relaxed);
  while (cur > v && !a.compare_exchange_weak(cur, v, std::memory_order_relaxed)) {
  }
  return cur;
#endif
}

/// Float max by compare-and-swap on the bit pattern (any sign).
WB_HD WB_INLINE float atomic_max(float* addr, float v) {
#if defined(__CUDA_ARCH__)
  int* ia = reinterpret_cast<int*>(addr);
  int old = *ia;
  while (__int_as_float(old) < v) {
    const int assumed = old;
    old = atomicCAS(ia, assumed, __float_as_int(v));
    if (old == assumed) break;
  }
  return __int_as_float(old);
#else
  std::atomic_ref<float> a(*addr);
  float cur = a.load(std::memory_order_relaxed);
  while (cur < v && !a.compare_exchange_weak(cur, v, std::memory_order_relaxed)) {
  }
  return cur;
#endif
}

/// Two floats added together: the particles' raster adds a mass and what it carries (oil,
/// momentum) to the same cell or face. The CPU adds both with one 8-byte compare-and-swap
/// (each atomic is the cost there, so a pair halves it); CUDA adds each.
struct alignas(8) FloatPair {
  float first;
  float second;
};

WB_HD WB_INLINE void atomic_add(FloatPair* addr, float a, float b) {
#if defined(__CUDA_ARCH__)
  atomicAdd(&addr->first, a);
  atomicAdd(&addr->second, b);
#else
  std::atomic_ref<FloatPair> r(*addr);
  FloatPair cur = r.load(std::memory_order_relaxed);
  while (!r.compare_exchange_weak(cur, FloatPair{cur.first + a, cur.second + b}, std::memory_order_relaxed)) {
  }
#endif
}

/// A load that may race with the atomics above (relaxed: a flag read before setting it).
WB_HD WB_INLINE int32_t atomic_load(const int32_t* addr) {
#if defined(__CUDA_ARCH__)
  return *reinterpret_cast<const volatile int*>(addr);
#else
  return std::atomic_ref<int32_t>(*const_cast<int32_t*>(addr)).load(std::memory_order_relaxed);
#endif
}

WB_HD WB_INLINE int32_t atomic_or(int32_t* addr, int32_t v) {
#if defined(__CUDA_ARCH__)
  return atomicOr(reinterpret_cast<int*>(addr), v);
#else
  return std::atomic_ref<int32_t>(*addr).fetch_or(v, std::memory_order_relaxed);
#endif
}

}  // namespace wb
