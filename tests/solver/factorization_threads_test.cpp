// CHOLMOD factorizes single-threaded (its BLAS and its OpenMP loops) unless the user chose.

#include "engine/solver/factorization_threads.hpp"

#include <dlfcn.h>
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <string>

#include "engine/solver/cholmod_solver.hpp"

namespace psq {
namespace {

template <class Function>
Function* runtime_function(const char* name) {
  return reinterpret_cast<Function*>(dlsym(RTLD_DEFAULT, name));
}

TEST(FactorizationThreads, ASolverLeavesOpenBlasOneThreadUnlessTheUserChoseACount) {
  auto* get = runtime_function<int()>("openblas_get_num_threads");
  ASSERT_NE(get, nullptr) << "PSQ is set up with OpenBLAS (scripts/setup.sh)";
  const bool user_choice = std::getenv("OPENBLAS_NUM_THREADS") != nullptr ||
                           std::getenv("GOTO_NUM_THREADS") != nullptr ||
                           std::getenv("OMP_NUM_THREADS") != nullptr;
  const CholmodSolver solver;
  EXPECT_EQ(use_single_threaded_factorization().blas_single, !user_choice);
  if (!user_choice) {
    EXPECT_EQ(get(), 1);
  }
}

TEST(FactorizationThreads, ASolverMakesCholmodsOpenMpRegionsSerialUnlessTheUserChose) {
  auto* get = runtime_function<int()>("omp_get_max_active_levels");
  ASSERT_NE(get, nullptr) << "Debian's CHOLMOD links libgomp";
  const bool user_choice = std::getenv("OMP_THREAD_LIMIT") != nullptr ||
                           std::getenv("OMP_MAX_ACTIVE_LEVELS") != nullptr;
  const CholmodSolver solver;
  EXPECT_EQ(use_single_threaded_factorization().openmp_serial, !user_choice);
  if (!user_choice) {
    EXPECT_EQ(get(), 0);
  }
}

/// What a region body saw: how often it ran, and the OpenMP team it ran in.
struct RegionCalls {
  int (*num_threads)() = nullptr;
  int (*thread_num)() = nullptr;
  std::atomic<int> calls = 0;
  int threads = 0;
  int thread = -1;
};

TEST(FactorizationThreads, CholmodsSerialOpenMpRegionsRunAsPlainCallsWithoutLibgompsTeams) {
  const CholmodSolver solver;  // sets OpenMP serial unless the user chose
  // libcholmod's calls bind to the first GOMP_parallel of the process's global scope: PSQ's.
  void* bound = dlsym(RTLD_DEFAULT, "GOMP_parallel");
  ASSERT_NE(bound, nullptr);
  Dl_info where{};
  ASSERT_NE(dladdr(bound, &where), 0);
  EXPECT_EQ(std::string(where.dli_fname).find("libgomp"), std::string::npos) << where.dli_fname;
  EXPECT_NE(bound, dlvsym(RTLD_NEXT, "GOMP_parallel", "GOMP_4.0"));

  RegionCalls calls;
  calls.num_threads = runtime_function<int()>("omp_get_num_threads");
  calls.thread_num = runtime_function<int()>("omp_get_thread_num");
  ASSERT_NE(calls.num_threads, nullptr);
  ASSERT_NE(calls.thread_num, nullptr);
  auto* region = reinterpret_cast<void (*)(void (*)(void*), void*, unsigned, unsigned)>(bound);
  region(
      [](void* data) {
        auto& c = *static_cast<RegionCalls*>(data);
        if (c.calls++ == 0) {
          c.threads = c.num_threads();
          c.thread = c.thread_num();
        }
      },
      &calls, 4, 0);
  if (use_single_threaded_factorization().openmp_serial) {
    EXPECT_EQ(calls.calls, 1);
    EXPECT_EQ(calls.threads, 1);
    EXPECT_EQ(calls.thread, 0);
  } else {
    EXPECT_GE(calls.calls, 1);
  }
}

}  // namespace
}  // namespace psq
