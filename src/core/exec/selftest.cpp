#include "core/exec/selftest.h"

#include <string>

#include "core/exec/buffer.h"
#include "core/exec/dispatch.h"

namespace wb {

void selftest_atomic_contention(const Device& d, float* acc4, int32_t* iacc2, int64_t n) {
  WB_DISPATCH(d, selftest_atomic_contention(acc4, iacc2, n));
}
void selftest_count_visits(const Device& d, int32_t* hits, int64_t n) { WB_DISPATCH(d, selftest_count_visits(hits, n)); }

void selftest_sum_squares(const Device& d, const int64_t* count, int64_t capacity, double* x, double* out,
                          SumScratch s) {
  WB_DISPATCH(d, selftest_sum_squares(count, capacity, x, out, s));
}
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
