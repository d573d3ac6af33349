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
// Bunch-Kaufman's L D L^T (LAPACK's dsytf2 and dsytrs, written out: through
// LAPACK's reference build a solve cost 22k instructions, the factorisation
// 45k, for 20 unknowns), which gives the exact inertia Ipopt's
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
  for (Index r = 0; r < nrhs; ++r) solve(rhs + static_cast<size_t>(r) * dim_);
  return Ipopt::SYMSOLVER_SUCCESS;
}

// Bunch-Kaufman's symmetric pivoting (LAPACK's dsytf2, lower, in full
// storage): P A P' = L D L' as a product of interchanges and unit lower
// elementary factors, D of 1x1 and 2x2 blocks, growth bounded by alpha =
// (1 + sqrt 17) / 8. By Sylvester's law D has A's inertia: a 1x1 block's
// sign is its eigenvalue's, a 2x2 block (det < 0 as the pivoting chooses it)
// holds one of each sign. Singular means an exactly zero pivot, as for
// MUMPS: a relative pivot floor (dim x eps x the largest entry) flagged the
// systems near a solution, where the barrier terms reach 1e11, and Ipopt's
// regularisation then stalled the sawmill's epigraph run; Ipopt's iterative
// refinement checks the residual of every solve.
ESymSolverStatus DenseSymSolver::factorize(const Index* ia, const Index* ja) {
  const int n = dim_;
  a_.assign(static_cast<size_t>(n) * n, 0.0);
  auto at = [&](int i, int j) -> double& { return a_[static_cast<size_t>(j) * n + i]; };
  for (size_t k = 0; k < values_.size(); ++k) {
    const int i = ia[k] - 1, j = ja[k] - 1;
    at(i, j) += values_[k];
    if (i != j) at(j, i) += values_[k];
  }
  if (!std::all_of(a_.begin(), a_.end(), [](double v) { return std::isfinite(v); }))
    return Ipopt::SYMSOLVER_FATAL_ERROR;
  const double alpha = (1 + std::sqrt(17.0)) / 8;
  pivots_.assign(static_cast<size_t>(n), 0);
  block_.assign(static_cast<size_t>(n), false);
  negative_ = 0;
  singular_ = false;
  for (int k = 0, step = 1; k < n; k += step) {
    const double akk = std::abs(at(k, k));
    int imax = k;
    double colmax = 0;
    for (int i = k + 1; i < n; ++i)
      if (std::abs(at(i, k)) > colmax) colmax = std::abs(at(i, k)), imax = i;
    int kp = k;
    step = 1;
    if (akk < alpha * colmax) {  // (a zero column takes the 1x1 branch, d = 0 below)
      double rowmax = 0;
      for (int j = k; j < n; ++j)
        if (j != imax) rowmax = std::max(rowmax, std::abs(at(imax, j)));
      if (akk >= alpha * colmax * (colmax / rowmax)) {
        kp = k;
      } else if (std::abs(at(imax, imax)) >= alpha * rowmax) {
        kp = imax;
      } else {
        kp = imax;
        step = 2;
      }
    }
    const int kk = k + step - 1;
    if (kp != kk) {  // swap rows and columns kk and kp of the trailing matrix
      for (int j = k; j < n; ++j) std::swap(at(kk, j), at(kp, j));
      for (int i = k; i < n; ++i) std::swap(at(i, kk), at(i, kp));
    }
    pivots_[static_cast<size_t>(kk)] = kp;
    if (step == 1) {
      const double d = at(k, k);
      if (d == 0) {
        singular_ = true;
        continue;
      }
      negative_ += d < 0;
      for (int j = k + 1; j < n; ++j) {
        const double l = at(j, k) / d;
        for (int i = k + 1; i < n; ++i) at(i, j) -= at(i, k) * l;
      }
      for (int i = k + 1; i < n; ++i) at(i, k) /= d;
    } else {
      block_[static_cast<size_t>(k)] = block_[static_cast<size_t>(k + 1)] = true;
      const double p = at(k, k), q = at(k + 1, k), r = at(k + 1, k + 1), det = p * r - q * q;
      if (det == 0) {
        singular_ = true;
        continue;
      }
      negative_ += det < 0 ? 1 : (p + r < 0 ? 2 : 0);
      for (int j = k + 2; j < n; ++j) {  // column j of L: (w_jk, w_jk+1) D^-1
        const double w0 = at(j, k), w1 = at(j, k + 1);
        const double l0 = (r * w0 - q * w1) / det, l1 = (p * w1 - q * w0) / det;
        for (int i = k + 2; i < n; ++i) at(i, j) -= at(i, k) * l0 + at(i, k + 1) * l1;
        at(k, j) = l0, at(k + 1, j) = l1;  // stash: the upper triangle above the block is free
      }
      for (int j = k + 2; j < n; ++j) at(j, k) = at(k, j), at(j, k + 1) = at(k + 1, j);
    }
  }
  return singular_ ? Ipopt::SYMSOLVER_SINGULAR : Ipopt::SYMSOLVER_SUCCESS;
}

// b <- A^-1 b with the factors (LAPACK's dsytrs, lower): forward through the
// interchanges and L's columns with D's blocks, then back through L'.
void DenseSymSolver::solve(double* b) const {
  const int n = dim_;
  auto at = [&](int i, int j) { return a_[static_cast<size_t>(j) * n + i]; };
  for (int k = 0; k < n;) {
    if (!block_[static_cast<size_t>(k)]) {
      std::swap(b[k], b[pivots_[static_cast<size_t>(k)]]);
      for (int i = k + 1; i < n; ++i) b[i] -= at(i, k) * b[k];
      b[k] /= at(k, k);
      k += 1;
    } else {
      std::swap(b[k + 1], b[pivots_[static_cast<size_t>(k + 1)]]);
      for (int i = k + 2; i < n; ++i) b[i] -= at(i, k) * b[k] + at(i, k + 1) * b[k + 1];
      const double p = at(k, k), q = at(k + 1, k), r = at(k + 1, k + 1), det = p * r - q * q;
      const double b0 = b[k], b1 = b[k + 1];
      b[k] = (r * b0 - q * b1) / det, b[k + 1] = (p * b1 - q * b0) / det;
      k += 2;
    }
  }
  for (int k = n - 1; k >= 0;) {
    if (!block_[static_cast<size_t>(k)]) {
      for (int i = k + 1; i < n; ++i) b[k] -= at(i, k) * b[i];
      std::swap(b[k], b[pivots_[static_cast<size_t>(k)]]);
      k -= 1;
    } else {  // the block k-1, k
      for (int i = k + 1; i < n; ++i) b[k] -= at(i, k) * b[i], b[k - 1] -= at(i, k - 1) * b[i];
      std::swap(b[k], b[pivots_[static_cast<size_t>(k)]]);
      k -= 2;
    }
  }
}

Ipopt::SmartPtr<Ipopt::AugSystemSolver> dense_aug_system_solver() {
  Ipopt::SmartPtr<Ipopt::SparseSymLinearSolverInterface> dense = new DenseSymSolver();
  Ipopt::SmartPtr<Ipopt::SymLinearSolver> triplets = new Ipopt::TSymLinearSolver(dense, nullptr);
  return new Ipopt::StdAugSystemSolver(*triplets);
}

}  // namespace opt::detail
