// Ipopt's "custom" linear solver for mechopt's small KKT systems: the
// matrix assembled dense and factorised by Bunch-Kaufman's L D L^T.
// Why and how: ipopt_dense_solver.cpp and docs/drivers.md, "Ipopt's linear
// solver". Needs Ipopt's internal headers (tools/ipopt_headers.sh).
#pragma once

#include <IpAugSystemSolver.hpp>
#include <IpSparseSymLinearSolverInterface.hpp>

#include <atomic>
#include <vector>

namespace opt::detail {

// Ipopt's SparseSymLinearSolverInterface: triplets (1-based, one triangle,
// duplicates add up, as for MA27) in, solves and the inertia out.
class DenseSymSolver : public Ipopt::SparseSymLinearSolverInterface {
 public:
  bool InitializeImpl(const Ipopt::OptionsList&, const std::string&) override { return true; }
  Ipopt::ESymSolverStatus InitializeStructure(Ipopt::Index dim, Ipopt::Index nonzeros, const Ipopt::Index*,
                                              const Ipopt::Index*) override;
  double* GetValuesArrayPtr() override { return values_.data(); }
  // Factorises when new_matrix (SYMSOLVER_WRONG_INERTIA when check_negative
  // and the count of negative eigenvalues is not negative_wanted), then
  // solves for the nrhs right-hand sides in rhs, in place.
  Ipopt::ESymSolverStatus MultiSolve(bool new_matrix, const Ipopt::Index* ia, const Ipopt::Index* ja,
                                     Ipopt::Index nrhs, double* rhs, bool check_negative,
                                     Ipopt::Index negative_wanted) override;
  Ipopt::Index NumberOfNegEVals() const override { return negative_; }
  bool IncreaseQuality() override { return false; }  // Bunch-Kaufman has no pivot tolerance to raise
  bool ProvidesInertia() const override { return true; }
  EMatrixFormat MatrixFormat() const override { return Triplet_Format; }

 private:
  Ipopt::ESymSolverStatus factorize(const Ipopt::Index* ia, const Ipopt::Index* ja);
  void solve(double* b) const;

  int dim_ = 0;
  std::vector<double> values_, a_;  // the triplets' values; the factors (column-major, full storage)
  std::vector<int> pivots_;         // the row each step's last pivot row was swapped with
  std::vector<bool> block_;         // in a 2x2 block of D
  int negative_ = 0;
  bool singular_ = false;
};

// Calls of Ipopt's CpuTime() that reached mechopt's cheap clock (ipopt.cpp).
inline std::atomic<long> ipopt_clock_reads{0};

// A new augmented-system solver over a DenseSymSolver, for AlgorithmBuilder
// and linear_solver = "custom". One per Ipopt run.
Ipopt::SmartPtr<Ipopt::AugSystemSolver> dense_aug_system_solver();

}  // namespace opt::detail
