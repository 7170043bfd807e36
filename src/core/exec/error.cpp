#include "core/exec/error.h"

#include <cstring>

#include "core/exec/dispatch.h"

namespace wb {

void throw_error(const char* file, int line, const std::string& message) {
  const char* base = std::strrchr(file, '/');
  throw Error(message, std::string(base ? base + 1 : file) + ":" + std::to_string(line));
}

namespace detail {
void throw_no_cuda() { throw Error("this binary was built without the CUDA backend (device cuda unavailable)"); }
}  // namespace detail

}  // namespace wb
