// Errors raised by the library: one exception type carrying a precise message.
#pragma once
#include <stdexcept>
#include <string>

namespace wb {

class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message, const std::string& where = {})
      : std::runtime_error(where.empty() ? message : message + " [" + where + "]"), message_(message) {}
  /// The message for the user, without the source location that what() appends for logs.
  const std::string& message() const { return message_; }

 private:
  std::string message_;
};

/// What to show a user for any exception: an Error's message, else what().
inline std::string user_message(const std::exception& e) {
  const auto* w = dynamic_cast<const Error*>(&e);
  return w ? w->message() : e.what();
}

[[noreturn]] void throw_error(const char* file, int line, const std::string& message);

}  // namespace wb

#define WB_THROW(msg) ::wb::throw_error(__FILE__, __LINE__, (msg))
#define WB_REQUIRE(cond, msg)          \
  do {                                 \
    if (!(cond)) WB_THROW((msg));      \
  } while (0)
