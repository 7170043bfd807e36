// The profiler that times every stage of a step: its record of a scope is found without
// allocating, so a step of the simulator allocates nothing to time itself.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <functional>
#include <new>

#include "core/exec/profile.h"

namespace {
// Counts this binary's allocations through operator new while `counting` is set. Every
// replaceable form that a library pairs with another is replaced, all on malloc and free, so
// that each allocation meets its own kind of release (the sanitizer build checks the pairs).
std::atomic<bool> counting{false};
std::atomic<long> allocations{0};

void* counted(std::size_t n) noexcept {
  if (counting.load(std::memory_order_relaxed)) allocations.fetch_add(1, std::memory_order_relaxed);
  return std::malloc(n ? n : 1);
}
void* counted_or_throw(std::size_t n) {
  if (void* p = counted(n)) return p;
  throw std::bad_alloc();
}
}  // namespace

void* operator new(std::size_t n) { return counted_or_throw(n); }
void* operator new[](std::size_t n) { return counted_or_throw(n); }
void* operator new(std::size_t n, const std::nothrow_t&) noexcept { return counted(n); }
void* operator new[](std::size_t n, const std::nothrow_t&) noexcept { return counted(n); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { std::free(p); }

namespace wb::test {
namespace {

long allocations_in(const std::function<void()>& f) {
  allocations = 0;
  counting = true;
  f();
  counting = false;
  return allocations.load();
}

void a_step() {
  // Names longer than a std::string holds without allocating, as most of the step's are.
  WB_PROFILE_SCOPE("step.with.a.long.name");
  for (int i = 0; i < 3; ++i) {
    WB_PROFILE_SCOPE("stage.with.a.long.name");
  }
}

TEST(Profiler, ScopesAllocateNothingOnceSeenAndAfterClear) {
  Profiler prof;
  ProfilerGuard guard(&prof);
  a_step();  // first calls: the series are made
  // 1000 more steps: only the series' own growth allocates (2 series, 3 vectors each, doubling
  // up to 4096 entries: at most 12 times each), not each of the 4000 calls.
  EXPECT_LE(allocations_in([] {
              for (int i = 0; i < 1000; ++i) a_step();
            }),
            2 * 3 * 12);
  EXPECT_EQ(prof.count("step.with.a.long.name"), 1001u);
  EXPECT_EQ(prof.count("stage.with.a.long.name"), 3003u);
  prof.clear();  // a long session clears its profiler often: the storage stays
  EXPECT_EQ(allocations_in([] {
              for (int i = 0; i < 1000; ++i) a_step();
            }),
            0);
  EXPECT_EQ(prof.count("step.with.a.long.name"), 1000u);
  EXPECT_EQ(prof.names().size(), 2u);
}

TEST(Profiler, OutermostOnlyRecordsTheWholeStepUnderItsOwnName) {
  Profiler prof;
  prof.set_outermost(true);
  ProfilerGuard guard(&prof);
  for (int i = 0; i < 5; ++i) a_step();
  EXPECT_EQ(prof.count("step.with.a.long.name:whole"), 5u);
  EXPECT_EQ(prof.count("stage.with.a.long.name"), 0u);
  EXPECT_EQ(prof.count("stage.with.a.long.name:whole"), 0u);
  prof.clear();
  EXPECT_TRUE(prof.names().empty());
  EXPECT_EQ(prof.median_ms("step.with.a.long.name:whole"), 0.0);
}

}  // namespace
}  // namespace wb::test
