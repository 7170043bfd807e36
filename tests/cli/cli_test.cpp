// The CLI as a user meets it: every subcommand has --help, bad stroke files give a clear
// message and a non-zero exit (never a crash), and a replay writes its image and stats.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <zip.h>

#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>
#include <string>

#include "core/io/document.h"
#include "run_cli.h"

namespace wb::test {
namespace {

std::string data(const std::string& rel) { return std::string(WB_TEST_DATA_DIR) + "/" + rel; }

std::filesystem::path temp_dir(const std::string& name) {
  auto p = std::filesystem::temp_directory_path() / ("wetbrush-cli-" + name + "-" + std::to_string(::getpid()));
  std::filesystem::create_directories(p);
  return p;
}

}  // namespace

TEST(Cli, EverySubcommandHasHelp) {
  const RunResult top = run_cli("--help");
  EXPECT_EQ(top.exit_code, 0) << top.output;
  // Every command that runs kernels takes --device; `params` only prints the table.
  for (const char* sub : {"replay", "bench", "soak", "devices", "params", "solver-study"}) {
    const RunResult r = run_cli(std::string(sub) + " --help");
    EXPECT_EQ(r.exit_code, 0) << sub << ": " << r.output;
    if (std::string(sub) != "params")
      EXPECT_NE(r.output.find("--device"), std::string::npos) << sub << " lacks --device";
  }
}

TEST(Cli, DevicesListsTheCpu) {
  const RunResult r = run_cli("devices --check");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("cpu"), std::string::npos);
  EXPECT_NE(r.output.find("self-test: ok"), std::string::npos) << r.output;
}

TEST(Cli, BadStrokeFilesFailCleanly) {
  int checked = 0;
  for (const auto& entry : std::filesystem::directory_iterator(data("strokes/bad"))) {
    const std::string path = entry.path().string();
    const RunResult r = run_cli("replay --device cpu -q '" + path + "'");
    EXPECT_FALSE(r.crashed) << path;
    EXPECT_NE(r.exit_code, 0) << path << " was accepted: " << r.output;
    EXPECT_NE(r.output.find("error"), std::string::npos) << path << ": " << r.output;
    EXPECT_NE(r.output.find(entry.path().filename().string()), std::string::npos)
        << "message does not name the file: " << r.output;
    ++checked;
  }
  EXPECT_GE(checked, 15);
}

TEST(Cli, ErrorsNameTheSourceLocationOnlyWhenVerbose) {
  // A stroke file without its samples: the message names the file and the missing key; the
  // source line that raised it is for a bug report (--verbose anywhere on the line, or
  // WB_VERBOSE=1).
  const std::string bad = "'" + data("strokes/bad/missing-samples.json") + "'";
  const std::regex location(R"(\[[A-Za-z_0-9]+\.(cpp|h|cu):[0-9]+\])");
  const RunResult plain = run_cli("replay --device cpu -q " + bad);
  EXPECT_EQ(plain.exit_code, 1) << plain.output;
  EXPECT_NE(plain.output.find("missing-samples.json: top level: missing required key 'samples'"), std::string::npos)
      << plain.output;
  EXPECT_FALSE(std::regex_search(plain.output, location)) << plain.output;
  for (const std::string& args : {"replay --device cpu -q --verbose " + bad, "--verbose replay --device cpu -q " + bad}) {
    const RunResult r = run_cli(args);
    EXPECT_EQ(r.exit_code, 1) << args << ": " << r.output;
    EXPECT_TRUE(std::regex_search(r.output, location)) << args << ": " << r.output;
  }
  ::setenv("WB_VERBOSE", "1", 1);
  const RunResult env = run_cli("replay --device cpu -q " + bad);
  ::unsetenv("WB_VERBOSE");
  EXPECT_EQ(env.exit_code, 1) << env.output;
  EXPECT_TRUE(std::regex_search(env.output, location)) << "WB_VERBOSE=1: " << env.output;
}

TEST(Cli, ProgressLinesReachALog) {
  // Standard error is a pipe here, as in a log: whole lines, steps done of the total with the
  // simulated, elapsed and remaining time, every --progress-every seconds and at the end; -q none.
  const std::string args = "replay --device cpu --grid-only --progress-every 0.1 " + data("strokes/good/tablet.txt");
  const RunResult r = run_cli(args);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::regex line(R"(step ([0-9]+)/([0-9]+)  [0-9.]+ s simulated  .* [0-9]+ s elapsed, [0-9]+ s left)");
  int lines = 0;
  std::string last;
  std::istringstream in(r.output);
  for (std::string l; std::getline(in, l);) {
    std::smatch m;
    if (!std::regex_match(l, m, line)) continue;
    ++lines;
    last = m[1] == m[2] ? "the final count" : l;
  }
  EXPECT_GE(lines, 2) << r.output;
  EXPECT_EQ(last, "the final count") << r.output;
  EXPECT_EQ(r.output.find('\r'), std::string::npos) << "no terminal redraws in a log";
  const RunResult quiet = run_cli(args + " -q");
  ASSERT_EQ(quiet.exit_code, 0) << quiet.output;
  EXPECT_EQ(quiet.output.find(" s left"), std::string::npos) << quiet.output;
}

