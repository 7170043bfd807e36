// Errors raised by the library: one exception type carrying a precise message.
#pragma once
#include <stdexcept>
#include <string>

namespace wb {

class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& what) : std::runtime_error(what) {}
};

[[noreturn]] void throw_error(const char* file, int line, const std::string& message);

}  // namespace wb

#define WB_THROW(msg) ::wb::throw_error(__FILE__, __LINE__, (msg))
#define WB_REQUIRE(cond, msg)          \
  do {                                 \
    if (!(cond)) WB_THROW((msg));      \
  } while (0)
