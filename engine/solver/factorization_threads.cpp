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

// CHOLMOD opens an OpenMP parallel region per supernode. Made serial, each region still costs
// libgomp a team allocation and a futex wake-up on its barrier: about 10,000 system calls per
// factorization of a 10k-vertex shell, 40 % of the factorization's time on the 2-core virtual
// machines PSQ is measured on (docs/benchmarks.md). A region that the runtime would run on one thread anyway (OpenMP
// max-active-levels 0, as use_single_threaded_factorization sets) is therefore run here as a
// plain call of its body on the calling thread, which is what libgomp would do, without the
// team; any other region goes to libgomp. Defined in the executable, this symbol is the one
// libcholmod's calls bind to (the executable comes first in the dynamic linker's search).
extern "C" void GOMP_parallel(void (*body)(void*), void* data, unsigned num_threads,
                              unsigned flags) {
  using MaxActiveLevels = int (*)();
  using ParallelRegion = void (*)(void (*)(void*), void*, unsigned, unsigned);
  static const auto max_active_levels =
      reinterpret_cast<MaxActiveLevels>(dlsym(RTLD_NEXT, "omp_get_max_active_levels"));
  if (max_active_levels != nullptr && max_active_levels() == 0) {
    body(data);
    return;
  }
  static const auto runtime =
      reinterpret_cast<ParallelRegion>(dlvsym(RTLD_NEXT, "GOMP_parallel", "GOMP_4.0"));
  // No libgomp entry point behind this one (another OpenMP runtime): the body runs serially.
  if (runtime == nullptr) {
    body(data);
    return;
  }
  runtime(body, data, num_threads, flags);
}