TEST(Cli, AWindowTooLargeForTheMemoryIsRefusedAtOnce) {
  // A valid stroke file asking for the largest window it may (1024 x 1024 x 64: 67 M cells, about
  // 23 GiB) against a 2 GiB budget: refused before it allocates, in under a second, its resident
  // memory within 100 MB of the program's own (a sanitizer build's start alone is ~120 MB).
  const auto dir = temp_dir("huge-window");
  const std::string f = (dir / "huge-window.json").string();
  std::ofstream(f) << R"({"format": "wetbrush-stroke", "version": 1, "canvas": {"width": 2048, "height": 2048},
    "simulation": {"window": [1024, 1024, 64]},
    "samples": [{"t": 0.0, "x": 100, "y": 128, "pressure": 0.0}, {"t": 0.5, "x": 200, "y": 128, "pressure": 0.6}]})";
  // The largest resident size of the children waited for so far: the program's start first.
  const auto peak_kib = [] {
    rusage use{};
    getrusage(RUSAGE_CHILDREN, &use);
    return use.ru_maxrss;
  };
  ASSERT_EQ(run_cli("--version").exit_code, 0);
  const long start_kib = peak_kib();
  const auto t0 = std::chrono::steady_clock::now();
  const RunResult r = run_cli("replay --device cpu -q --memory-limit 2G " + f);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_FALSE(r.crashed) << r.output;
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("1024 x 1024 x 64 cells needs about"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("--memory-limit 2.00 GiB"), std::string::npos) << r.output;
  EXPECT_LT(seconds, 1.0) << r.output;
  EXPECT_LT(peak_kib(), start_kib + 100 * 1024) << "KiB resident at most (the program's start: " << start_kib << ")";
  const RunResult bad = run_cli("replay --device cpu -q --memory-limit lots " + f);
  EXPECT_EQ(bad.exit_code, 1) << bad.output;
  EXPECT_NE(bad.output.find("memory size 'lots'"), std::string::npos) << bad.output;
  std::filesystem::remove_all(dir);
}

TEST(Cli, BadOptionsFailCleanly) {
  EXPECT_NE(run_cli("replay --device quantum " + data("strokes/good/minimal.json")).exit_code, 0);
  EXPECT_NE(run_cli("replay /nonexistent/stroke.json").exit_code, 0);
  const RunResult shape = run_cli("replay --device cpu -q --brush spoon " + data("strokes/good/minimal.json"));
  EXPECT_NE(shape.exit_code, 0);
  EXPECT_NE(shape.output.find("spoon"), std::string::npos) << shape.output;
}

TEST(Cli, ReplayWritesImageAndStats) {
  const auto dir = temp_dir("replay");
  const std::string png = (dir / "out.png").string(), stats = (dir / "stats.json").string();
  const RunResult r = run_cli("replay --device cpu -q " + data("strokes/good/tablet.txt") + " -o " + png +
                              " --stats " + stats + " --frames " + (dir / "frames").string() + " --every 5");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_GT(std::filesystem::file_size(png), 100u);
  std::ifstream f(stats);
  const nlohmann::json j = nlohmann::json::parse(f);
  EXPECT_GT(j["steps"].get<int>(), 0);
  EXPECT_EQ(j["device"], "cpu");
  EXPECT_EQ(j["nonfinite_events"], 0);
  EXPECT_EQ(j["brush"]["vertices_per_bristle"], 10);
  EXPECT_EQ(j["brush"]["samples_per_bristle"], 128);
  EXPECT_LT(j["brush"]["max_stretch"].get<double>(), 0.01);  // segment lengths held within 1%
  EXPECT_GT(j["brush"]["contact_cells_max"].get<int>(), 0);   // the pen went down: bristles touched
  EXPECT_GT(j["timing_ms"]["step_median"].get<double>(), 0.0);
  EXPECT_TRUE(j["wall_ms"].is_number());
  EXPECT_FALSE(std::filesystem::is_empty(dir / "frames"));
  std::filesystem::remove_all(dir);
}

