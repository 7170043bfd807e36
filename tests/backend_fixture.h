// BackendTest: every kernel test runs on the device named by WB_DEVICE
// (cpu by default; WB_DEVICE=cuda runs the same suite on the GPU).
#pragma once
#include <gtest/gtest.h>

#include "core/exec/device.h"
#include "core/exec/workspace.h"

namespace wb::test {

inline Device test_device() {
  static const Device d = Device::from_env();
  return d;
}

class BackendTest : public ::testing::Test {
 protected:
  void SetUp() override {
    device_.activate();
    ws_ = Workspace(device_);
  }
  // Set at construction, so that a derived fixture's members built from it live on it too.
  Device device_ = test_device();
  Workspace ws_;
};

}  // namespace wb::test
