#include "core/exec/device.h"

#include <omp.h>

#include <cstdlib>

#include "core/exec/error.h"
#if defined(WB_WITH_CUDA)
#include "core/exec/cuda_check.h"
#include "core/exec/stream.h"
#endif

namespace wb {

bool cuda_compiled() {
#if defined(WB_WITH_CUDA)
  return true;
#else
  return false;
#endif
}

int cuda_device_count() {
#if defined(WB_WITH_CUDA)
  int n = 0;
  // No driver or no GPU is a normal answer here, not an error.
  if (cudaGetDeviceCount(&n) != cudaSuccess) {
    (void)cudaGetLastError();
    return 0;
  }
  return n;
#else
  return 0;
#endif
}

int cpu_thread_count() { return omp_get_max_threads(); }

Device Device::parse(const std::string& text) {
  if (text == "auto") return auto_select();
  if (text == "cpu" || text == "cpu:0") return Device(DeviceType::CPU, 0);
  if (text == "cuda" || text.rfind("cuda:", 0) == 0) {
    int index = 0;
    if (text.size() > 5) {
      char* end = nullptr;
      const long v = std::strtol(text.c_str() + 5, &end, 10);
      WB_REQUIRE(end && *end == '\0' && v >= 0 && v < 64, "bad device '" + text + "': expected cuda:N");
      index = int(v);
    }
    WB_REQUIRE(cuda_compiled(), "device '" + text + "' requested, but this binary was built without the CUDA backend");
    const int count = cuda_device_count();
    WB_REQUIRE(index < count, "device '" + text + "' requested, but " + std::to_string(count) +
                                  " CUDA device(s) are present");
    return Device(DeviceType::CUDA, index);
  }
  WB_THROW("bad device '" + text + "': expected auto, cpu, cuda or cuda:N");
}

Device Device::auto_select() {
  if (cuda_compiled() && cuda_device_count() > 0) return Device(DeviceType::CUDA, 0);
  return Device(DeviceType::CPU, 0);
}

Device Device::from_env() {
  const char* e = std::getenv("WB_DEVICE");
  return parse(e && *e ? e : "cpu");
}

std::string Device::to_string() const {
  return is_cpu() ? std::string("cpu") : "cuda:" + std::to_string(index_);
}

void Device::activate() const {
#if defined(WB_WITH_CUDA)
  if (is_cuda()) WB_CUDA_CHECK(cudaSetDevice(index_));
#endif
}

void Device::synchronize() const {
#if defined(WB_WITH_CUDA)
  if (is_cuda()) WB_CUDA_CHECK(cudaStreamSynchronize(cuda_stream()));
#endif
}

std::vector<DeviceInfo> list_devices() {
  std::vector<DeviceInfo> out;
  out.push_back({Device(DeviceType::CPU), "CPU (OpenMP)", 0, std::to_string(cpu_thread_count()) + " threads"});
#if defined(WB_WITH_CUDA)
  for (int i = 0; i < cuda_device_count(); ++i) {
    cudaDeviceProp prop{};
    WB_CUDA_CHECK(cudaGetDeviceProperties(&prop, i));
    out.push_back({Device(DeviceType::CUDA, i), prop.name, prop.totalGlobalMem,
                   "sm_" + std::to_string(prop.major) + std::to_string(prop.minor) + ", " +
                       std::to_string(prop.multiProcessorCount) + " SMs"});
  }
#endif
  return out;
}

}  // namespace wb
