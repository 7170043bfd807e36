// `wetbrush render` and `wetbrush export` end to end: a known volume saved as a painting, its
// 16-bit height map read back against the analytic height, and a bad painting rejected.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>

#include <unistd.h>

#include "core/io/png.h"

namespace wb::test {

namespace {
int run(const std::string& args) { return std::system((std::string(WB_CLI_PATH) + " " + args + " > /dev/null 2>&1").c_str()); }
}  // namespace

TEST(ExportCli, HeightMapOfHemisphereMatchesAnalyticHeight) {
  const auto dir = std::filesystem::temp_directory_path() / ("wetbrush_export_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string ora = (dir / "h.ora").string(), hpng = (dir / "h.png").string(), npng = (dir / "n.png").string();
  ASSERT_EQ(run("render --device cpu --test-volume hemisphere --ao-rays 0 --save " + ora), 0);
  ASSERT_EQ(run("export --device cpu " + ora + " --height " + hpng + " --normal " + npng), 0);
  const PngPixels h = read_png(hpng);
  ASSERT_EQ(h.bit_depth, 16);
  ASSERT_EQ(h.width, 96);
  const double per_cell = 65535.0 / 32.0;  // hemisphere canvas depth is 32 cells
  for (int y = 0; y < 96; y += 3)
    for (int x = 0; x < 96; x += 3) {
      const double dx = x + 0.5 - 48, dy = y + 0.5 - 48, r2 = dx * dx + dy * dy;
      if (r2 > 0.8 * 0.8 * 576 && r2 < 1.1 * 1.1 * 576) continue;  // the foot of the dome: steep
      const double expect = r2 < 576 ? std::sqrt(576 - r2) : 0.0;
      EXPECT_NEAR(h.data16[size_t(y) * 96 + x] / per_cell, expect, 0.1) << x << "," << y;
    }
  // The normal map is up (128, 128, 255) where the canvas is bare and tilts with the dome.
  const PngPixels n = read_png(npng);
  ASSERT_EQ(n.channels, 3);
  EXPECT_NEAR(n.data8[0 * 3 + 2], 255, 1);
  const size_t right = (size_t(48) * 96 + 62) * 3;  // east slope: normal points +x
  EXPECT_GT(n.data8[right], 160);
  // A damaged painting is an error with a message, not a crash.
  EXPECT_NE(run("render " + std::string(WB_TEST_DATA_DIR) + "/documents/bad/bad_checksum.ora -o " + (dir / "x.png").string()), 0);
  std::filesystem::remove_all(dir);
}

}  // namespace wb::test
