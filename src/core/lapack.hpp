// The two LAPACK/BLAS routines the library calls (the Casimir spectrum's
// zheevd, the matrix baselines' zgemm), taken from the system's LAPACK when
// first needed instead of linked. A threaded OpenBLAS starts a thread per
// processor when it is loaded and, when a process limit refuses one, prints
// and ends the process: linked, it did so to every program that linked this
// library, spectrum or not. Loaded here, after the threads it will start are
// known to be available, a refusal is a status.
#pragma once

#include <complex>
#include <cstddef>

namespace lpi {
namespace lapack {

using cplx = std::complex<double>;

// Fortran LAPACK's zheevd and BLAS's zgemm, with the hidden lengths of their
// character arguments. Each throws LPI_ERR_UNSUPPORTED naming the library
// when it cannot be loaded or lacks the routine, and LPI_ERR_NO_MEMORY when
// the threads a threaded OpenBLAS starts on loading cannot be had (it is
// then not loaded, and a later call tries again), or the buffers OpenBLAS
// takes on loading and on its first call cannot (lapack.cpp).
void zheevd(const char *jobz, const char *uplo, const int *n, cplx *a, const int *lda, double *w,
            cplx *work, const int *lwork, double *rwork, const int *lrwork, int *iwork, const int *liwork,
            int *info, std::size_t jobz_len, std::size_t uplo_len);
void zgemm(const char *transa, const char *transb, const int *m, const int *n, const int *k, const cplx *alpha,
           const cplx *a, const int *lda, const cplx *b, const int *ldb, const cplx *beta, cplx *c,
           const int *ldc, std::size_t transa_len, std::size_t transb_len);

}  // namespace lapack
}  // namespace lpi
