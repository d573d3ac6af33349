// The chain's third derivatives in the crank angle (mech/linkage/third.hpp:
// each group's constraints differentiated three times) and the driving
// torque's slope from them, against forward-mode autodiff in phi: the
// chain solved on a Dual of slope 1 in phi, whose second derivatives'
// slopes are the third derivatives and whose |torque| has the slope. On
// every shipped linkage config of RRR and RRP groups, at eight angles.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "mech/linkage/third.hpp"
#include "opt/config.hpp"
#include "problems/linkage/description.hpp"
#include "paths.hpp"

namespace {

using mech::Dual;
using mech::Lanes;
using mech::linkage::Chain;
using mech::linkage::State;
using mech::linkage::Thirds;

const double kAngles[] = {0.3, 1.7, 3.1, 5.5, 0.9, 2.4, 4.0, 6.1};

void expect_thirds(const Chain& c, const std::string& what) {
  const std::vector<double>& v = c.defaults();
  const std::vector<Dual> vd(v.begin(), v.end());
  State<double> st;
  State<Dual> sd;
  st.resize(c), sd.resize(c);
  Thirds<double> t;
  t.resize(c);
  for (double phi : kAngles) {
    ASSERT_TRUE(mech::linkage::solve(c, v.data(), phi, st)) << what;
    ASSERT_TRUE(mech::linkage::solve(c, vd.data(), mech::seed(phi), sd)) << what;
    mech::linkage::third_order(c, v.data(), st, t);
    // Every point's, axis's and slide's x''' and y''' against the dual's,
    // to 1e-12 of the largest.
    std::vector<std::pair<double, double>> pairs;  // (ours, the dual's)
    for (size_t p = 0; p < c.point_names().size(); ++p) {
      pairs.emplace_back(t.point[p].x, sd.point[p].x.dd.d);
      pairs.emplace_back(t.point[p].y, sd.point[p].y.dd.d);
    }
    for (size_t k = 0; k < c.links().size(); ++k) {
      pairs.emplace_back(t.axis[k].x, sd.axis[k].x.dd.d);
      pairs.emplace_back(t.axis[k].y, sd.axis[k].y.dd.d);
      pairs.emplace_back(t.slide[k], sd.slide[k].dd.d);
    }
    double scale = 0;
    for (const auto& [ours, dual] : pairs) scale = std::max(scale, std::abs(dual));
    for (size_t i = 0; i < pairs.size(); ++i)
      EXPECT_NEAR(pairs[i].first, pairs[i].second, 1e-12 * scale) << what << " at " << phi << ", entry " << i;
  }
}

// |M|'s slope on lanes against the dual's, to 1e-12 of the largest |M'|
// (returned: 0 for a chain without masses or loads), its drive point
// against drive_point's bits.
double expect_torque_slopes(const Chain& c, const std::string& what) {
  const std::vector<double>& v = c.defaults();
  const std::vector<Dual> vd(v.begin(), v.end());
  mech::linkage::LaneSolver<double> lanes(c, v.data());
  Thirds<Lanes> t;
  t.resize(c);
  State<Dual> sd;
  sd.resize(c);
  std::vector<std::pair<double, double>> pairs;
  for (int b = 0; b < 2; ++b) {
    Lanes phi, cp, sp;
    for (int j = 0; j < mech::kLanes; ++j) phi[j] = kAngles[mech::kLanes * b + j];
    mech::sincos(phi, sp, cp);
    const State<Lanes>& st = lanes.at(phi, cp, sp);
    mech::linkage::third_order(c, lanes.v.data(), st, t);
    const mech::linkage::DriveSlope ds = mech::linkage::drive_slope(c, lanes.v.data(), st, t);
    const Lanes& slope = ds.slope;
    // Its drive point is drive_point's, bit for bit.
    const mech::linkage::DrivePoint<Lanes> p = mech::linkage::drive_point(c, lanes.v.data(), st);
    for (int j = 0; j < mech::kLanes; ++j) {
      EXPECT_EQ(ds.point.energy[j], p.energy[j]) << what;
      EXPECT_EQ(ds.point.torque[j], p.torque[j]) << what;
      EXPECT_EQ(ds.point.energy_slope[j], p.energy_slope[j]) << what;
    }
    for (int j = 0; j < mech::kLanes; ++j) {
      EXPECT_TRUE(mech::linkage::solve(c, vd.data(), mech::seed(phi[j]), sd)) << what;
      const Dual m = mech::linkage::drive_point(c, vd.data(), sd).torque;
      pairs.emplace_back(slope[j], m.v < 0 ? -m.d : m.d);
    }
  }
  double scale = 0;
  for (const auto& [ours, dual] : pairs) scale = std::max(scale, std::abs(dual));
  for (size_t i = 0; i < pairs.size(); ++i)
    EXPECT_NEAR(pairs[i].first, pairs[i].second, 1e-12 * scale) << what << " at " << kAngles[i];
  return scale;
}

TEST(LinkageThird, TheThirdDerivativesAreTheDualsInPhi) {
  int n = 0;
  for (const auto& f : std::filesystem::directory_iterator(std::string(MECHOPT_SOURCE_DIR) + "/configs/linkage")) {
    const auto d = problems::linkage::read_description(opt::ConfigNode::load(f.path().string()));
    if (!mech::linkage::has_third_order(d.chain)) continue;
    expect_thirds(d.chain, f.path().filename().string());
    ++n;
  }
  EXPECT_GE(n, 6);
}

TEST(LinkageThird, TheTorquesSlopeIsTheDualsInPhi) {
  int n = 0;
  for (const auto& f : std::filesystem::directory_iterator(std::string(MECHOPT_SOURCE_DIR) + "/configs/linkage")) {
    const auto d = problems::linkage::read_description(opt::ConfigNode::load(f.path().string()));
    if (!mech::linkage::has_third_order(d.chain)) continue;
    n += expect_torque_slopes(d.chain, f.path().filename().string()) > 0;
  }
  EXPECT_GE(n, 5);
}

}  // namespace
