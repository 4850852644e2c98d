// The BLAS under CHOLMOD runs single-threaded unless the user chose a thread count.

#include "engine/solver/blas_threads.hpp"

#include <dlfcn.h>
#include <gtest/gtest.h>

#include <cstdlib>

#include "engine/solver/cholmod_solver.hpp"

namespace psq {
namespace {

TEST(BlasThreads, ASolverLeavesOpenBlasOneThreadUnlessTheUserChoseACount) {
  using GetThreads = int (*)();
  auto* get = reinterpret_cast<GetThreads>(dlsym(RTLD_DEFAULT, "openblas_get_num_threads"));
  ASSERT_NE(get, nullptr) << "PSQ is set up with OpenBLAS (scripts/setup.sh)";
  const bool user_choice = std::getenv("OPENBLAS_NUM_THREADS") != nullptr ||
                           std::getenv("GOTO_NUM_THREADS") != nullptr ||
                           std::getenv("OMP_NUM_THREADS") != nullptr;
  const CholmodSolver solver;
  EXPECT_EQ(use_single_threaded_blas(), !user_choice);
  if (!user_choice) {
    EXPECT_EQ(get(), 1);
  }
}

}  // namespace
}  // namespace psq
