// The saresgs binary's allocation counter (apps/heap_count.h), compiled into this test
// binary too: every operator new is counted, from any thread, and memory still works.
#include <gtest/gtest.h>

#include <thread>
#include <vector>

#include "apps/heap_count.h"

namespace {
// Stores through a volatile pointer, so the compiler may not elide the allocations.
void* volatile g_sink = nullptr;
}  // namespace

TEST(HeapCount, CountsEveryAllocationFromAnyThread) {
  const std::uint64_t before = saresgs::apps::heapAllocations();
  for (int i = 0; i < 10; ++i) {
    int* p = new int(i);
    g_sink = p;
    delete p;
  }
  EXPECT_EQ(saresgs::apps::heapAllocations() - before, 10u);

  const std::uint64_t before_threads = saresgs::apps::heapAllocations();
  std::thread t([] {
    std::vector<double> v(1000, 1.0);
    g_sink = v.data();
  });
  t.join();
  // The vector's buffer at least (the thread's own start-up may allocate too).
  EXPECT_GE(saresgs::apps::heapAllocations() - before_threads, 1u);

  struct alignas(64) Wide {
    float x[16];
  };
  const std::uint64_t before_aligned = saresgs::apps::heapAllocations();
  Wide* w = new Wide{};
  g_sink = w;
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(w) % 64, 0u);
  delete w;
  EXPECT_EQ(saresgs::apps::heapAllocations() - before_aligned, 1u);
}
