// Seed 000 Table 1: the cells that reproduce, pinned. Paper values are the
// printed table; the high-precision reference values come from
// tools/reference_seed000.py (mpmath, 40 digits, written from the paper's
// equations, no shared code), saved in tools/reference_seed000.json.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "mech/twin_slider_crank.hpp"
#include "opt/config.hpp"
#include "opt/driver.hpp"
#include "opt/drivers/nlopt.hpp"
#include "problems/recuperative_drive.hpp"

namespace {

constexpr double kPi = std::numbers::pi;
// Table 1 prints 4-6 significant digits; 0.05% covers its rounding and the
// paper's own grid-sampled maximum (the acceptance tolerance).
constexpr double kPaperTol = 5e-4;
// Our cycle values against the 40-digit reference: quadrature and root finding
// are converged to roundoff, so 1e-12 relative.
constexpr double kRefTol = 1e-12;

struct Row {
  double l, tmax, tcp, k1, k2, k3;
};
const Row kPaper[] = {  // seed 000, Table 1
    {0.5, 3814.9, 2405.8, 1.5857, 1.3532, 2.14585},  {0.6, 3544.82, 2396.64, 1.4791, 1.3481, 1.9939},
    {0.7, 3371.6, 2400.63, 1.4044, 1.3503, 1.8965},  {0.8, 3252.94, 2411.24, 1.349, 1.3563, 1.8297},
    {0.9, 3170.23, 2425.55, 1.307, 1.3643, 1.7832},  {1.0, 3109.9, 2442.1, 1.2734, 1.3737, 1.7493},
    {1.1, 3065.86, 2460.1, 1.2462, 1.3838, 1.7245},  {1.2, 3033.6, 2479.1, 1.2237, 1.3945, 1.7064},
    {1.3, 3010.3, 2498.73, 1.2047, 1.4055, 1.6933},  {1.4, 2993.86, 2518.87, 1.1886, 1.4168, 1.684},
    {1.5, 2982.83, 2539.37, 1.1746, 1.4284, 1.6778}};
// tools/reference_seed000.json: (T_max, T_cp) at 100 rpm.
const double kRef[][2] = {
    {3814.9075500747747, 2399.402531213774},  {3544.8161836289869, 2390.178022370431},
    {3371.6089707544189, 2394.1121454215554}, {3253.6347036948048, 2404.6553359931792},
    {3170.2289875499655, 2418.9043675207197}, {3109.932488833055, 2435.3999985342419},
    {3065.8639635804448, 2453.3398570087992}, {3033.6355933693769, 2472.2517372761803},
    {3010.3147491578168, 2491.8424800545939}, {2993.8656439947493, 2511.9220300855025},
    {2982.8301955050213, 2532.3626762556321}};

mech::CycleMetrics<double> at(double l) {
  const mech::TwinDrive<double> d{0.2, l, kPi / 2, 0.0, 100 * kPi / 30, 1000, 80, 0.9, 3562};
  return mech::cycle_metrics(d, 32);
}

double rel(double a, double b) { return std::abs(a - b) / std::abs(b); }

TEST(Seed000Table1, PeakEnergyAndK3ReproduceAt100Rpm) {
  for (const Row& r : kPaper) {
    const auto m = at(r.l);
    EXPECT_LT(rel(m.peak_kinetic_energy, r.tmax), kPaperTol) << "l = " << r.l;
    EXPECT_LT(rel(m.k3, r.k3), kPaperTol) << "l = " << r.l;
    EXPECT_LT(rel(m.least_mean_kinetic_energy, 1777.8), kPaperTol);
  }
}

TEST(Seed000Table1, MeanEnergyIsThePaperMixingTwoSpeeds) {
  // T_cp, k1 and k2 of the table sit 0.27% off the exact cycle mean at 100 rpm:
  // the ratio 10.5 / (100 pi / 30) of the printed and the actual speed.
  // Scaling ours by that ratio reproduces them to the table's rounding.
  const double speed_ratio = 10.5 / (100 * kPi / 30);
  for (const Row& r : kPaper) {
    const auto m = at(r.l);
    EXPECT_GT(rel(m.mean_kinetic_energy, r.tcp), 2.5e-3) << "unscaled differs";
    EXPECT_LT(rel(m.mean_kinetic_energy * speed_ratio, r.tcp), kPaperTol) << "l = " << r.l;
    EXPECT_LT(rel(m.k1 / speed_ratio, r.k1), kPaperTol) << "l = " << r.l;
    EXPECT_LT(rel(m.k2 * speed_ratio, r.k2), kPaperTol) << "l = " << r.l;
  }
}

TEST(Seed000Table1, AgreesWithHighPrecisionReference) {
  for (size_t i = 0; i < std::size(kPaper); ++i) {
    const auto m = at(kPaper[i].l);
    EXPECT_LT(rel(m.peak_kinetic_energy, kRef[i][0]), kRefTol) << "l = " << kPaper[i].l;
    EXPECT_LT(rel(m.mean_kinetic_energy, kRef[i][1]), kRefTol) << "l = " << kPaper[i].l;
  }
}

TEST(Seed000Optimum, ContinuousRodLengthMatchesReference) {
  // tools/reference_seed000.json: l* = 0.60864008996547893 m, T_cp(l*) = 2390.1336147556022 J.
  const auto p = problems::make_recuperative_drive(opt::ConfigNode::parse(
      "problem: recuperative_drive\nvariables: {rod_length: {min: 0.5 m, max: 1.5 m}}\n", "<t>"));
  // SLSQP builds a quasi-Newton model and lands on the root of the gradient,
  // where the driver stops it once the gradient is zero to roundoff (NLopt
  // alone went on stepping on roundoff and ended 1.8e-10 off); MMA's
  // conservative steps stop on xtol a little short of it (measured 1.1e-8),
  // so it is held to 1e-7.
  for (auto [alg, xtol] : {std::pair{"LD_SLSQP", 1e-14}, std::pair{"LD_MMA", 1e-7}}) {
    opt::DriverOptions o;
    o.algorithm = alg;
    const auto r = opt::NloptDriver(o).minimize(*p, {"mean_kinetic_energy"}, {}, p->initial_point());
    ASSERT_TRUE(r.success()) << alg << ": " << r.message;
    EXPECT_LT(rel(r.x[0], 0.60864008996547893), xtol) << alg;
    EXPECT_LT(rel(r.objective, 2390.1336147556022), kRefTol) << alg;
  }
}

}  // namespace
