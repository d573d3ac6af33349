// A dense linear solver for Ipopt's augmented (KKT) systems, through Ipopt's
// own "custom" linear-solver hook: AlgorithmBuilder takes an AugSystemSolver,
// which is Ipopt's StdAugSystemSolver over TSymLinearSolver over this
// SparseSymLinearSolverInterface. Design: docs/drivers.md, "Ipopt's linear
// solver".
//
// Why: mechopt's Ipopt problems have 1-10 variables and a few rows, so the
// KKT matrix is 2-40 square; MUMPS spends ~3.4M instructions a solve on its
// own bookkeeping for such a system (docs/drivers.md has the profile), most
// of an Ipopt iteration. Here the matrix is assembled dense and factorised by
// LAPACK's Bunch-Kaufman L D L^T, which gives the exact inertia Ipopt's
// perturbation handler asks for (the count of negative eigenvalues), and a
// singular matrix is reported as such, so Ipopt regularises it as it would
// with MUMPS.
//
// The internal headers (IpTSymLinearSolver.hpp ...) are not in Debian's
// coinor-libipopt-dev; tools/ipopt_headers.sh takes them from Debian's source
// package of the installed version (same version, so the same classes as the
// library's).
#include "ipopt_dense_solver.hpp"

#include <IpStdAugSystemSolver.hpp>
#include <IpTSymLinearSolver.hpp>

#include <algorithm>
#include <cmath>

extern "C" {  // LAPACK
void dsytrf_(const char* uplo, const int* n, double* a, const int* lda, int* ipiv, double* work,
             const int* lwork, int* info);
void dsytrs_(const char* uplo, const int* n, const int* nrhs, const double* a, const int* lda,
             const int* ipiv, double* b, const int* ldb, int* info);
}

namespace opt::detail {

using Ipopt::ESymSolverStatus;
using Ipopt::Index;

ESymSolverStatus DenseSymSolver::InitializeStructure(Index dim, Index nonzeros, const Index*, const Index*) {
  dim_ = dim;
  values_.assign(static_cast<size_t>(nonzeros), 0.0);
  return Ipopt::SYMSOLVER_SUCCESS;
}

ESymSolverStatus DenseSymSolver::MultiSolve(bool new_matrix, const Index* ia, const Index* ja, Index nrhs,
                                            double* rhs, bool check_negative, Index negative_wanted) {
  if (new_matrix) {
    const ESymSolverStatus s = factorize(ia, ja);
    if (s != Ipopt::SYMSOLVER_SUCCESS) return s;
    if (check_negative && negative_ != negative_wanted) return Ipopt::SYMSOLVER_WRONG_INERTIA;
  }
  if (singular_) return Ipopt::SYMSOLVER_SINGULAR;
  int n = dim_, k = nrhs, info = 0;
  dsytrs_("L", &n, &k, a_.data(), &n, pivots_.data(), rhs, &n, &info);
  return info == 0 ? Ipopt::SYMSOLVER_SUCCESS : Ipopt::SYMSOLVER_FATAL_ERROR;
}

// Bunch-Kaufman L D L^T (LAPACK dsytrf): by Sylvester's law D has the
// matrix's inertia; a 1x1 block's sign is its eigenvalue's, and each 2x2
// block holds one negative and one positive eigenvalue. Singular means an
// exactly zero pivot, as for MUMPS (a relative pivot floor flagged the
// systems near a solution, where the barrier terms reach 1e11, and Ipopt's
// regularisation then stalled the epigraph runs); Ipopt's iterative
// refinement checks the residual of every solve.
ESymSolverStatus DenseSymSolver::factorize(const Index* ia, const Index* ja) {
  a_.assign(static_cast<size_t>(dim_) * dim_, 0.0);
  for (size_t k = 0; k < values_.size(); ++k) {
    const Index i = std::max(ia[k], ja[k]) - 1, j = std::min(ia[k], ja[k]) - 1;  // lower triangle
    a_[static_cast<size_t>(j) * dim_ + i] += values_[k];
  }
  if (!std::all_of(a_.begin(), a_.end(), [](double v) { return std::isfinite(v); }))
    return Ipopt::SYMSOLVER_FATAL_ERROR;
  int n = dim_, info = 0, lwork = static_cast<int>(work_.size());
  pivots_.resize(static_cast<size_t>(dim_));
  dsytrf_("L", &n, a_.data(), &n, pivots_.data(), work_.data(), &lwork, &info);
  if (info < 0) return Ipopt::SYMSOLVER_FATAL_ERROR;
  singular_ = info > 0;
  negative_ = 0;
  for (int i = 0; i < dim_; ++i) {
    const bool block = pivots_[static_cast<size_t>(i)] < 0;
    negative_ += block || a_[static_cast<size_t>(i) * dim_ + i] < 0;
    i += block;
  }
  return singular_ ? Ipopt::SYMSOLVER_SINGULAR : Ipopt::SYMSOLVER_SUCCESS;
}

Ipopt::SmartPtr<Ipopt::AugSystemSolver> dense_aug_system_solver() {
  Ipopt::SmartPtr<Ipopt::SparseSymLinearSolverInterface> dense = new DenseSymSolver();
  Ipopt::SmartPtr<Ipopt::SymLinearSolver> triplets = new Ipopt::TSymLinearSolver(dense, nullptr);
  return new Ipopt::StdAugSystemSolver(*triplets);
}

}  // namespace opt::detail