TEST(Cli, ScumbleKeepsItsBooksOverTheDriedTracesOfItsStrokes) {
  // examples/scumble.json: dark strokes dried, then a light brush over them. A stroke that dried
  // leaves the thin top of its wet paint as dried traces thinner than half a cell, neither solid
  // nor liquid; the passes bounded by the grid's extent must see them (docs/GRID.md "Work in
  // proportion to the paint"). Left out of the extent they lost or made paint: the books drifted
  // 2.4e-5, where every example keeps them to 1e-7.
  const auto dir = temp_dir("scumble");
  const std::string stats = (dir / "stats.json").string();
  const RunResult r = run_cli("replay --device cpu -q " + std::string(WB_SOURCE_DIR) + "/examples/scumble.json --stats " + stats);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::ifstream f(stats);
  const nlohmann::json j = nlohmann::json::parse(f);
  EXPECT_LT(std::abs(j["paint"]["mass_drift"].get<double>()), 1e-6);
  EXPECT_EQ(j["nonfinite_events"], 0);
  std::filesystem::remove_all(dir);
}

TEST(Cli, ReplayOptionsOverrideTheStrokeFilesWindowAndTilt) {
  // A recording carries its window and tilt (the studio's do); --window and --set are what the
  // replay runs, not undone when the session takes the stroke.
  const auto dir = temp_dir("override");
  std::ifstream in(data("strokes/good/minimal.json"));
  nlohmann::json stroke = nlohmann::json::parse(in);
  stroke["simulation"]["window"] = {32, 32, 8};
  stroke["canvas"]["tilt"] = 10;
  const std::string file = (dir / "windowed.json").string(), stats = (dir / "stats.json").string();
  std::ofstream(file) << stroke.dump();
  const auto replayed = [&](const std::string& options) {
    const RunResult r = run_cli("replay --device cpu -q " + file + options + " --stats " + stats);
    EXPECT_EQ(r.exit_code, 0) << r.output;
    std::ifstream f(stats);
    return nlohmann::json::parse(f, nullptr, false);
  };
  const nlohmann::json j = replayed(" --window 48,40,8 --set grid.tilt=30");
  EXPECT_EQ(j["window"], nlohmann::json({48, 40, 8}));
  EXPECT_NEAR(j.value("tilt_deg", -1.0), 30.0, 1e-6);
  const nlohmann::json k = replayed("");  // without the options, the file's own
  EXPECT_EQ(k["window"], nlohmann::json({32, 32, 8}));
  EXPECT_NEAR(k.value("tilt_deg", -1.0), 10.0, 1e-6);
  std::filesystem::remove_all(dir);
}

TEST(Cli, BenchReportsEveryStageTheStepRateAndMemory) {
  const auto dir = temp_dir("bench");
  const std::string out = (dir / "bench.json").string();
  const RunResult r =
      run_cli("bench --device cpu " + data("strokes/good/minimal.json") + " --window 32,32,8 --json " + out);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  for (const char* row : {"sim.step", "grid.advect", "brush.step", "step rate", "memory"})
    EXPECT_NE(r.output.find(row), std::string::npos) << "no '" << row << "' in:\n" << r.output;
  std::ifstream f(out);
  const nlohmann::json j = nlohmann::json::parse(f);
  EXPECT_GT(j["steps"].get<int>(), 0);
  EXPECT_GT(j["step_rate"].get<double>(), 0.0);
  EXPECT_GT(j["memory_peak_bytes"].get<double>(), 1e5) << "the window and the brush alone hold more";
  // Every other step is timed whole (its stages untimed), the others stage by stage.
  const nlohmann::json& step = j["stages"]["sim.step"];
  const nlohmann::json& whole = j["stages"]["sim.step:whole"];
  EXPECT_EQ(step["calls"].get<int>() + whole["calls"].get<int>(), j["steps"].get<int>());
  EXPECT_NEAR(step["calls"].get<int>(), whole["calls"].get<int>(), 1);
  EXPECT_EQ(j["stages"].count("grid.advect:whole"), 0u) << "an inner scope was timed in a whole step";
  EXPECT_GE(step["p90_ms"].get<double>(), step["median_ms"].get<double>());
  EXPECT_GT(j["step_median_ms"].get<double>(), 0.0);
  // Host reads of device results: every step makes some (the books' record at least), and
  // launches, counted alike on either backend.
  EXPECT_GE(j["host_waits_per_step"].get<double>(), 1.0);
  EXPECT_GE(step["host_reads_mean"].get<double>(), 1.0);
  EXPECT_GT(j["launches_per_step"].get<double>(), 10.0);
  EXPECT_GE(step["launches_mean"].get<double>(), j["stages"]["grid.advect"]["launches_mean"].get<double>());
  for (const auto& [name, st] : j["stages"].items())
    if (name.find(":whole") == std::string::npos)
      EXPECT_LE(st["median_ms"].get<double>(), step["p90_ms"].get<double>() * 1.01 + 1e-3) << name << " longer than a step";
  EXPECT_NE(run_cli("bench --device cpu " + data("strokes/bad/empty.json")).exit_code, 0);
  std::filesystem::remove_all(dir);
}

