#include "engine/solver/blas_threads.hpp"

#include <dlfcn.h>

#include <cstdlib>
#include <mutex>

namespace psq {
namespace {

bool user_chose_thread_count() {
  for (const char* name : {"OPENBLAS_NUM_THREADS", "GOTO_NUM_THREADS", "OMP_NUM_THREADS"})
    if (std::getenv(name) != nullptr) return true;
  return false;
}

/// Looked up at run time so that PSQ links against any BLAS, not only OpenBLAS.
bool set_openblas_threads(int threads) {
  using SetThreads = void (*)(int);
  auto* set = reinterpret_cast<SetThreads>(dlsym(RTLD_DEFAULT, "openblas_set_num_threads"));
  if (set == nullptr) return false;
  set(threads);
  return true;
}

}  // namespace

bool use_single_threaded_blas() {
  static std::once_flag once;
  static bool set = false;
  std::call_once(once, [] { set = !user_chose_thread_count() && set_openblas_threads(1); });
  return set;
}

}  // namespace psq
