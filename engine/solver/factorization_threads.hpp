#pragma once
// How many threads CHOLMOD's supernodal factorization may use: the threads of the BLAS under
// it (OpenBLAS) and of its own OpenMP loops.
//
// OpenBLAS (the BLAS that scripts/setup.sh installs) starts one busy-waiting thread per core.
// On the 2-core machines PSQ runs on, every factorization then competes with whatever else
// runs — the test suite's second job, a second sweep worker, a build — and spinning threads
// lose more than they gain. Measured under such load (factorization ms per
// Newton iteration, `bench_drape --sizes 1000,5000,20000 --frames 2`, run as is and with
// OPENBLAS_NUM_THREADS=2; 2 threads → 1): 1.1k vertices 52–59 → 16–25, 5.3k 191–312 → 140–142,
// 21k 1423–1627 → 1110–1354. On a quiet machine two threads gain little (same benchmark, 1 → 2
// threads: 1.1k 19 → 26–29, 5.3k 122–130 → 112–119, 21k 601–606 → 542–558).
//
// CHOLMOD 3 (Debian 12) also opens an OpenMP parallel region per supernode with a fixed
// num_threads(4) clause, which OMP_NUM_THREADS does not cap. Each region wakes and parks
// threads through futex calls, and on a virtual machine those system calls cost more than the
// work of a small supernode. Serializing them (OpenMP max-active-levels 0) was measured with
// the same benchmark on a quiet machine, factorization ms per Newton iteration, parallel →
// serial: 1.1k 18 → 8, 5.3k 124 → 68, 21k 615 → 350.
//
// Even serial, a libgomp region allocates a team and wakes its barrier with a futex call, about
// 10,000 system calls per factorization of a 10k-vertex shell; so a region the runtime would
// run on one thread is run as a plain call (GOMP_parallel in factorization_threads.cpp).
//
// So PSQ factorizes single-threaded unless the user says otherwise.

namespace psq {

/// What use_single_threaded_factorization changed.
struct FactorizationThreading {
  bool blas_single = false;      ///< OpenBLAS was set to one thread
  bool openmp_serial = false;    ///< OpenMP parallel regions were made serial
};

/// Once per process: sets OpenBLAS to one thread unless OPENBLAS_NUM_THREADS,
/// GOTO_NUM_THREADS or OMP_NUM_THREADS is set, and makes OpenMP regions (CHOLMOD's) serial
/// unless OMP_THREAD_LIMIT or OMP_MAX_ACTIVE_LEVELS is set: the user's choice wins. Another
/// BLAS or OpenMP runtime is left as it is. PSQ's own parallel loops use TBB, not OpenMP.
FactorizationThreading use_single_threaded_factorization();

}  // namespace psq
