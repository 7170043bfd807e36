// Fuzz harness: PNG images (the layers, merged image and thumbnail of painting files) through
// decode_png, with a 64 MiB decode limit.
#include "core/io/png.h"
#include "fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  wb::fuzz::expect_clean([&] { wb::decode_png(data, size, "fuzz.png", uint64_t(64) << 20); });
  return 0;
}
