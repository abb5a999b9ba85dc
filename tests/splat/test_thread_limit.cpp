#include <gtest/gtest.h>

#include <chrono>
#include <mutex>
#include <set>
#include <thread>

#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include "splat/thread_limit.h"

using namespace saresgs;

namespace {
// The threads that ran a parallel loop of short sleeps (long enough for every worker TBB
// allows to join in).
std::size_t threadsUsed() {
  std::mutex m;
  std::set<std::thread::id> ids;
  tbb::parallel_for(0, 64, [&](int) {
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
    std::lock_guard<std::mutex> lock(m);
    ids.insert(std::this_thread::get_id());
  });
  return ids.size();
}
}  // namespace

// --threads 1 holds all of the process's TBB work, not only the rasterizer's arena, to one
// thread while the limit lives; 0 sets no limit; the limit ends with its object.
TEST(ThreadLimit, OneThreadMeansOneThreadForAllTbbWork) {
  EXPECT_EQ(limitThreads(0), nullptr);
  const std::size_t before = tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism);
  {
    const auto limit = limitThreads(1);
    ASSERT_NE(limit, nullptr);
    EXPECT_EQ(tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism), 1u);
    EXPECT_EQ(threadsUsed(), 1u);
  }
  EXPECT_EQ(tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism), before);
  if (std::thread::hardware_concurrency() >= 2) {
    const auto limit = limitThreads(2);
    EXPECT_LE(threadsUsed(), 2u);
    EXPECT_GE(threadsUsed(), 1u);
  }
}
