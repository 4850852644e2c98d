// CHOLMOD factorizes single-threaded (its BLAS and its OpenMP loops) unless the user chose.

#include "engine/solver/factorization_threads.hpp"

#include <dlfcn.h>
#include <gtest/gtest.h>

#include <cstdlib>

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

}  // namespace
}  // namespace psq
