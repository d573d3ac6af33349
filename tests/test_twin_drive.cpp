// Twin slider-crank drive: physics identities, quadrature convergence, and
// autodiff gradients of every metric against central differences.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "mech/twin_slider_crank.hpp"

namespace {

using mech::TwinDrive;
constexpr double kPi = std::numbers::pi;

TwinDrive<double> seed000(double l = 0.8) {
  return {0.2, l, kPi / 2, 0.0, 100 * kPi / 30, 1000, 80, 0.9, 3562};
}

TEST(TwinDrive, InertiaMomentIsTheAngleDerivativeOfKineticEnergy) {
  // At constant speed, eqs (18)-(20) equal dT/dphi; checked by central
  // differences (h = 1e-5: error ~1e-10 * |T'''| ~ 1e-6 N m on T ~ 3e3 J).
  for (auto rod : {mech::RodModel::point_masses, mech::RodModel::full})
    for (auto layout : {mech::Layout::opposed, mech::Layout::same_side}) {
      auto d = seed000(0.6);
      d.rod = rod;
      d.layout = layout;
      d.offset = 0.05;
      const double h = 1e-5;
      for (double phi = 0.05; phi < 6.3; phi += 0.3) {
        const double fd = (mech::drive_point(d, phi + h).kinetic_energy -
                           mech::drive_point(d, phi - h).kinetic_energy) / (2 * h);
        EXPECT_NEAR(mech::drive_point(d, phi).inertia_moment, fd, 1e-5);
      }
    }
}

TEST(TwinDrive, MomentSlopeIsTheDualNumbersAngleDerivative) {
  // drive_point_slope's dM/dphi (third-order transfer functions written
  // out) against forward-mode autodiff of M in phi, an independent route:
  // every layout, rod model, kinematics and resistance, random designs and
  // angles, to roundoff of the terms (|M'| + |M_i|).
  std::mt19937_64 gen(5);
  std::uniform_real_distribution<double> u(0, 1);
  int checked = 0;
  for (int i = 0; i < 4000; ++i) {
    TwinDrive<double> d{0.05 + 0.3 * u(gen), 0.2 + 1.5 * u(gen), 2 * kPi * u(gen), -0.15 + 0.3 * u(gen),
                        0.1 + 10 * u(gen), 1000 * u(gen), 80 * u(gen), 0.5 + 0.5 * u(gen), 5000 * u(gen)};
    d.resistance = i % 2 ? mech::Resistance::signed_velocity : mech::Resistance::opposes_motion;
    d.layout = i / 2 % 2 ? mech::Layout::same_side : mech::Layout::opposed;
    d.rod = i / 4 % 2 ? mech::RodModel::full : mech::RodModel::point_masses;
    d.kinematics = i / 8 % 2 ? mech::Kinematics::binomial : mech::Kinematics::exact;
    if (mech::check(d) != mech::Status::ok) continue;
    const double phi = 2 * kPi * u(gen), c = std::cos(phi), s = std::sin(phi);
    const double cd = std::cos(d.phase_shift), sd = std::sin(d.phase_shift);
    const mech::Dual M = mech::drive_point(d.cast<mech::Dual>(), mech::Dual(c, -s), mech::Dual(s, c),
                                           mech::Dual(cd), mech::Dual(sd)).total_moment();
    const auto p = mech::drive_point_slope(d, c, s, cd, sd);
    EXPECT_EQ(p.total_moment(), M.v) << i;  // the same values, slope or not
    EXPECT_NEAR(p.moment_slope, M.d, 1e-13 * (std::abs(M.d) + std::abs(p.inertia_moment))) << i;
    ++checked;
  }
  EXPECT_GT(checked, 3000);
}

TEST(TwinDrive, InertiaMomentAndSignedResistanceHaveZeroCycleMean) {
  // M_i = dT/dphi and M_on ~ dx/dphi are derivatives of periodic functions.
  auto d = seed000(0.7);
  d.offset = 0.04;
  const auto m = mech::cycle_metrics(d, 64);
  EXPECT_NEAR(m.mean_total_moment, 0.0, 1e-10 * m.rms_total_moment);
}

TEST(TwinDrive, OpposingResistanceHasClosedFormMean) {
  // |dx/dphi| integrates to the path per revolution, two strokes, so the mean
  // static moment of two carts is F/eta * 2 * 2 S / (2 pi), with the stroke
  // S = sqrt((l+r)^2 - e^2) - sqrt((l-r)^2 - e^2); the inertia moment adds
  // nothing. The arcs between dead centres are integrated separately, so the
  // kinks cost no accuracy: 1e-12 relative at the default 32 points.
  for (double e : {0.0, 0.05}) {
    auto d = seed000(0.8);
    d.offset = e;
    d.resistance = mech::Resistance::opposes_motion;
    const double r = 0.2, l = 0.8;
    const double stroke = std::sqrt((l + r) * (l + r) - e * e) - std::sqrt((l - r) * (l - r) - e * e);
    const double exact = 3562 / 0.9 * 2 * stroke / kPi;
    EXPECT_NEAR(mech::cycle_metrics(d, 32).mean_total_moment, exact, 1e-12 * exact) << "e = " << e;
  }
}

TEST(TwinDrive, OpposingResistanceRmsConvergesDespiteKinks) {
  // Piecewise Gauss-Legendre between dead centres: 32 points agree with 512 to
  // 1e-13 (a trapezoidal rule across the kinks would be off by ~1e-3).
  auto d = seed000(0.6);
  d.resistance = mech::Resistance::opposes_motion;
  const double ref = mech::cycle_metrics(d, 512).rms_total_moment;
  EXPECT_NEAR(mech::cycle_metrics(d, 32).rms_total_moment, ref, 1e-13 * ref);
}

TEST(TwinDrive, LeastMeanKineticEnergyIsEquation14) {
  // 4 m r^2 w^2 / pi^2 = 1777.8 J at 100 rpm (seed 000 text).
  EXPECT_NEAR(mech::least_mean_kinetic_energy(seed000()), 1777.7777777777778, 1e-9);
}

TEST(TwinDrive, CycleMeanConvergesExponentially) {
  // Errors against a 512-point value shrink at least 10x for every 4 more
  // points until roundoff (analytic integrand: the error is ~exp(-a n)).
  const auto d = seed000(0.5);
  const double ref = mech::mean_kinetic_energy(d, 512);
  double prev = std::abs(mech::mean_kinetic_energy(d, 4) - ref);
  for (int n = 8; n <= 20; n += 4) {
    const double err = std::abs(mech::mean_kinetic_energy(d, n) - ref);
    EXPECT_LT(err, std::max(prev / 10, 1e-11 * ref)) << "n = " << n;
    prev = err;
  }
  EXPECT_LT(std::abs(mech::mean_kinetic_energy(d, 32) - ref), 1e-13 * ref);
}

TEST(TwinDrive, PeakIsRefinedBeyondTheGrid) {
  // The refined peak agrees with a 200000-point grid maximum to its resolution
  // ((2 pi / 2e5)^2 * |T''| / 8 ~ 1e-6 J), and is never below any grid value.
  const auto d = seed000(0.8);
  const auto m = mech::cycle_metrics(d, 16);
  double grid = 0;
  for (int k = 0; k < 200000; ++k) grid = std::max(grid, mech::drive_point(d, 2 * kPi * k / 200000).kinetic_energy);
  EXPECT_GE(m.peak_kinetic_energy, grid - 1e-9);
  EXPECT_NEAR(m.peak_kinetic_energy, grid, 1e-5);
}

TEST(TwinDrive, PeakIsGlobalWhenTwoPeaksNearlyTie) {
  // At the least-peak design of configs/recuperative_drive/rod_and_phase.yaml
  // two energy peaks are equal to ~1e-4; for any grid size the refined peak
  // must be the higher one (a grid can rank them the wrong way round).
  auto d = seed000(1.282381955);
  d.phase_shift = 1.662767852;
  double grid = 0;
  for (int k = 0; k < 200000; ++k) grid = std::max(grid, mech::drive_point(d, 2 * kPi * k / 200000).kinetic_energy);
  for (int n : {12, 16, 20, 24, 28, 32, 64}) {
    const double peak = mech::cycle_metrics(d, n).peak_kinetic_energy;
    EXPECT_GE(peak, grid - 1e-9) << "n = " << n;
    EXPECT_NEAR(peak, grid, 1e-5) << "n = " << n;
  }
}

// Designs of configs/doe/recuperative_drive.yaml (Sobol samples 206144,
// 348608, 536321, 41681, 709490, 436043) where an earlier refinement lied:
// two energy maxima within one grid step (the grid point was returned), a
// torque maximum beside a dead-centre kink (the search looked at one side
// only, or the grid showed no local maximum there: up to 10% low), and
// Gauss-Legendre nodes capped at 128 on long arcs near the dead point
// ((r + |e|)/l = 0.9999). Reference: the independent numpy peer
// bench/doe/peer_recuperative_doe.py (closed-form dead centres, uncapped
// Gauss-Legendre panels, every candidate maximum refined on both sides),
// whose values agreed with a 2e6-point scan and scipy quad to 1e-12:
//   /usr/bin/python3 bench/doe/peer_recuperative_doe.py --samples 1000000 --store PEER.sqlite
// Columns: l, dphi, r, e; peak T, rms M, mean M, peak |M|.
TEST(TwinDrive, HardDesignsMatchAnIndependentPeer) {
  const double cases[][8] = {
      {0.3402530670166016, 0.02894190314643612, 0.20098190307617186, 0.049530792236328114, 4691.999937009683,
       3532.869686697433, 1030.0070939938241, 6337.71200200135},
      {0.3234838485717773, 0.9496239893880021, 0.2839817047119141, -0.039496231079101565, 19053.503997062548,
       80418.18250390455, 1525.6093923316714, 1703257.384655382},
      {0.955637264251709, 1.9107797991911835, 0.12154827117919922, 0.043673896789550776, 1106.6853634610118,
       695.6392936360302, 613.1571693897558, 1109.6333588041462},
      {1.1013717651367188, 1.8937472195444454, 0.1289520263671875, 0.049813842773437506, 1245.2162870457764,
       738.2342192654291, 650.4899008854256, 1176.7310471467038},
      {1.3733477592468262, 1.5529188592923309, 0.19785671234130858, -0.08561153411865235, 2785.264282024993,
       1178.5391965312203, 999.0237696943641, 2034.6968923376112},
      {0.9052415847778321, 1.8738114614143848, 0.12485313415527344, 0.09572334289550782, 1036.0026156113618,
       662.2736491249863, 632.7773140609069, 895.8687707698789}};
  for (const auto& c : cases) {
    TwinDrive<double> d{c[2], c[0], c[1], c[3], 100 * kPi / 30, 1000, 80, 0.9, 3562};
    d.resistance = mech::Resistance::opposes_motion;
    ASSERT_EQ(mech::check(d), mech::Status::ok);
    const auto m = mech::cycle_metrics(d, mech::auto_cycle_points(d));
    EXPECT_NEAR(m.peak_kinetic_energy, c[4], 1e-11 * c[4]) << "l = " << c[0];
    EXPECT_NEAR(m.rms_total_moment, c[5], 1e-11 * c[5]) << "l = " << c[0];
    EXPECT_NEAR(m.mean_total_moment, c[6], 1e-11 * c[6]) << "l = " << c[0];
    EXPECT_NEAR(m.peak_total_moment, c[7], 1e-11 * c[7]) << "l = " << c[0];
  }
}

// The closed-form dead centres (exact kinematics) are where each slider
// stops: its velocity vanishes there and changes sign across, two per slider.
TEST(TwinDrive, DeadCentresAreWhereTheSlidersStop) {
  for (auto layout : {mech::Layout::opposed, mech::Layout::same_side})
    for (double e : {-0.09, 0.0, 0.05})
      for (double l : {0.32, 0.8}) {
        auto d = seed000(l);
        d.layout = layout;
        d.offset = e;
        d.phase_shift = 1.3;
        const auto centres = mech::dead_centres(d, 24);
        ASSERT_EQ(centres.size(), 4u);
        for (int i = 0; i < 4; ++i) {
          const auto m = d.mechanism(i / 2);
          const double psi = centres[std::size_t(i)] + (i < 2 ? 0.0 : d.phase_shift);
          auto dx = [&](double a) { return mech::slider_crank_velocity(m, std::cos(a), std::sin(a)).dx; };
          EXPECT_NEAR(dx(psi), 0.0, 1e-13) << "l " << l << " e " << e;
          EXPECT_LT(dx(psi - 1e-4) * dx(psi + 1e-4), 0) << "l " << l << " e " << e;
          EXPECT_GE(centres[std::size_t(i)], 0.0);
          EXPECT_LT(centres[std::size_t(i)], 2 * kPi);
        }
      }
}

TEST(TwinDrive, MirroredLayoutAtZeroOffsetHasTheSameEnergyAsShiftedSameSide) {
  // At zero offset a mirrored slider moves as x_m(psi) = -x_n(psi + pi): its
  // energy is the normal one shifted by pi, and a cycle mean is shift-invariant.
  auto a = seed000(0.9), b = seed000(0.9);
  b.layout = mech::Layout::same_side;
  EXPECT_NEAR(mech::mean_kinetic_energy(a, 64), mech::mean_kinetic_energy(b, 64), 1e-9);
}

TEST(TwinDrive, InfeasibleDesignsAreStatuses) {
  auto d = seed000(0.15);  // rod shorter than the crank
  EXPECT_EQ(mech::check(d), mech::Status::cannot_assemble);
  d = seed000(0.8);
  d.efficiency = 0;
  EXPECT_EQ(mech::check(d), mech::Status::invalid_parameter);
}

}  // namespace
