#include "core/exec/profile.h"

#include <algorithm>
#include <numeric>

namespace wb {
namespace {
thread_local Profiler* g_current = nullptr;
}

Profiler* Profiler::current() { return g_current; }
int& ProfileScope::depth() {
  thread_local int d = 0;
  return d;
}
void Profiler::set_current(Profiler* p) { g_current = p; }

double Profiler::median_ms(const std::string& name) const {
  auto it = samples_.find(name);
  if (it == samples_.end() || it->second.empty()) return 0.0;
  std::vector<double> v = it->second;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}
double Profiler::total_ms(const std::string& name) const {
  auto it = samples_.find(name);
  return it == samples_.end() ? 0.0 : std::accumulate(it->second.begin(), it->second.end(), 0.0);
}
size_t Profiler::count(const std::string& name) const {
  auto it = samples_.find(name);
  return it == samples_.end() ? 0 : it->second.size();
}
const std::vector<double>& Profiler::samples(const std::string& name) const {
  static const std::vector<double> empty;
  auto it = samples_.find(name);
  return it == samples_.end() ? empty : it->second;
}
const std::vector<int64_t>& Profiler::host_reads(const std::string& name) const {
  static const std::vector<int64_t> empty;
  auto it = reads_.find(name);
  return it == reads_.end() ? empty : it->second;
}
const std::vector<int64_t>& Profiler::launches(const std::string& name) const {
  static const std::vector<int64_t> empty;
  auto it = launches_.find(name);
  return it == launches_.end() ? empty : it->second;
}
std::vector<std::string> Profiler::names() const {
  std::vector<std::string> n;
  for (auto& [k, v] : samples_) n.push_back(k);
  return n;
}

}  // namespace wb