TEST(Cli, SoakReportsMemoryStepTimeAndBooksPerRun) {
  // One cycle (the shortest soak): a line per run and a JSON of the figures; a fresh simulator
  // per run leaves no backend memory held after it.
  const auto dir = temp_dir("soak");
  const std::string out = (dir / "soak.json").string();
  const RunResult r = run_cli("soak --device cpu --minutes 0.001 " + data("strokes/good/minimal.json") + " --json " + out);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("soak: 1 cycles"), std::string::npos) << r.output;
  std::ifstream f(out);
  const nlohmann::json j = nlohmann::json::parse(f);
  ASSERT_EQ(j["runs"].size(), 1u);
  EXPECT_GT(j["runs"][0]["steps"].get<int>(), 0);
  EXPECT_GT(j["runs"][0]["resident_bytes"].get<double>(), 1e6);
  // The program's own code is paged in from its file: part of the resident figure, not all of it.
  EXPECT_GT(j["runs"][0]["resident_file_bytes"].get<double>(), 1e5);
  EXPECT_LT(j["runs"][0]["resident_file_bytes"].get<double>(), j["runs"][0]["resident_bytes"].get<double>());
  EXPECT_TRUE(j["runs"][0].contains("heap_bytes"));  // the C library's figure (0 under a sanitizer's allocator)
  EXPECT_EQ(j["backend_held_max_bytes"].get<double>(), 0.0) << "a replay's buffers outlived its simulator";
  EXPECT_LE(j["drift_max"].get<double>(), 1e-4);
  EXPECT_NE(run_cli("soak --device cpu --minutes -1 " + data("strokes/good/minimal.json")).exit_code, 0);
  std::filesystem::remove_all(dir);
}

// Privacy (docs/RELIABILITY.md): a saved painting records no path of the machine that made it,
// only the file names the user chose; checked in every entry of the archive, uncompressed.
namespace {
std::string archive_text(const std::string& path) {
  int err = 0;
  zip_t* za = zip_open(path.c_str(), ZIP_RDONLY, &err);
  if (!za) return {};
  std::string all;
  for (zip_int64_t i = 0; i < zip_get_num_entries(za, 0); ++i) {
    zip_stat_t st;
    zip_stat_index(za, zip_uint64_t(i), 0, &st);
    std::string b(size_t(st.size), '\0');
    zip_file_t* f = zip_fopen_index(za, zip_uint64_t(i), 0);
    if (f && !b.empty()) zip_fread(f, b.data(), b.size());
    if (f) zip_fclose(f);
    all += std::string(st.name) + "\n" + b + "\n";
  }
  zip_close(za);
  return all;
}
}  // namespace

TEST(Cli, SavedPaintingsRecordNoPath) {
  const auto dir = temp_dir("privacy");
  ASSERT_TRUE(dir.is_absolute());
  const std::string stroke = (dir / "private-stroke.json").string();
  std::ofstream(stroke) << R"({"format": "wetbrush-stroke", "version": 1, "canvas": {"width": 64, "height": 48},
    "samples": [{"t": 0.0, "x": 30, "y": 24, "pressure": 0.0}, {"t": 0.05, "x": 34, "y": 24, "pressure": 0.5}]})";
  const std::string ora = (dir / "p.ora").string();
  const RunResult r = run_cli("replay --device cpu -q " + stroke + " --window 32,32,8 -o " + (dir / "p.png").string() +
                              " --save " + ora);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const Painting p = load_painting(ora, Device(DeviceType::CPU));
  EXPECT_EQ(p.metadata.at("stroke"), "private-stroke.json");
  const std::string text = archive_text(ora);
  ASSERT_NE(text.find("wetbrush/metadata.json"), std::string::npos);
  EXPECT_EQ(text.find(dir.string()), std::string::npos) << "the painting records " << dir << ":\n" << p.metadata.dump();

  // A painting rendered and saved again names its source file, not where it lies.
  const std::string again = (dir / "again.ora").string();
  const RunResult r2 = run_cli("render --device cpu " + ora + " -o " + (dir / "again.png").string() + " --save " + again);
  ASSERT_EQ(r2.exit_code, 0) << r2.output;
  EXPECT_EQ(load_painting(again, Device(DeviceType::CPU)).metadata.at("source"), "p.ora");
  EXPECT_EQ(archive_text(again).find(dir.string()), std::string::npos);
  std::filesystem::remove_all(dir);
}

}  // namespace wb::test
