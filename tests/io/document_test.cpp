// Painting files (OpenRaster + wetbrush volume): exact round trips, the OpenRaster structure
// other programs rely on, atomic saves, and clear errors for every kind of bad file.
#include <unistd.h>
#include <zip.h>

#include <algorithm>
#include <cstring>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>

#include "backend_fixture.h"
#include "core/io/atomic_file.h"
#include "core/io/document.h"
#include "core/io/png.h"
#include "core/render/test_volumes.h"
#include "io/test_zip.h"

namespace wb::test {

namespace fs = std::filesystem;

namespace {
std::string fresh_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("wetbrush_doc_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d.string();
}
}  // namespace

class DocumentTest : public BackendTest {
 protected:
  // Random paint on a small canvas, values on the stored lattice, some tiles left empty.
  TileStore random_canvas(CanvasDims d, unsigned seed) {
    TileStore c(device_, d);
    fill_volume(c, 0, 0, d.width, d.height / 2 + 3, [&](int x, int y, int z) {
      PaintCell p;
      // Deterministic per cell (fill_volume may run tiles in any order).
      std::mt19937 r(seed ^ unsigned(x) * 73856093u ^ unsigned(y) * 19349663u ^ unsigned(z) * 83492791u);
      std::uniform_real_distribution<float> v(0.f, 1.f);
      if (v(r) < 0.3f) return p;
      p.density = v(r) * 1.3f;
      p.pigment_r = v(r);
      p.pigment_y = v(r);
      p.pigment_b = v(r);
      p.oil = v(r);
      p.dryness = v(r);
      return p;
    });
    return c;
  }
  Image merged_for(TileStore& c) {
    Renderer r(device_);
    r.params().ao_rays = 0;  // the picture's quality does not matter here
    return r.render(c, Camera::top(c.dims()));
  }
  static void expect_same_volume(const TileStore& a, const TileStore& b) {
    ASSERT_EQ(a.dims(), b.dims());
    auto ia = a.allocated_tile_ids(), ib = b.allocated_tile_ids();
    std::sort(ia.begin(), ia.end());
    std::sort(ib.begin(), ib.end());
    ASSERT_EQ(ia, ib);
    for (int id : ia) {
      const TileData ta = a.read_tile(id), tb = b.read_tile(id);
      ASSERT_EQ(std::memcmp(ta.density.data(), tb.density.data(), ta.density.size() * 4), 0) << "tile " << id;
      ASSERT_EQ(ta.pigment_r, tb.pigment_r);
      ASSERT_EQ(ta.pigment_y, tb.pigment_y);
      ASSERT_EQ(ta.pigment_b, tb.pigment_b);
      ASSERT_EQ(ta.oil, tb.oil);
      ASSERT_EQ(ta.dryness, tb.dryness);
    }
  }
};

TEST_F(DocumentTest, SaveLoadRoundTripIsExact) {
  const std::string dir = fresh_dir("roundtrip");
  for (CanvasDims d : {CanvasDims{64, 48, 8}, CanvasDims{100, 37, 5}}) {
    TileStore c = random_canvas(d, 42);
    const nlohmann::json meta = {{"title", "test"}, {"strokes", 3}, {"brush", {{"shape", "round"}}}};
    const std::string path = dir + "/p.ora";
    save_painting(path, c, merged_for(c), meta);
    Painting p = load_painting(path, device_);
    expect_same_volume(c, p.canvas);
    EXPECT_EQ(p.metadata, meta);
    Workspace ws(device_);
    EXPECT_EQ(p.canvas.total_density(), c.total_density());
  }
  // An empty canvas round-trips too.
  TileStore e(device_, CanvasDims{40, 40, 4});
  save_painting(dir + "/e.ora", e, merged_for(e), nullptr);
  EXPECT_EQ(load_painting(dir + "/e.ora", device_).canvas.allocated_tiles(), 0);
  fs::remove_all(dir);
}

TEST_F(DocumentTest, PaletteRoundTripsAndADamagedOneIsNamed) {
  const std::string dir = fresh_dir("palette");
  TileStore c = random_canvas(CanvasDims{64, 48, 8}, 3), pal = random_canvas(CanvasDims{40, 24, 8}, 5);
  SaveOptions with_palette;
  with_palette.palette = &pal;
  save_painting(dir + "/p.ora", c, merged_for(c), nullptr, with_palette);
  Painting p = load_painting(dir + "/p.ora", device_);
  expect_same_volume(c, p.canvas);
  ASSERT_TRUE(p.palette.has_value());
  expect_same_volume(pal, *p.palette);
  save_painting(dir + "/n.ora", c, merged_for(c), nullptr);
  EXPECT_FALSE(load_painting(dir + "/n.ora", device_).palette.has_value()) << "no palette saved, none read";
  // A damaged palette is refused, and the message says it is the palette.
  std::vector<uint8_t> file = read_file(dir + "/p.ora");
  const std::vector<uint8_t> v = encode_volume(pal);
  const auto at = std::search(file.begin(), file.end(), v.begin(), v.end());
  ASSERT_NE(at, file.end()) << "the palette is stored uncompressed";
  file[size_t(at - file.begin()) + v.size() / 2] ^= 0x5a;
  try {
    load_painting_bytes(file.data(), file.size(), "damaged.ora", device_);
    ADD_FAILURE() << "a damaged palette was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("damaged.ora: palette (wetbrush/palette.bin)"), std::string::npos) << e.what();
  }
  fs::remove_all(dir);
}

TEST_F(DocumentTest, FileIsAnOpenRasterImage) {
  const std::string dir = fresh_dir("ora");
  TileStore c = random_canvas(CanvasDims{600, 300, 2}, 7);
  const Image merged = merged_for(c);
  save_painting(dir + "/p.ora", c, merged, {});
  int err = 0;
  zip_t* za = zip_open((dir + "/p.ora").c_str(), ZIP_RDONLY | ZIP_CHECKCONS, &err);
  ASSERT_NE(za, nullptr);
  // mimetype first, stored, exactly "image/openraster".
  EXPECT_STREQ(zip_get_name(za, 0, 0), "mimetype");
  zip_stat_t st;
  zip_stat_index(za, 0, 0, &st);
  EXPECT_EQ(st.comp_method, ZIP_CM_STORE);
  auto read = [&](const char* name) {
    zip_stat_t s;
    EXPECT_EQ(zip_stat(za, name, 0, &s), 0) << name;
    std::vector<uint8_t> b(size_t(s.size));
    zip_file_t* f = zip_fopen(za, name, 0);
    zip_fread(f, b.data(), b.size());
    zip_fclose(f);
    return b;
  };
  const auto mt = read("mimetype");
  EXPECT_EQ(std::string(mt.begin(), mt.end()), "image/openraster");
  const auto stack = read("stack.xml");
  const std::string xml(stack.begin(), stack.end());
  EXPECT_NE(xml.find("src=\"data/paint.png\""), std::string::npos);
  EXPECT_NE(xml.find("w=\"600\" h=\"300\""), std::string::npos);
  const auto m = read("mergedimage.png");
  const PngPixels mp = decode_png(m.data(), m.size(), "mergedimage.png");
  EXPECT_EQ(mp.width, 600);
  EXPECT_EQ(mp.height, 300);
  EXPECT_EQ(mp.data8, merged.rgba);
  const auto l = read("data/paint.png");
  EXPECT_EQ(l, m);
  const auto t = read("Thumbnails/thumbnail.png");
  const PngPixels tp = decode_png(t.data(), t.size(), "thumbnail");
  EXPECT_LE(std::max(tp.width, tp.height), 256);
  EXPECT_GT(tp.width, 100);
  zip_close(za);
  fs::remove_all(dir);
}

TEST_F(DocumentTest, FailedSaveLeavesPreviousFileIntact) {
  const std::string dir = fresh_dir("atomic");
  const std::string path = dir + "/p.ora";
  TileStore a = random_canvas(CanvasDims{64, 64, 4}, 1), b = random_canvas(CanvasDims{64, 64, 4}, 2);
  save_painting(path, a, merged_for(a), {{"v", 1}});
  const std::vector<uint8_t> before = read_file(path);
  for (const char* stage : {"partial-write", "before-rename"}) {
    SaveOptions o;
    o.fault_hook = [&](const std::string& s) {
      if (s == stage) throw std::runtime_error(std::string("simulated crash at ") + stage);
    };
    EXPECT_THROW(save_painting(path, b, merged_for(b), {{"v", 2}}, o), std::runtime_error);
    EXPECT_EQ(read_file(path), before) << stage;
    int files = 0;
    for (const auto& e : fs::directory_iterator(dir)) files += e.is_regular_file();
    EXPECT_EQ(files, 1) << "temporary file left behind after a failure at " << stage;
  }
  Painting p = load_painting(path, device_);
  expect_same_volume(a, p.canvas);
  // A directory we cannot write to: a clear error, nothing written.
  EXPECT_THROW(save_painting(dir + "/missing/sub/p.ora", b, merged_for(b), {}), Error);
  // A successful save replaces the file.
  save_painting(path, b, merged_for(b), {{"v", 2}});
  expect_same_volume(b, load_painting(path, device_).canvas);
  fs::remove_all(dir);
}

TEST_F(DocumentTest, VolumeCorruptionIsDetected) {
  TileStore c = random_canvas(CanvasDims{48, 48, 4}, 9);
  const std::vector<uint8_t> v = encode_volume(c);
  expect_same_volume(c, decode_volume(v.data(), v.size(), device_, "mem"));
  // Every single-byte flip and every truncation is rejected with wb::Error, never a crash.
  for (size_t i = 0; i < v.size(); i += std::max<size_t>(1, v.size() / 300)) {
    std::vector<uint8_t> bad = v;
    bad[i] ^= 0x5a;
    EXPECT_THROW(decode_volume(bad.data(), bad.size(), device_, "mem"), Error) << "flip at " << i;
    EXPECT_THROW(decode_volume(v.data(), i, device_, "mem"), Error) << "truncated to " << i;
  }
}

// The committed bad files (tests/data/documents/bad), each with the message it must give.
TEST_F(DocumentTest, BadFilesGiveClearErrors) {
  const std::string bad = std::string(WB_TEST_DATA_DIR) + "/documents/bad/";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"empty.ora", "empty file"},
      {"truncated.ora", "not a ZIP archive"},
      {"no_mimetype.ora", "no 'mimetype' entry"},
      {"wrong_mimetype.ora", "its mimetype is 'application/zip'"},
      {"png_renamed.ora", "this is a PNG image"},
      {"foreign.ora", "without a wetbrush paint volume"},
      {"bad_checksum.ora", "checksum mismatch"},
      {"newer_version.ora", "written by a newer wetbrush (volume format version 2"},
      {"missing.ora", "cannot open"},
  };
  for (const auto& [file, msg] : cases) {
    try {
      load_painting(bad + file, device_);
      ADD_FAILURE() << file << " was accepted";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(msg), std::string::npos) << file << ": " << e.what();
      EXPECT_NE(std::string(e.what()).find(file), std::string::npos) << "message names the file: " << e.what();
    }
  }
}

