// The one runtime dispatcher of the primitives: validates, then picks the backend.
#include "core/exec/algorithms.h"

#include <string>

#include "core/exec/dispatch.h"
#include "core/exec/error.h"
#include "core/exec/memory.h"

namespace wb {
namespace {
void check_ws(const Device& d, const Workspace& ws) {
  WB_REQUIRE(ws.device() == d, "algorithm workspace lives on " + ws.device().to_string() + ", not " + d.to_string());
}
}  // namespace

void sort_by_key(const Device& d, uint32_t* keys, uint32_t* values, int64_t n, int key_bits, Workspace& ws) {
  WB_REQUIRE(n >= 0 && key_bits > 0 && key_bits <= 32, "sort_by_key: bad size or key bit count");
  check_ws(d, ws);
  mem::count_launch();
  WB_DISPATCH(d, sort_by_key(keys, values, n, key_bits, ws));
}
uint32_t exclusive_scan(const Device& d, const uint32_t* in, uint32_t* out, int64_t n, Workspace& ws) {
  check_ws(d, ws);
  mem::count_launch();
  mem::count_host_read();
  WB_DISPATCH(d, exclusive_scan(in, out, n, ws));
}
void exclusive_scan_into(const Device& d, const uint32_t* in, uint32_t* out, int64_t n, Workspace& ws) {
  check_ws(d, ws);
  mem::count_launch();
  WB_DISPATCH(d, exclusive_scan_into(in, out, n, ws));
}
double reduce_sum(const Device& d, const float* in, int64_t n, Workspace& ws) {
  check_ws(d, ws);
  mem::count_launch();
  mem::count_host_read();
  WB_DISPATCH(d, reduce_sum(in, n, ws));
}
void reduce_sum_into(const Device& d, const float* in, int64_t n, double* out, Workspace& ws) {
  check_ws(d, ws);
  mem::count_launch();
  WB_DISPATCH(d, reduce_sum_into(in, n, out, ws));
}
void reduce_sum_into(const Device& d, const double* in, int64_t n, double* out, Workspace& ws) {
  check_ws(d, ws);
  mem::count_launch();
  WB_DISPATCH(d, reduce_sum_into(in, n, out, ws));
}
void reduce_sum_count_into(const Device& d, const double* in, const int64_t* count, int64_t capacity, double* out,
                           Workspace& ws) {
  check_ws(d, ws);
  mem::count_launch();
  WB_DISPATCH(d, reduce_sum_count_into(in, count, capacity, out, ws));
}
void reduce_sum_add_into(const Device& d, const float* in, int64_t n, double* out, Workspace& ws) {
  check_ws(d, ws);
  mem::count_launch();
  WB_DISPATCH(d, reduce_sum_add_into(in, n, out, ws));
}
void FloatArrays::add(const float* p, int64_t size) {
  WB_REQUIRE(count < kMax, "FloatArrays: more than " + std::to_string(kMax) + " arrays");
  WB_REQUIRE(size >= 0 && (size == 0 || p), "FloatArrays: a null array or a negative length");
  ptr[count] = p;
  n[count] = size;
  ++count;
}
void count_nonfinite_each_into(const Device& d, const FloatArrays& arrays, int64_t* out, Workspace& ws) {
  check_ws(d, ws);
  mem::count_launch();
  if (arrays.count == 0) return;
  WB_DISPATCH(d, count_nonfinite_each_into(arrays, out, ws));
}
float reduce_max(const Device& d, const float* in, int64_t n, Workspace& ws) {
  check_ws(d, ws);
  mem::count_launch();
  mem::count_host_read();
  WB_DISPATCH(d, reduce_max(in, n, ws));
}
void reduce_max_into(const Device& d, const float* in, int64_t n, float* out, Workspace& ws) {
  check_ws(d, ws);
  mem::count_launch();
  WB_DISPATCH(d, reduce_max_into(in, n, out, ws));
}
float reduce_min(const Device& d, const float* in, int64_t n, Workspace& ws) {
  check_ws(d, ws);
  mem::count_launch();
  mem::count_host_read();
  WB_DISPATCH(d, reduce_min(in, n, ws));
}
int64_t count_nonfinite(const Device& d, const float* in, int64_t n, Workspace& ws) {
  check_ws(d, ws);
  mem::count_launch();
  mem::count_host_read();
  WB_DISPATCH(d, count_nonfinite(in, n, ws));
}

}  // namespace wb
