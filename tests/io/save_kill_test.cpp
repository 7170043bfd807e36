// Saves that survive kills, full disks and read-only folders (docs/RELIABILITY.md): a child
// process saves a large painting over an existing one and is killed with SIGKILL at 100 moments
// spread over the save; after each, the file is the previous painting or the complete new one
// (never anything else), and the next save removes the killed save's temporary file. A child
// limited by RLIMIT_FSIZE (a full disk) or without write access to the folder gets a clear
// error and the old file stays intact.
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <functional>
#include <random>
#include <thread>

#include "backend_fixture.h"
#include "core/io/atomic_file.h"
#include "core/io/document.h"
#include "core/io/png.h"
#include "core/io/stroke.h"
#include "core/render/test_volumes.h"

namespace wb::test {

namespace fs = std::filesystem;

// The saves run in forked child processes, and a child cannot use its parent's CUDA context:
// these tests are about files, so they hold their paintings on the CPU backend whatever
// WB_DEVICE names (the document tests read and write paintings on every backend).
class SaveKillTest : public ::testing::Test {
 protected:
  void SetUp() override {
    device_ = Device(DeviceType::CPU);
    dir_ = fs::temp_directory_path() / ("wetbrush_kill_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    path_ = (dir_ / "painting.ora").string();
  }
  void TearDown() override {
    std::error_code ec;
    fs::permissions(dir_, fs::perms::owner_all, fs::perm_options::add, ec);
    fs::remove_all(dir_, ec);
  }
  // Paint in every tile (random values: the volume compresses little, so writing takes a
  // good share of the save).
  TileStore painted(CanvasDims d, unsigned seed) {
    TileStore c(device_, d);
    fill_volume(c, 0, 0, d.width, d.height, [&](int x, int y, int z) {
      // A cheap per-cell hash (fill_volume may visit cells in any order).
      uint64_t h = (uint64_t(seed) << 48) ^ (uint64_t(x) << 32) ^ (uint64_t(y) << 12) ^ uint64_t(z);
      auto next = [&h] {
        h += 0x9e3779b97f4a7c15ull;
        uint64_t v = (h ^ (h >> 30)) * 0xbf58476d1ce4e5b9ull;
        v = (v ^ (v >> 27)) * 0x94d049bb133111ebull;
        return float((v ^ (v >> 31)) >> 40) / float(1 << 24);
      };
      PaintCell p;
      p.density = next();
      p.pigment_r = next();
      p.pigment_y = next();
      p.pigment_b = next();
      p.oil = next();
      return p;
    });
    return c;
  }
  static Image flat_image(CanvasDims d, uint8_t value) {
    Image img;
    img.width = d.width;
    img.height = d.height;
    img.rgba.assign(size_t(d.width) * d.height * 4, value);
    return img;
  }
  std::vector<fs::path> temporaries() const {
    std::vector<fs::path> t;
    for (const auto& e : fs::directory_iterator(dir_))
      if (e.path().filename().string().find(".tmp-") != std::string::npos) t.push_back(e.path());
    return t;
  }
  // Runs `fn` in a child process; returns its exit status (waitpid's). The child never returns
  // into the test runner, whatever `fn` throws.
  static int in_child(const std::function<int()>& fn) {
    const pid_t pid = ::fork();
    if (pid == 0) ::_exit(child_exit_code(fn));
    int status = 0;
    ::waitpid(pid, &status, 0);
    return status;
  }
  static int child_exit_code(const std::function<int()>& fn) {
    try {
      return fn();
    } catch (...) {
      return 3;
    }
  }
  Device device_;
  fs::path dir_;
  std::string path_;
};

TEST_F(SaveKillTest, KilledSavesLeaveThePreviousPaintingOrTheNewOne) {
  const CanvasDims d{192, 192, 8};
  const TileStore old_canvas = painted(d, 1), new_canvas = painted(d, 2);
  const Image old_img = flat_image(d, 40), new_img = flat_image(d, 200);
  save_painting(path_, old_canvas, old_img, {{"version", "old"}});
  const std::vector<uint8_t> old_bytes = read_file(path_);
  // The complete new file, and how long one save takes in a child process (the longest of
  // three, measured again every 10 kills: the machine's load changes it).
  const std::string new_path = (dir_ / "new.ora").string();
  auto timed_save = [&] {
    const auto t0 = std::chrono::steady_clock::now();
    EXPECT_EQ(in_child([&] {
                save_painting(new_path, new_canvas, new_img, {{"version", "new"}});
                return 0;
              }),
              0);
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  };
  double save_s = std::max({timed_save(), timed_save(), timed_save()});
  const std::vector<uint8_t> new_bytes = read_file(new_path);
  fs::remove(new_path);
  const std::vector<uint8_t> old_volume = encode_volume(old_canvas), new_volume = encode_volume(new_canvas);
  ASSERT_NE(old_volume, new_volume);
  std::printf("[          ] a save of %zu bytes takes %.3f s in a child process\n", new_bytes.size(), save_s);

  // 100 kills at moments spread evenly over 1.2 x the save's duration, each jittered.
  std::mt19937 rng(15);
  std::uniform_real_distribution<double> jitter(0.0, 1.0);
  int old_seen = 0, new_seen = 0, temporaries_left = 0;
  for (int k = 0; k < 100; ++k) {
    if (k % 10 == 9) {
      save_s = std::max(save_s, timed_save());
      fs::remove(new_path);
    }
    const double at = save_s * 1.2 * (k + jitter(rng)) / 100.0;
    const pid_t pid = ::fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) ::_exit(child_exit_code([&] {
      save_painting(path_, new_canvas, new_img, {{"version", "new"}});
      return 0;
    }));
    std::this_thread::sleep_for(std::chrono::duration<double>(at));
    ::kill(pid, SIGKILL);
    int status = 0;
    ::waitpid(pid, &status, 0);
    // The previous file, byte for byte, or a complete new one (its ZIP entries carry the time
    // of the save, so it is compared by what it holds).
    const bool is_old = read_file(path_) == old_bytes;
    bool is_new = false;
    if (!is_old) {
      const Painting p = load_painting(path_, device_);
      is_new = p.metadata.at("version") == "new" && encode_volume(p.canvas) == new_volume;
    } else if (k % 10 == 0) {  // the previous file also opens as the previous painting
      const Painting p = load_painting(path_, device_);
      EXPECT_EQ(p.metadata.at("version"), "old");
      EXPECT_EQ(encode_volume(p.canvas), old_volume);
    }
    ASSERT_TRUE(is_old || is_new) << "kill " << k << " at " << at << " s left a file that is neither painting";
    old_seen += is_old;
    new_seen += is_new;
    temporaries_left += !temporaries().empty();
    // The next save (here: putting the previous painting back) removes the killed save's
    // temporary file.
    write_file_atomic(path_, old_bytes);
    EXPECT_TRUE(temporaries().empty()) << "kill " << k << ": a temporary file survived the next save";
  }
  std::printf("[          ] 100 kills over %.3f s: %d left the previous painting, %d the new one, %d a "
              "temporary file (removed by the next save)\n",
              save_s * 1.2, old_seen, new_seen, temporaries_left);
  EXPECT_GE(old_seen, 25) << "the kills did not spread over the save";

