#include "core/exec/selftest.h"

#include <string>

#include "core/exec/buffer.h"

namespace wb {

WB_DEFINE_DISPATCHERS(WB_SELFTEST_KERNELS)

std::string selftest_run(const Device& d) {
  try {
    d.activate();
    const int64_t n = 1 << 18;
    DeviceBuffer<float> acc(d, 4);
    DeviceBuffer<int32_t> iacc(d, 2), hits(d, size_t(n));
    acc.fill_zero();
    iacc.fill_zero();
    hits.fill_zero();
    selftest_atomic_contention(d, acc.data(), iacc.data(), n);
    selftest_count_visits(d, hits.data(), n);
    auto a = acc.to_host();
    auto ia = iacc.to_host();
    for (float v : a)
      if (v != float(n / 4)) return "float atomics lost updates";
    if (ia[0] != n || ia[1] != n - 1) return "integer atomics lost updates";
    for (int32_t h : hits.to_host())
      if (h != 1) return "parallel_for missed or repeated an index";
    return "";
  } catch (const std::exception& e) {
    return e.what();
  }
}

}  // namespace wb
