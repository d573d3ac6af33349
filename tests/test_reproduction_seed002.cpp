// Seed 002 Tables 1-2 (the conveyor swing mechanism's five variants): what
// reproduces is pinned; what does not is pinned as the documented difference.
// Paper values are the printed tables; the rest are closed forms.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "opt/config.hpp"
#include "opt/driver.hpp"
#include "opt/drivers/ipopt.hpp"
#include "opt/drivers/nlopt.hpp"
#include "problems/conveyor_swing.hpp"

namespace {

constexpr double kDeg = std::numbers::pi / 180;

struct Variant {
  double l_co1, l3, l1, l2, pressure_deg, K;
};
const Variant kPaper[] = {  // Tables 1 and 2
    {0.6, 1.17, 0.06, 1.35, 69, 1.35}, {1.2, 1.56, 0.35, 1.27, 65, 1.29},
    {1.4, 1.72, 0.44, 1.30, 52, 1.19}, {1.6, 1.89, 0.51, 1.35, 39, 1.09},
    {1.8, 2.06, 0.57, 1.44, 26, 1.01}};

std::unique_ptr<opt::Problem> family() {
  return problems::make_conveyor_swing(opt::ConfigNode::parse(
      "problem: conveyor_swing\nvariables: {l_co1: {min: 0.3 m, max: 3 m}}\n", "<seed002>"));
}

opt::Evaluation at(const opt::Problem& p, double l_co1) {
  return p.evaluate(Eigen::VectorXd::Constant(1, l_co1), opt::MetricSet::all(), false);
}

TEST(Seed002Table1, LinkLengthsReproduce) {
  // The table prints two decimals from a graphical construction, sometimes
  // truncated (0.3555 -> 0.35) and sometimes rounded (0.5674 -> 0.57): one
  // unit of the last digit, 0.01 m.
  const auto p = family();
  for (const Variant& v : kPaper) {
    const auto e = at(*p, v.l_co1);
    EXPECT_NEAR(e.at("rocker_length"), v.l3, 0.01) << v.l_co1;
    EXPECT_NEAR(e.at("crank_length"), v.l1, 0.01) << v.l_co1;
    EXPECT_NEAR(e.at("coupler_length"), v.l2, 0.01) << v.l_co1;
    EXPECT_NEAR(e.at("frame_length"), 2.42, 0.005);  // eq. (1)
    EXPECT_NEAR(e.at("rocker_length"), std::hypot(v.l_co1, 1.0), 1e-14);  // eq. (3)
  }
}

TEST(Seed002Reference, PeakMomentsAgreeWithHighPrecisionReference) {
  // tools/reference_seed002.py: mpmath at 30 digits, angles by circle
  // intersection, derivatives numerically, M = dT/dphi + M_c |w3| (no shared
  // code, none of our velocity or acceleration formulas). Both converge to
  // roundoff, so 1e-10 relative.
  const double kRef[][2] = {{1.2, 153931.18899275564},
                            {1.4, 114328.02123318473},
                            {1.6, 109304.52816473052},
                            {1.8, 137188.88866149927}};
  const auto p = family();
  for (const auto& [l_co1, peak] : kRef)
    EXPECT_NEAR(at(*p, l_co1).at("peak_crank_torque"), peak, 1e-10 * peak) << l_co1;
  EXPECT_NEAR(at(*p, 1.2).at("crank_length"), 0.35548393472677394, 1e-14);
  EXPECT_NEAR(at(*p, 1.2).at("coupler_length"), 1.2716334533860779, 1e-14);
}

TEST(Seed002Table2, TimeRatioAndPressureAngleOfVariants1To3Reproduce) {
  // K to the printed two decimals (0.01, truncation included); the maximum
  // pressure angle to the graphical method's degree (1 deg).
  const auto p = family();
  for (int i = 1; i <= 3; ++i) {
    const auto e = at(*p, kPaper[i].l_co1);
    ASSERT_TRUE(e.ok());
    EXPECT_NEAR(e.at("time_ratio"), kPaper[i].K, 0.01) << kPaper[i].l_co1;
    EXPECT_NEAR(e.at("max_pressure_angle") / kDeg, kPaper[i].pressure_deg, 1.0) << kPaper[i].l_co1;
    EXPECT_NEAR(e.at("swing_angle") / kDeg, 32.0, 1e-10);
  }
}

TEST(Seed002Table2, Variant4PressureAngleIsTakenAtOneOfTwoPositions) {
  // The paper reads [gamma]_max with the crank on the line OO1 pointing away
  // from O1: 26 deg (ours 26.0). Pointing toward O1 it is 29.2 deg, the true
  // maximum over the cycle, which is what we report.
  const auto p = family();
  const auto e = at(*p, 1.8);
  EXPECT_NEAR(e.at("max_pressure_angle") / kDeg, 29.19, 0.01);
  EXPECT_NEAR(e.at("time_ratio"), 1.01, 0.01);
}

TEST(Seed002Table1, Variant0HasNoCrankRockerSynthesis) {
  // B' and B'' straddle the frame line at l_CO1 = 0.6 m: synthesis_failed
  // (the paper lists it as valid and excludes it only for its pressure angle).
  const auto p = family();
  const auto e = at(*p, 0.6);
  EXPECT_EQ(e.status, mech::Status::synthesis_failed);
  EXPECT_LT(e.at("synthesis_margin"), 0.0);
  EXPECT_FALSE(e.has("peak_crank_torque"));
}

TEST(Seed002Optimum, ContinuousOptimumBeatsEveryVariant) {
  // Least peak balancing moment in the l_CO1 family under [gamma] <= 60 deg:
  // every driver that converges lands on the same design (a kink where two
  // moment peaks are equal), below every admissible variant of the paper.
  const auto p = problems::make_conveyor_swing(opt::ConfigNode::parse(R"(
problem: conveyor_swing
variables: {l_co1: {min: 0.9 m, max: 2.4 m}}
)", "<seed002>"));
  const std::vector<opt::Constraint> cons = {{"max_pressure_angle", true, 60 * kDeg}};
  double best = HUGE_VAL, where = 0;
  for (const char* alg : {"LD_SLSQP", "LD_MMA", "LN_COBYLA"}) {
    opt::DriverOptions o;
    o.algorithm = alg;
    o.xtol_rel = 1e-10;
    const auto r = opt::NloptDriver(o).minimize(*p, {"peak_crank_torque"}, cons, p->initial_point());
    ASSERT_EQ(r.status, opt::DriverStatus::converged) << alg << ": " << r.message;
    if (where != 0) {
      EXPECT_NEAR(r.x[0], where, 1e-6) << alg;
    }
    where = r.x[0];
    best = std::min(best, r.objective);
  }
  // tools/reference_seed002.json: the two moment troughs are equal at
  // l_CO1 = 1.5224536093493499 m, peak 98310.834286910226 N m.
  EXPECT_NEAR(where, 1.5224536093493499, 1e-8);
  EXPECT_NEAR(best, 98310.834286910226, 1e-9 * best);
  for (int i = 2; i <= 4; ++i) {  // variants within the pressure-angle limit
    EXPECT_LT(best, 0.95 * at(*p, kPaper[i].l_co1).at("peak_crank_torque")) << kPaper[i].l_co1;
  }
  // A 1 mm scan around the optimum finds nothing lower (the max is nonsmooth).
  for (double l = where - 0.05; l <= where + 0.05; l += 0.001) {
    const auto e = at(*p, l);
    if (e.ok() && e.at("max_pressure_angle") <= 60 * kDeg) {
      EXPECT_GE(e.at("peak_crank_torque"), best - 1e-6 * best) << "l_co1 = " << l;
    }
  }
}

TEST(Seed002Drivers, IpoptNeedsTheEpigraphOnTheKink) {
  // At the optimum two moment troughs are equal, so the peak is not
  // differentiable there. Ipopt on the plain maximum does not converge (its
  // iteration limit, or a failed restoration, is reported as such); with the
  // epigraph rows it converges to the reference from every start. (With
  // the rows ordered by value, which swapped the two peaks' rows wherever
  // they crossed, 2 of 30 starts from 0.92 to 2.37 m ran out of iterations
  // on the optimum with the dual infeasibility near 1e-2.)
  const auto p = family();
  const std::vector<opt::Constraint> cons = {{"max_pressure_angle", true, 60 * kDeg}};
  opt::DriverOptions o;
  o.library = "ipopt";
  o.max_iterations = 200;
  int evaluations = 0;
  for (const double start : {1.0, 1.1, 1.2, 1.3, 1.4, 1.6, 1.7, 1.9, 2.1}) {
    const auto with = opt::IpoptDriver(o).minimize(*p, {"peak_crank_torque"}, cons, Eigen::VectorXd::Constant(1, start));
    EXPECT_EQ(with.status, opt::DriverStatus::converged) << start << ": " << with.message;
    EXPECT_NEAR(with.x[0], 1.5224536093493499, 1e-8) << start;
    evaluations = std::max(evaluations, with.evaluations);
  }
  o.epigraph = false;
  const auto without = opt::IpoptDriver(o).minimize(*p, {"peak_crank_torque"}, cons, Eigen::VectorXd::Constant(1, 1.2));
  EXPECT_NE(without.status, opt::DriverStatus::converged) << without.message;
  EXPECT_GT(without.evaluations, 10 * evaluations);
}

TEST(Seed002Failures, InfeasibleStartIsRestoredThenOptimised) {
  // Start in the failed-synthesis region (variant 0): phase 1 moves to a
  // valid synthesis, then SLSQP finds the same optimum as from a valid start.
  const auto p = problems::make_conveyor_swing(opt::ConfigNode::parse(R"(
problem: conveyor_swing
variables: {l_co1: {min: 0.3 m, max: 3 m, initial: 0.6 m}}
)", "<seed002>"));
  ASSERT_EQ(p->evaluate(p->initial_point(), opt::MetricSet::all(), false).status, mech::Status::synthesis_failed);
  opt::DriverOptions o;
  o.xtol_rel = 1e-10;
  const std::vector<opt::Constraint> cons = {{"max_pressure_angle", true, 60 * kDeg}};
  const auto r = opt::NloptDriver(o).minimize(*p, {"peak_crank_torque"}, cons, p->initial_point());
  ASSERT_EQ(r.status, opt::DriverStatus::converged) << r.message;
  EXPECT_NE(r.message.find("phase 1 restored it"), std::string::npos) << r.message;
  EXPECT_NEAR(r.x[0], 1.5224536093493499, 1e-8);  // tools/reference_seed002.json
}

TEST(Seed002Failures, SweepRecordsEveryStatus) {
  // Each failure is a row with its status, and the metrics that stay defined.
  const auto p = family();
  EXPECT_EQ(at(*p, 0.5).status, mech::Status::synthesis_failed);
  EXPECT_EQ(at(*p, 1.2).status, mech::Status::ok);
  const auto free = [](const std::string& lengths) {
    return problems::make_conveyor_swing(opt::ConfigNode::parse(
        "problem: conveyor_swing\nmodel: {design: free_links, " + lengths + "}\n", "<seed002>"));
  };
  const Eigen::VectorXd none(0);
  EXPECT_EQ(free("crank_length: 3 m")->evaluate(none, opt::MetricSet::all(), false).status, mech::Status::not_grashof);
  EXPECT_EQ(free("coupler_length: 9 m")->evaluate(none, opt::MetricSet::all(), false).status, mech::Status::cannot_assemble);
  const auto e = free("crank_length: 1.5 m, coupler_length: 0.5 m, rocker_length: 1.6 m")
                     ->evaluate(none, opt::MetricSet::all(), false);
  EXPECT_EQ(e.status, mech::Status::toggle_in_cycle);
  EXPECT_LT(e.at("rotation_margin"), 0.0);
  EXPECT_FALSE(e.has("peak_crank_torque"));
}

}  // namespace
