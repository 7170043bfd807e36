// Device: where buffers live and kernels run. A value type parsed from "cpu",
// "cuda", "cuda:N" or "auto" (CUDA when a GPU is present at run time, else CPU).
#pragma once
#include <string>
#include <vector>

namespace wb {

enum class DeviceType { CPU, CUDA };

class Device {
 public:
  Device() = default;
  Device(DeviceType type, int index = 0) : type_(type), index_(index) {}

  /// Parses "cpu", "cuda", "cuda:N" or "auto"; throws wb::Error on anything else,
  /// and on "cuda" when the build has no CUDA backend or no GPU is present.
  static Device parse(const std::string& text);
  /// CUDA:0 when compiled in and a GPU is present, else CPU.
  static Device auto_select();
  /// Device chosen by the WB_DEVICE environment variable (default "cpu").
  static Device from_env();

  DeviceType type() const { return type_; }
  int index() const { return index_; }
  bool is_cpu() const { return type_ == DeviceType::CPU; }
  bool is_cuda() const { return type_ == DeviceType::CUDA; }
  std::string to_string() const;
  bool operator==(const Device& o) const { return type_ == o.type_ && index_ == o.index_; }

  /// Makes this device current for the calling thread (cudaSetDevice on CUDA).
  void activate() const;
  /// Waits for all work queued on this device.
  void synchronize() const;

 private:
  DeviceType type_ = DeviceType::CPU;
  int index_ = 0;
};

/// True when the CUDA backend was compiled into this binary.
bool cuda_compiled();
/// Number of CUDA devices visible at run time (0 when none or not compiled).
int cuda_device_count();
/// Number of OpenMP threads the CPU backend uses.
int cpu_thread_count();

struct DeviceInfo {
  Device device;
  std::string name;
  size_t memory_bytes = 0;
  std::string detail;
};
/// Every device usable now: the CPU, then each CUDA device.
std::vector<DeviceInfo> list_devices();

}  // namespace wb
