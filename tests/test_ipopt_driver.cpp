// Ipopt's dense KKT solver (libopt/src/drivers/ipopt_dense_solver.cpp) and the
// driver around it: the solver's inertia and solutions against Eigen's
// symmetric eigendecomposition (an independent computation); the driver with
// the dense solver against the same driver with MUMPS; Ipopt's timers on
// mechopt's clock; one application reused across runs gives the runs' own
// answers; an ipopt.opt in the working directory changes nothing.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <thread>

#include "drivers/ipopt_dense_solver.hpp"
#include "opt/config.hpp"
#include "opt/driver.hpp"
#include "opt/drivers/ipopt.hpp"
#include "opt/registry.hpp"

namespace {

// A in triplets (1-based, lower triangle, every diagonal entry present), as
// Ipopt's TSymLinearSolver hands them over; the (1, 1) entry is split into
// two triplets, which must add up.
struct Triplets {
  std::vector<int> ia, ja;
  std::vector<double> v;
};
Triplets triplets(const Eigen::MatrixXd& a) {
  Triplets t;
  for (int j = 0; j < a.cols(); ++j)
    for (int i = j; i < a.rows(); ++i)
      if (i == j || a(i, j) != 0) t.ia.push_back(i + 1), t.ja.push_back(j + 1), t.v.push_back(a(i, j));
  t.ia.push_back(1), t.ja.push_back(1), t.v.push_back(0.25 * t.v[0]);
  t.v[0] *= 0.75;
  return t;
}

Ipopt::ESymSolverStatus solve(opt::detail::DenseSymSolver& s, const Triplets& t, int dim, Eigen::VectorXd& b,
                              bool check = false, int negative = 0) {
  s.InitializeStructure(dim, static_cast<int>(t.v.size()), t.ia.data(), t.ja.data());
  std::copy(t.v.begin(), t.v.end(), s.GetValuesArrayPtr());
  return s.MultiSolve(true, t.ia.data(), t.ja.data(), 1, b.data(), check, negative);
}

// KKT-like matrices [H J'; J -D] with H positive definite or not, J of full
// rank, D >= 0 (zero rows as for Ipopt's equality rows): the inertia Ipopt
// asks for is (n, m, 0) when H is positive definite on J's null space.
TEST(DenseSymSolver, InertiaAndSolutionsMatchAnEigendecomposition) {
  std::mt19937 rng(7);
  std::normal_distribution<double> normal;
  int checked = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const int n = 1 + trial % 7, m = trial % 4, dim = n + m;
    Eigen::MatrixXd h = Eigen::MatrixXd::NullaryExpr(n, n, [&] { return normal(rng); });
    h = (h * h.transpose()).eval() + (trial % 3 == 0 ? -2.0 : 0.1) * Eigen::MatrixXd::Identity(n, n);
    Eigen::MatrixXd a = Eigen::MatrixXd::Zero(dim, dim);
    a.topLeftCorner(n, n) = h;
    for (int r = 0; r < m; ++r) {
      for (int c = 0; c < n; ++c) a(n + r, c) = a(c, n + r) = normal(rng);
      a(n + r, n + r) = trial % 2 ? 0.0 : -std::abs(normal(rng)) * 1e-3;
    }
    // Barrier-like scale spread: one diagonal entry of H at 1e10.
    if (trial % 5 == 0) a(0, 0) += 1e10;
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(a);
    const auto l = eig.eigenvalues().array();
    if ((l.abs() < 1e-8 * l.abs().maxCoeff()).any()) continue;  // near-singular: not this test's case
    const int negative = static_cast<int>((l < 0).count());
    Eigen::VectorXd x_true = Eigen::VectorXd::NullaryExpr(dim, [&] { return normal(rng); });
    Eigen::VectorXd b = a * x_true;
    opt::detail::DenseSymSolver s;
    ASSERT_EQ(solve(s, triplets(a), dim, b), Ipopt::SYMSOLVER_SUCCESS) << "trial " << trial;
    EXPECT_EQ(s.NumberOfNegEVals(), negative) << "trial " << trial;
    // Backward error: residual against |A| |x|, as a stable solver gives.
    const double scale = (a.cwiseAbs() * b.cwiseAbs()).maxCoeff();
    EXPECT_LE((a * b - a * x_true).cwiseAbs().maxCoeff(), 1e-13 * scale) << "trial " << trial;
    // The inertia check: the wrong count is refused before any solve.
    Eigen::VectorXd c = a * x_true;
    EXPECT_EQ(solve(s, triplets(a), dim, c, true, negative + 1), Ipopt::SYMSOLVER_WRONG_INERTIA);
    EXPECT_EQ(solve(s, triplets(a), dim, c, true, negative), Ipopt::SYMSOLVER_SUCCESS);
    ++checked;
  }
  EXPECT_GE(checked, 150);  // the near-singular skips are few
}

