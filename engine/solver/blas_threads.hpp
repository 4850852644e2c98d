#pragma once
// How many threads the BLAS under CHOLMOD's supernodal factorization may use.
//
// OpenBLAS (the BLAS that scripts/setup.sh installs) starts one busy-waiting thread per core.
// On the 2-core machines PSQ runs on, every factorization then competes with whatever else
// runs — the test suite's second job, a second sweep worker, a build — and spinning threads
// lose more than they gain. Measured under such load (factorization ms per
// Newton iteration, `bench_drape --sizes 1000,5000,20000 --frames 2`, run as is and with
// OPENBLAS_NUM_THREADS=2; 2 threads → 1): 1.1k vertices 52–59 → 16–25, 5.3k 191–312 → 140–142,
// 21k 1423–1627 → 1110–1354. On a quiet machine two threads gain little (same benchmark, 1 → 2
// threads: 1.1k 19 → 26–29, 5.3k 122–130 → 112–119, 21k 601–606 → 542–558). So PSQ factorizes
// single-threaded unless the user says otherwise (OPENBLAS_NUM_THREADS=2 for a lone run).

namespace psq {

/// Sets OpenBLAS to one thread, once per process, unless OPENBLAS_NUM_THREADS,
/// GOTO_NUM_THREADS or OMP_NUM_THREADS is set (the user's choice wins). Another BLAS is left
/// as it is. Returns whether the thread count was set.
bool use_single_threaded_blas();

}  // namespace psq
