// Reading and writing the project's JSON files (strokes, brushes, grounds, MyPaint dumps): values
// checked against their ranges with messages naming `file: path.key`, and floats written as the
// shortest decimal that reads back to the same float.
#pragma once
#include <array>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace wb {

/// Larger magnitudes are not measurements but corrupt data (no canvas is 10^7 cells).
constexpr double kAbsurdValue = 1e7;

/// v with up to 10 significant digits, for messages.
std::string number_text(double v);
/// "a string ("..."), null, a boolean, an array, an object or a number", for messages.
std::string json_type_name(const nlohmann::json& v);
/// Float written as the shortest decimal that reads back to the same float, so files show 0.1
/// rather than 0.10000000149011612.
double float_for_json(float v);

/// Reads values of one JSON object, naming `source: path.key` in every message and
/// collecting unknown keys.
class ObjectReader {
 public:
  ObjectReader(const nlohmann::json& j, std::string source, std::string path);

  [[noreturn]] void fail(const std::string& msg, const char* key = nullptr) const;
  std::string where(const char* key) const;

  bool has(const char* key);
  const nlohmann::json& raw(const char* key);

  double number(const char* key, double lo, double hi) { return check_number(raw(key), key, lo, hi); }
  double number_or(const char* key, double def, double lo, double hi) {
    return has(key) ? check_number(j_.at(key), key, lo, hi) : def;
  }
  int integer(const char* key, int lo, int hi) { return check_integer(raw(key), key, lo, hi); }
  int integer_or(const char* key, int def, int lo, int hi) {
    return has(key) ? check_integer(j_.at(key), key, lo, hi) : def;
  }
  bool boolean_or(const char* key, bool def);
  std::string string(const char* key);
  /// Array of 3 numbers in [lo, hi].
  std::array<float, 3> triple(const char* key, double lo, double hi);

  double check_number(const nlohmann::json& v, const char* key, double lo, double hi) const;
  int check_integer(const nlohmann::json& v, const char* key, int lo, int hi) const;

  /// Keys present but never asked for.
  std::vector<std::string> unknown_keys() const;
  /// Each unknown key as a warning ("... ignored").
  void warn_unknown(std::vector<std::string>& warnings) const;
  /// Fails on the first unknown key: for objects where a misspelt key would silently change the result.
  void refuse_unknown() const;

 private:
  const nlohmann::json& j_;
  std::string source_;
  std::string path_;
  std::vector<std::string> seen_;
};

}  // namespace wb