// Zero diagonals need Bunch-Kaufman's 2x2 pivots: [[0, 1], [1, 0]] has
// eigenvalues -1 and 1; the 3x3 [[0, 2, 1], [2, 0, 0], [1, 0, 1e-3]] has one
// negative eigenvalue (det -4e-3 < 0 and trace > 0, so one or three, and
// the leading 2x2 block is indefinite).
TEST(DenseSymSolver, TwoByTwoPivotsOnZeroDiagonals) {
  opt::detail::DenseSymSolver s;
  Eigen::MatrixXd a(2, 2);
  a << 0, 1, 1, 0;
  Eigen::VectorXd b(2);
  b << 3, 5;
  ASSERT_EQ(solve(s, triplets(a), 2, b), Ipopt::SYMSOLVER_SUCCESS);
  EXPECT_EQ(s.NumberOfNegEVals(), 1);
  EXPECT_EQ(b[0], 5);
  EXPECT_EQ(b[1], 3);
  Eigen::MatrixXd c(3, 3);
  c << 0, 2, 1, 2, 0, 0, 1, 0, 1e-3;
  Eigen::VectorXd x(3), y(3);
  x << 1, -2, 3;
  y = c * x;
  ASSERT_EQ(solve(s, triplets(c), 3, y), Ipopt::SYMSOLVER_SUCCESS);
  EXPECT_EQ(s.NumberOfNegEVals(), 1);
  EXPECT_LE((y - x).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(DenseSymSolver, SingularAndNonFiniteMatricesAreSaidSo) {
  Eigen::MatrixXd a(3, 3);
  a << 1, 2, 0, 2, 4, 0, 0, 0, 0;  // rank 1, and an empty row and column
  Eigen::VectorXd b = Eigen::VectorXd::Ones(3);
  opt::detail::DenseSymSolver s;
  EXPECT_EQ(solve(s, triplets(a), 3, b), Ipopt::SYMSOLVER_SINGULAR);
  a(2, 2) = std::nan("");
  EXPECT_EQ(solve(s, triplets(a), 3, b), Ipopt::SYMSOLVER_FATAL_ERROR);
}

std::shared_ptr<opt::Problem> conveyor() {
  return opt::make_problem(opt::ConfigNode::parse(
      "problem: conveyor_swing\nvariables: {l_co1: {min: 0.9 m, max: 2.4 m}}\n", "<conveyor>"));
}
std::shared_ptr<opt::Problem> rod_length() {
  return opt::make_problem(opt::ConfigNode::parse(
      "problem: recuperative_drive\nvariables: {rod_length: {min: 0.5 m, max: 1.5 m}}\n", "<rod>"));
}
const std::vector<opt::Constraint> kPressure = {{"max_pressure_angle", true, 60 * M_PI / 180}};

opt::Result run(const opt::Problem& p, const std::string& objective, const std::vector<opt::Constraint>& k,
                const std::string& linear_solver, double tol = 1e-10) {
  opt::DriverOptions o;
  o.library = "ipopt";
  o.linear_solver = linear_solver;
  o.tol = tol;
  return opt::IpoptDriver(o).minimize(p, {objective}, k, p.initial_point());
}

// Both linear solvers reach the optimum (the references of docs/drivers.md's
// work-precision tables, tools/reference_seed000.json and
// reference_seed002.json) on the smooth rod length and on the conveyor's kink.
TEST(IpoptDriver, DenseAndMumpsReachTheSameOptimum) {
  const auto rod = rod_length(), conv = conveyor();
  constexpr double kRod = 0.60864008996547893, kConveyor = 1.5224536093493499;
  constexpr double kTol = 1e-8;  // relative; both converge to ~1e-10 at tol 1e-10
  for (const char* ls : {"dense", "mumps"}) {
    const auto r = run(*rod, "mean_kinetic_energy", {}, ls);
    ASSERT_EQ(r.status, opt::DriverStatus::converged) << ls << ": " << r.message;
    EXPECT_NEAR(r.x[0], kRod, kTol * kRod) << ls;
    EXPECT_GT(r.iterations, 0) << ls;
    const auto c = run(*conv, "peak_crank_torque", kPressure, ls);
    ASSERT_EQ(c.status, opt::DriverStatus::converged) << ls << ": " << c.message;
    EXPECT_NEAR(c.x[0], kConveyor, kTol * kConveyor) << ls;
  }
}

// Ipopt's timers read mechopt's clock (libopt/src/drivers/ipopt.cpp), not getrusage:
// the definitions in the executable take the place of libipopt.so's.
TEST(IpoptDriver, IpoptsTimersReadTheCheapClock) {
  const long before = opt::detail::ipopt_clock_reads.load();
  const auto r = run(*rod_length(), "mean_kinetic_energy", {}, "dense");
  ASSERT_EQ(r.status, opt::DriverStatus::converged) << r.message;
  EXPECT_GT(opt::detail::ipopt_clock_reads.load() - before, 10 * r.iterations);
}

// One Ipopt application serves every run of a thread: a run between two
// identical ones, with other options and another problem, leaves no trace.
TEST(IpoptDriver, ReusedApplicationGivesEachRunItsOwnAnswer) {
  const auto rod = rod_length(), conv = conveyor();
  const auto first = run(*conv, "peak_crank_torque", kPressure, "dense");
  run(*rod, "mean_kinetic_energy", {}, "mumps", 1e-4);
  const auto again = run(*conv, "peak_crank_torque", kPressure, "dense");
  EXPECT_EQ(first.x[0], again.x[0]);
  EXPECT_EQ(first.objective, again.objective);
  EXPECT_EQ(first.iterations, again.iterations);
  EXPECT_EQ(first.evaluations, again.evaluations);
}

// Ipopt reads ipopt.opt from the working directory unless told otherwise; a
// stray one (here: one iteration at most) must not change a mechopt run.
TEST(IpoptDriver, AnIpoptOptFileInTheWorkingDirectoryIsIgnored) {
  const auto dir = std::filesystem::path(::testing::TempDir()) / "ipopt_opt_cwd";
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "ipopt.opt") << "max_iter 1\nprint_level 12\n";
  const auto here = std::filesystem::current_path();
  std::filesystem::current_path(dir);
  // A fresh thread: a fresh application, initialised with the file present.
  opt::Result r;
  std::thread([&] { r = run(*rod_length(), "mean_kinetic_energy", {}, "dense"); }).join();
  std::filesystem::current_path(here);
  EXPECT_EQ(r.status, opt::DriverStatus::converged) << r.message;
  EXPECT_GT(r.iterations, 1);
}

}  // namespace
