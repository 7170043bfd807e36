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

void Profiler::add(const char* name, bool whole, double ms, int64_t host_reads, int64_t launches) {
  size_t i = series_.size();
  for (const Key& k : keys_)
    if (k.literal == name && k.whole == whole) {
      i = k.series;
      break;
    }
  if (i == series_.size()) {  // the first call from this literal: the series by its name
    const std::string full = whole ? std::string(name) + ":whole" : std::string(name);
    for (i = 0; i < series_.size() && series_[i].name != full; ++i) {
    }
    if (i == series_.size()) series_.push_back(Series{full, {}, {}, {}});
    keys_.push_back(Key{name, whole, i});
  }
  Series& s = series_[i];
  s.ms.push_back(ms);
  s.reads.push_back(host_reads);
  s.launches.push_back(launches);
}

void Profiler::clear() {
  for (Series& s : series_) {
    s.ms.clear();
    s.reads.clear();
    s.launches.clear();
  }
}

const Profiler::Series* Profiler::find(const std::string& name) const {
  for (const Series& s : series_)
    if (s.name == name) return &s;
  return nullptr;
}

double Profiler::median_ms(const std::string& name) const {
  const Series* s = find(name);
  if (!s || s->ms.empty()) return 0.0;
  std::vector<double> v = s->ms;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}
double Profiler::total_ms(const std::string& name) const {
  const Series* s = find(name);
  return s ? std::accumulate(s->ms.begin(), s->ms.end(), 0.0) : 0.0;
}
size_t Profiler::count(const std::string& name) const {
  const Series* s = find(name);
  return s ? s->ms.size() : 0;
}
const std::vector<double>& Profiler::samples(const std::string& name) const {
  static const std::vector<double> empty;
  const Series* s = find(name);
  return s ? s->ms : empty;
}
const std::vector<int64_t>& Profiler::host_reads(const std::string& name) const {
  static const std::vector<int64_t> empty;
  const Series* s = find(name);
  return s ? s->reads : empty;
}
const std::vector<int64_t>& Profiler::launches(const std::string& name) const {
  static const std::vector<int64_t> empty;
  const Series* s = find(name);
  return s ? s->launches : empty;
}
std::vector<std::string> Profiler::names() const {
  std::vector<std::string> n;
  for (const Series& s : series_)
    if (!s.ms.empty()) n.push_back(s.name);
  std::sort(n.begin(), n.end());
  return n;
}

}  // namespace wb