  // Most of a save is encoding in memory; to be sure of a kill while the temporary file is
  // written and just before the rename, the child kills itself at those two points.
  for (const char* stage : {"partial-write", "before-rename"}) {
    const pid_t pid = ::fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) ::_exit(child_exit_code([&] {
      SaveOptions o;
      o.fault_hook = [&](const std::string& at) {
        if (at == stage) ::raise(SIGKILL);
      };
      save_painting(path_, new_canvas, new_img, {{"version", "new"}}, o);
      return 0;
    }));
    int status = 0;
    ::waitpid(pid, &status, 0);
    ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL) << stage;
    EXPECT_EQ(read_file(path_), old_bytes) << stage;
    EXPECT_EQ(temporaries().size(), 1u) << "the killed save at " << stage << " left its temporary file";
    write_file_atomic(path_, old_bytes);
    EXPECT_TRUE(temporaries().empty()) << "the next save removes the temporary file of a save killed at " << stage;
  }
  const Painting p = load_painting(path_, device_);
  EXPECT_EQ(p.metadata.at("version"), "old");
  EXPECT_EQ(encode_volume(p.canvas), old_volume);
}

// A full disk (RLIMIT_FSIZE: writes beyond the limit fail with EFBIG): a clear error, the old
// file intact, no temporary file left.
TEST_F(SaveKillTest, FullDiskGivesAClearErrorAndKeepsTheOldFile) {
  const CanvasDims d{128, 128, 8};
  const TileStore a = painted(d, 3), b = painted(d, 4);
  save_painting(path_, a, flat_image(d, 10), {{"version", "old"}});
  const std::vector<uint8_t> before = read_file(path_);
  const int status = in_child([&] {
    ::signal(SIGXFSZ, SIG_IGN);  // the write fails with EFBIG instead of killing the process
    rlimit lim{64 * 1024, 64 * 1024};
    if (::setrlimit(RLIMIT_FSIZE, &lim) != 0) return 3;
    try {
      save_painting(path_, b, flat_image(d, 20), {{"version", "new"}});
    } catch (const Error& e) {
      const std::string m = e.what();
      std::fprintf(stderr, "full disk: %s\n", e.what());
      return m.find(path_) != std::string::npos && m.find("save failed: write: File too large") != std::string::npos ? 0 : 2;
    }
    return 1;  // the save succeeded: the limit did not apply
  });
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0) << "1: saved past the limit, 2: unclear message, 3: setrlimit failed";
  EXPECT_EQ(read_file(path_), before);
  EXPECT_TRUE(temporaries().empty());
  EXPECT_EQ(load_painting(path_, device_).metadata.at("version"), "old");
}

