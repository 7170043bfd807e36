#include "core/io/json_reader.h"

#include <charconv>
#include <cmath>
#include <cstdlib>
#include <sstream>

#include "core/exec/error.h"

namespace wb {

using nlohmann::json;

std::string number_text(double v) {
  std::ostringstream os;
  os.precision(10);
  os << v;
  return os.str();
}

std::string json_type_name(const json& v) {
  if (v.is_string()) return "a string (" + v.dump() + ")";
  if (v.is_null()) return "null";
  if (v.is_boolean()) return "a boolean";
  if (v.is_array()) return "an array";
  if (v.is_object()) return "an object";
  return "a number";
}

double float_for_json(float v) {
  char buf[32];
  auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::strtod(std::string(buf, r.ptr).c_str(), nullptr);
}

ObjectReader::ObjectReader(const json& j, std::string source, std::string path)
    : j_(j), source_(std::move(source)), path_(std::move(path)) {
  if (!j_.is_object()) fail("expected an object, found " + json_type_name(j_));
}

void ObjectReader::fail(const std::string& msg, const char* key) const {
  WB_THROW(source_ + ": " + where(key) + ": " + msg);
}

std::string ObjectReader::where(const char* key) const {
  if (!key) return path_.empty() ? "top level" : path_;
  return path_.empty() ? std::string(key) : path_ + "." + key;
}

bool ObjectReader::has(const char* key) {
  seen_.push_back(key);
  return j_.contains(key);
}

const json& ObjectReader::raw(const char* key) {
  if (!has(key)) fail("missing required key '" + std::string(key) + "'");
  return j_.at(key);
}

bool ObjectReader::boolean_or(const char* key, bool def) {
  if (!has(key)) return def;
  const json& v = j_.at(key);
  if (!v.is_boolean()) fail("expected true or false, found " + json_type_name(v), key);
  return v.get<bool>();
}

std::string ObjectReader::string(const char* key) {
  const json& v = raw(key);
  if (!v.is_string()) fail("expected a string, found " + json_type_name(v), key);
  return v.get<std::string>();
}

std::array<float, 3> ObjectReader::triple(const char* key, double lo, double hi) {
  const json& v = raw(key);
  if (!v.is_array() || v.size() != 3) fail("expected an array of 3 numbers, found " + json_type_name(v), key);
  std::array<float, 3> out{};
  for (int i = 0; i < 3; ++i) {
    const std::string k = std::string(key) + "[" + std::to_string(i) + "]";
    out[size_t(i)] = float(check_number(v[size_t(i)], k.c_str(), lo, hi));
  }
  return out;
}

double ObjectReader::check_number(const json& v, const char* key, double lo, double hi) const {
  if (!v.is_number()) fail("expected a number, found " + json_type_name(v), key);
  const double d = v.get<double>();
  // Corrupt data gets its own message; a range wider than kAbsurdValue (a brush's seed) is honoured.
  const bool in_range = d >= lo && d <= hi;
  if (!std::isfinite(d) || (std::fabs(d) > kAbsurdValue && !in_range))
    fail(number_text(d) + " is not a plausible value (|v| > 1e7)", key);
  if (!in_range) fail(number_text(d) + " is outside [" + number_text(lo) + ", " + number_text(hi) + "]", key);
  return d;
}

int ObjectReader::check_integer(const json& v, const char* key, int lo, int hi) const {
  const double d = check_number(v, key, lo, hi);
  if (d != std::floor(d)) fail("expected an integer, found " + number_text(d), key);
  return int(d);
}

std::vector<std::string> ObjectReader::unknown_keys() const {
  std::vector<std::string> out;
  for (auto it = j_.begin(); it != j_.end(); ++it) {
    bool known = false;
    for (const std::string& s : seen_) known = known || s == it.key();
    if (!known) out.push_back(it.key());
  }
  return out;
}

void ObjectReader::warn_unknown(std::vector<std::string>& warnings) const {
  for (const std::string& k : unknown_keys())
    warnings.push_back(source_ + ": " + where(nullptr) + ": unknown key '" + k + "' ignored");
}

void ObjectReader::refuse_unknown() const {
  const std::vector<std::string> unknown = unknown_keys();
  if (!unknown.empty()) fail("unknown key '" + unknown.front() + "'");
}

}  // namespace wb
