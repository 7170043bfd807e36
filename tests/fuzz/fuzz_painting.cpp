// Fuzz harness: painting files (.ora): the ZIP archive, its mimetype, the zstd paint volume
// with its checksums and the metadata, through load_painting_bytes on the CPU backend, with
// limits small enough that one input never needs more than a few hundred MB.
#include "core/io/document.h"
#include "fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  wb::LoadLimits limits;
  limits.max_paint_bytes = uint64_t(256) << 20;
  wb::fuzz::expect_clean([&] {
    wb::load_painting_bytes(data, size, "fuzz.ora", wb::Device(wb::DeviceType::CPU), limits);
  });
  return 0;
}
