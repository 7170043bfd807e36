// The CLI as a user meets it: every subcommand has --help, bad stroke files give a clear
// message and a non-zero exit (never a crash), and a replay writes its image and stats.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

namespace wb::test {
namespace {

struct RunResult {
  int exit_code = -1;
  bool crashed = false;
  std::string output;  // stdout and stderr together
};

RunResult run_cli(const std::string& args) {
  const std::string cmd = std::string(WB_CLI_PATH) + " " + args + " 2>&1";
  RunResult r;
  FILE* pipe = popen(cmd.c_str(), "r");
  if (!pipe) return r;
  std::array<char, 4096> buf{};
  while (fgets(buf.data(), int(buf.size()), pipe)) r.output += buf.data();
  const int status = pclose(pipe);
  r.crashed = WIFSIGNALED(status);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

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
  for (const char* sub : {"replay", "bench", "devices", "params", "solver-study"}) {
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
  const nlohmann::json& step = j["stages"]["sim.step"];
  EXPECT_EQ(step["calls"].get<int>(), j["steps"].get<int>());
  EXPECT_GE(step["p90_ms"].get<double>(), step["median_ms"].get<double>());
  for (const auto& [name, st] : j["stages"].items())
    EXPECT_LE(st["median_ms"].get<double>(), step["p90_ms"].get<double>() * 1.01 + 1e-3) << name << " longer than a step";
  EXPECT_NE(run_cli("bench --device cpu " + data("strokes/bad/empty.json")).exit_code, 0);
  std::filesystem::remove_all(dir);
}

}  // namespace wb::test