// A folder the saving process may not write to: a clear error, the old file intact. As root
// (which may write anywhere) the child first becomes the unprivileged user 65534.
TEST_F(SaveKillTest, ReadOnlyFolderGivesAClearErrorAndKeepsTheOldFile) {
  const CanvasDims d{64, 64, 4};
  const TileStore a = painted(d, 5), b = painted(d, 6);
  save_painting(path_, a, flat_image(d, 10), {{"version", "old"}});
  const std::vector<uint8_t> before = read_file(path_);
  fs::permissions(dir_, fs::perms::owner_read | fs::perms::owner_exec | fs::perms::group_read |
                            fs::perms::group_exec | fs::perms::others_read | fs::perms::others_exec);
  const int status = in_child([&] {
    if (::geteuid() == 0 && (::setgid(65534) != 0 || ::setuid(65534) != 0)) return 3;
    try {
      save_painting(path_, b, flat_image(d, 20), {{"version", "new"}});
    } catch (const Error& e) {
      const std::string m = e.what();
      std::fprintf(stderr, "read-only folder: %s\n", e.what());
      return m.find("cannot create a temporary file in " + dir_.string()) != std::string::npos &&
                     m.find("Permission denied") != std::string::npos
                 ? 0
                 : 2;
    }
    return 1;
  });
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0) << "1: saved into a read-only folder, 2: unclear message, 3: cannot drop root";
  EXPECT_EQ(read_file(path_), before);
  EXPECT_TRUE(temporaries().empty());
}

// Every other file the project writes goes through the same atomic write: a stroke recording,
// an exported PNG map, a JSON report. On a full disk each fails with a clear error and leaves
// the old file whole.
TEST_F(SaveKillTest, EveryWriterOnAFullDiskKeepsTheOldFile) {
  Stroke big;
  big.samples.resize(2000);
  for (size_t i = 0; i < big.samples.size(); ++i) big.samples[i].x = float(i), big.samples[i].t = 0.01 * double(i);
  std::vector<uint8_t> noise(256 * 256 * 3);
  uint32_t h = 12345;
  for (uint8_t& b : noise) b = uint8_t((h = h * 1664525u + 1013904223u) >> 24);  // incompressible
  const std::string text(200 * 1024, 'x');
  const std::vector<std::pair<std::string, std::function<void(const std::string&)>>> writers = {
      {"recording.json", [&](const std::string& f) { save_stroke_json(big, f); }},
      {"normal.png", [&](const std::string& f) { write_png8(f, noise.data(), 256, 256, 3); }},
      {"stats.json", [&](const std::string& f) { write_file_atomic(f, text); }},
  };
  for (const auto& [name, write] : writers) {
    const std::string f = (dir_ / name).string();
    write_file_atomic(f, std::string("old"));
    const int status = in_child([&, f = f, write = write] {
      ::signal(SIGXFSZ, SIG_IGN);
      rlimit lim{16 * 1024, 16 * 1024};
      if (::setrlimit(RLIMIT_FSIZE, &lim) != 0) return 3;
      try {
        write(f);
      } catch (const Error& e) {
        return std::string(e.what()).find(f) != std::string::npos ? 0 : 2;
      }
      return 1;
    });
    ASSERT_TRUE(WIFEXITED(status));
    EXPECT_EQ(WEXITSTATUS(status), 0) << name << ": 1: written past the limit, 2: unclear message, 3: setrlimit";
    const std::vector<uint8_t> now = read_file(f);
    EXPECT_EQ(std::string(now.begin(), now.end()), "old") << name;
  }
  EXPECT_TRUE(temporaries().empty());
}

}  // namespace wb::test
