// Runs the `wetbrush` binary the tests were built with (WB_CLI_PATH) as a user would, with its
// standard output and error together.
#pragma once
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <string>

namespace wb::test {

struct RunResult {
  int exit_code = -1;
  bool crashed = false;
  std::string output;  // stdout and stderr together
};

inline RunResult run_cli(const std::string& args) {
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

}  // namespace wb::test
