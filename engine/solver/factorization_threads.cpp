#include "engine/solver/factorization_threads.hpp"

#include <dlfcn.h>

#include <cstdlib>
#include <initializer_list>
#include <mutex>

namespace psq {
namespace {

bool any_set(std::initializer_list<const char*> names) {
  for (const char* name : names)
    if (std::getenv(name) != nullptr) return true;
  return false;
}

/// Looked up at run time so that PSQ links against any BLAS and OpenMP runtime.
bool call_with(const char* function, int argument) {
  using Setter = void (*)(int);
  auto* set = reinterpret_cast<Setter>(dlsym(RTLD_DEFAULT, function));
  if (set == nullptr) return false;
  set(argument);
  return true;
}

}  // namespace

FactorizationThreading use_single_threaded_factorization() {
  static std::once_flag once;
  static FactorizationThreading done;
  std::call_once(once, [] {
    done.blas_single =
        !any_set({"OPENBLAS_NUM_THREADS", "GOTO_NUM_THREADS", "OMP_NUM_THREADS"}) &&
        call_with("openblas_set_num_threads", 1);
    done.openmp_serial = !any_set({"OMP_THREAD_LIMIT", "OMP_MAX_ACTIVE_LEVELS"}) &&
                         call_with("omp_set_max_active_levels", 0);
  });
  return done;
}

}  // namespace psq
