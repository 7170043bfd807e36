// Golden images of the renderer: an image compared with a stored PNG under tests/render/golden/
// with a tolerance (mean difference < 1/255, < 0.5 % of samples off by more than 8/255).
// WB_UPDATE_GOLDEN=1 writes the image instead (and skips the test), e.g.
// `WB_UPDATE_GOLDEN=1 wetbrush_tests --gtest_filter='FilmTest.Golden*'`.
#pragma once
#include <gtest/gtest.h>

#include <cstdlib>
#include <string>

#include "core/io/png.h"
#include "core/render/renderer.h"

namespace wb::test {

inline std::string golden_path(const std::string& name) {
  return std::string(WB_SOURCE_DIR) + "/tests/render/golden/" + name + ".png";
}

/// True when the golden images are being written rather than compared.
inline bool updating_golden() { return std::getenv("WB_UPDATE_GOLDEN") != nullptr; }

/// Compares `img` with the golden image `name` (or writes it under WB_UPDATE_GOLDEN).
inline void expect_golden(const Image& img, const std::string& name) {
  const std::string path = golden_path(name);
  if (updating_golden()) {
    write_png8(path, img.rgba.data(), img.width, img.height, 4);
    return;
  }
  const PngPixels g = read_png(path);
  ASSERT_EQ(g.width, img.width) << name;
  ASSERT_EQ(g.height, img.height) << name;
  ASSERT_EQ(g.channels, 4) << name;
  double sum = 0.0;
  int large = 0;
  for (size_t i = 0; i < img.rgba.size(); ++i) {
    const int d = std::abs(int(img.rgba[i]) - int(g.data8[i]));
    sum += d;
    large += d > 8;
  }
  EXPECT_LT(sum / img.rgba.size(), 1.0) << name << ": mean difference per sample, of 255";
  EXPECT_LT(large, int(img.rgba.size() / 200)) << name << ": samples off by more than 8/255";
}

}  // namespace wb::test
