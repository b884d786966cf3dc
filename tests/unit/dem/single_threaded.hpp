// Small DEM systems in unit tests are stepped on one thread: a step has several OpenMP regions,
// and for a few dozen bodies their barriers cost more than the work (badly so on a loaded
// machine). Results do not depend on the thread count (DemThreads.BitIdenticalOnOneAndThreeThreads
// checks that). Include once per test program.
#pragma once
#include <gtest/gtest.h>
#include <omp.h>

namespace ff::test {
class SingleThreaded : public ::testing::Environment {
 public:
  void SetUp() override { omp_set_num_threads(1); }
};
[[maybe_unused]] inline ::testing::Environment* const kSingleThreaded =
    ::testing::AddGlobalTestEnvironment(new SingleThreaded);
}  // namespace ff::test
