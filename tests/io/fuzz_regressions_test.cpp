// Every input a fuzz harness (tests/fuzz/) ever found a problem with is kept in
// tests/data/fuzz/<harness>/ and read here through the same entry point as its harness: each
// must give a clean wb::Error (a message naming the file), never a crash, another exception
// type or a hang. docs/RELIABILITY.md lists the findings and their fixes.
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "backend_fixture.h"
#include "core/io/brush_json.h"
#include "core/io/document.h"
#include "core/io/png.h"
#include "core/io/stroke.h"
#include "core/io/stroke_player.h"
#include "core/params/param_table.h"

namespace wb::test {

namespace fs = std::filesystem;

namespace {
std::vector<fs::path> findings(const std::string& harness) {
  std::vector<fs::path> out;
  const fs::path dir = fs::path(WB_TEST_DATA_DIR) / "fuzz" / harness;
  if (fs::is_directory(dir))
    for (const auto& e : fs::directory_iterator(dir))
      if (e.is_regular_file()) out.push_back(e.path());
  std::sort(out.begin(), out.end());
  return out;
}
std::string text_of(const fs::path& p) {
  const std::vector<uint8_t> b = read_file(p.string());
  return {b.begin(), b.end()};
}
}  // namespace

class FuzzRegressions : public BackendTest {
 protected:
  // `read` must throw wb::Error naming the file.
  template <class F>
  void expect_clean_error(const fs::path& file, F&& read) {
    SCOPED_TRACE(file.string());
    try {
      read();
      ADD_FAILURE() << file << " was accepted";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(file.filename().string()), std::string::npos) << e.what();
    }
  }
};

TEST_F(FuzzRegressions, StrokeFiles) {
  for (const fs::path& f : findings("stroke_json"))
    expect_clean_error(f, [&] { StrokePlayer player(load_stroke(f.string())); });
}

TEST_F(FuzzRegressions, MyPaintDumps) {
  for (const fs::path& f : findings("mypaint"))
    expect_clean_error(f, [&] { StrokePlayer player(parse_mypaint_events(text_of(f), f.string())); });
}

TEST_F(FuzzRegressions, BrushPresets) {
  for (const fs::path& f : findings("brush_json"))
    expect_clean_error(f, [&] { brush_from_json(nlohmann::json::parse(text_of(f)), f.string(), ""); });
}

TEST_F(FuzzRegressions, ParameterFiles) {
  for (const fs::path& f : findings("params_json"))
    expect_clean_error(f, [&] {
      SimParams p;
      std::vector<std::string> warnings;
      params_from_json(p, nlohmann::json::parse(text_of(f)), warnings);
    });
}

TEST_F(FuzzRegressions, Paintings) {
  for (const fs::path& f : findings("painting")) expect_clean_error(f, [&] { load_painting(f.string(), device_); });
}

TEST_F(FuzzRegressions, PngImages) {
  for (const fs::path& f : findings("png")) expect_clean_error(f, [&] { read_png(f.string()); });
}

}  // namespace wb::test
