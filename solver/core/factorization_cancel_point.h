// The cancel point inside a supernodal factorization, for the BLAS/LAPACK definitions of
// process_overrides.cpp (see kCancelPoint in sparse_cholesky.cpp). Internal: not part of the
// solver's API.
#pragma once

namespace inbetween::solver::internal {

// True once the calling thread's cancellable supernodal factorization is cancelled (and from
// then on, until that factorization returns); false outside one.
bool SupernodalFactorizationCancelled();

// Makes CHOLMOD stop at the supernode being factored: answers its dpotrf_ call with *info = 1 (a
// failed first pivot) and spares CHOLMOD's zeroing of the factor's unfactored rest.
void StopSupernodalFactorizationHere(int* info);

}  // namespace inbetween::solver::internal
