#include "studio/latency.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace wb::studio {
namespace {

/// The q-quantile of `v` by nearest rank (v is reordered).
double nearest_rank(std::vector<float>& v, double q) {
  const size_t k = size_t(std::max(1.0, std::ceil(q * double(v.size())))) - 1;
  std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(k), v.end());
  return v[k];
}

}  // namespace

void LatencyLog::add(const InputTiming& t, double at) {
  entries_.push_back({at,
                      {float((at - t.event) * 1e3), float((t.consumed - t.event) * 1e3),
                       float((t.published - t.consumed) * 1e3), float((at - t.published) * 1e3)}});
  if (entries_.size() > kKeep) {
    entries_.pop_front();
    ++first_;
  }
}

LatencySummary LatencyLog::summary(int64_t from, LatencyPart part) const {
  const size_t skip = size_t(std::clamp<int64_t>(from - first_, 0, int64_t(entries_.size())));
  std::vector<float> ms;
  ms.reserve(entries_.size() - skip);
  for (size_t i = skip; i < entries_.size(); ++i) ms.push_back(entries_[i].ms[int(part)]);
  LatencySummary s;
  s.count = int64_t(ms.size());
  if (ms.empty()) return s;
  s.median_ms = nearest_rank(ms, 0.5);
  s.p95_ms = nearest_rank(ms, 0.95);
  return s;
}

double LatencyLog::current_ms(double now) {
  std::vector<float> ms;
  for (auto it = entries_.rbegin(); it != entries_.rend() && it->at >= now - 1.0; ++it) ms.push_back(it->ms[0]);
  if (!ms.empty()) last_current_ = nearest_rank(ms, 0.5);
  return last_current_;
}

}  // namespace wb::studio