// Regenerates the bad files: WB_UPDATE_FIXTURES=1 wetbrush_tests --gtest_filter=DocumentTest.WriteBadFixtures
TEST_F(DocumentTest, WriteBadFixtures) {
  if (!std::getenv("WB_UPDATE_FIXTURES")) GTEST_SKIP() << "set WB_UPDATE_FIXTURES=1 to regenerate tests/data/documents/bad";
  const std::string bad = std::string(WB_SOURCE_DIR) + "/tests/data/documents/bad/";
  fs::create_directories(bad);
  TileStore c = random_canvas(CanvasDims{32, 32, 2}, 3);
  const Image merged = merged_for(c);
  const std::string good = bad + "good.tmp";
  save_painting(good, c, merged, {});
  const std::vector<uint8_t> g = read_file(good);
  fs::remove(good);
  write_file_atomic(bad + "empty.ora", std::vector<uint8_t>{});
  write_file_atomic(bad + "truncated.ora", std::vector<uint8_t>(g.begin(), g.begin() + long(g.size() * 6 / 10)));
  const auto png = encode_png8(merged.rgba.data(), merged.width, merged.height, 4);
  write_file_atomic(bad + "png_renamed.ora", png);
  write_file_atomic(bad + "no_mimetype.ora", make_zip({{"stack.xml", bytes_of("<image/>")}, {"mergedimage.png", png}}));
  write_file_atomic(bad + "wrong_mimetype.ora", make_zip({{"mimetype", bytes_of("application/zip")}, {"stack.xml", bytes_of("<image/>")}}));
  write_file_atomic(bad + "foreign.ora", make_zip({{"mimetype", bytes_of("image/openraster")},
                                            {"stack.xml", bytes_of("<image w=\"32\" h=\"32\"><stack/></image>")},
                                            {"mergedimage.png", png}}));
  std::vector<uint8_t> v = encode_volume(c);
  std::vector<uint8_t> flipped = v;
  flipped[v.size() - 5] ^= 0x01;  // inside the last tile's compressed data
  write_file_atomic(bad + "bad_checksum.ora", make_zip({{"mimetype", bytes_of("image/openraster")}, {"wetbrush/volume.bin", flipped}}));
  std::vector<uint8_t> newer = v;
  newer[8] = 2;  // format version 2
  write_file_atomic(bad + "newer_version.ora", make_zip({{"mimetype", bytes_of("image/openraster")}, {"wetbrush/volume.bin", newer}}));
}

}  // namespace wb::test
