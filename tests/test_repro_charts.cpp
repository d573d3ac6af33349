// The chart writer on axes that used to make its tick loop endless (a span of
// a few ulp wrote a 1.26 GB pareto.svg): the range/tick helper on degenerate
// data, write_svg's file size, and the two repro configs through the CLI.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "cli.hpp"
#include "opt/chart.hpp"

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kMax = std::numeric_limits<double>::max();

std::string label(double t, int digits) {
  std::ostringstream s;
  s.precision(digits);
  s << t;
  return s.str();
}

// What every axis must be: a finite range lo < hi holding every finite value,
// 2..kMaxTicks increasing ticks inside it whose labels differ.
void expect_sane(const std::vector<double>& values, double pad = 0) {
  const opt::Axis a = opt::make_axis(values, pad);
  ASSERT_TRUE(std::isfinite(a.lo) && std::isfinite(a.hi)) << a.lo << " " << a.hi;
  ASSERT_LT(a.lo, a.hi);
  for (double v : values)
    if (std::isfinite(v)) {
      EXPECT_LE(a.lo, v);
      EXPECT_GE(a.hi, v);
    }
  ASSERT_GE(a.ticks.size(), 2u);
  ASSERT_LE(a.ticks.size(), static_cast<size_t>(opt::kMaxTicks));
  for (size_t i = 0; i < a.ticks.size(); ++i) {
    EXPECT_TRUE(std::isfinite(a.ticks[i]));
    EXPECT_LE(a.lo, a.ticks[i]);
    EXPECT_GE(a.hi, a.ticks[i]);
    if (i) {
      EXPECT_LT(a.ticks[i - 1], a.ticks[i]);
      EXPECT_NE(label(a.ticks[i - 1], a.digits), label(a.ticks[i], a.digits)) << "digits " << a.digits;
    }
  }
}

TEST(ChartAxis, ZeroSpan) {
  expect_sane({2960.6069564924892, 2960.6069564924892});
  expect_sane({0, 0});
  expect_sane({-7});
  const opt::Axis a = opt::make_axis({0.0});
  EXPECT_DOUBLE_EQ(a.lo, -1);
  EXPECT_DOUBLE_EQ(a.hi, 1);
}

TEST(ChartAxis, FewUlpSpan) {
  const double x = 2960.6069564924892;
  const double y = std::nextafter(std::nextafter(std::nextafter(x, kInf), kInf), kInf);
  expect_sane({x, y}, 0.05);
  expect_sane({x, y, x});
  expect_sane({1.0, std::nextafter(1.0, 2.0)});
  expect_sane({-1e-300, std::nextafter(-1e-300, 0.0)});
  // Padded around the value: a flat axis is not drawn at the ulp scale.
  const opt::Axis a = opt::make_axis({x, y});
  EXPECT_GT(a.hi - a.lo, 1.0);
}

TEST(ChartAxis, TinySpans) {
  expect_sane({0, 1e-300});
  expect_sane({1e-300, 2e-300});
  expect_sane({0, std::numeric_limits<double>::denorm_min()});
  expect_sane({1, 1 + 1e-12});
}

TEST(ChartAxis, HugeSpans) {
  expect_sane({0, 1e300});
  expect_sane({-1e300, 1e300}, 0.05);
  expect_sane({-kMax, kMax}, 0.05);
  expect_sane({kMax, kMax});
  expect_sane({1e300, 1e300 * (1 + 1e-15)});
}

TEST(ChartAxis, NonFiniteValuesSkipped) {
  expect_sane({kNaN, kInf, -kInf, 1.0, 2.0});
  const opt::Axis a = opt::make_axis({kNaN, 1.0, kInf, 2.0});
  const opt::Axis b = opt::make_axis({1.0, 2.0});
  EXPECT_EQ(a.lo, b.lo);
  EXPECT_EQ(a.hi, b.hi);
  EXPECT_EQ(a.ticks, b.ticks);
  for (const auto& none : std::vector<std::vector<double>>{{}, {kNaN}, {kInf, -kInf}}) {
    const opt::Axis c = opt::make_axis(none);
    EXPECT_EQ(c.lo, 0);
    EXPECT_EQ(c.hi, 1);
    expect_sane(none);
  }
}

TEST(ChartAxis, OrdinaryRangeGetsNiceTicks) {
  const opt::Axis a = opt::make_axis({0.5, 1.5});
  EXPECT_EQ(a.lo, 0.5);
  EXPECT_EQ(a.hi, 1.5);
  EXPECT_GE(a.ticks.size(), 4u);
  for (double t : a.ticks) EXPECT_NEAR(t * 5, std::round(t * 5), 1e-9) << t;  // steps of 0.2
}

std::uintmax_t svg_bytes(const opt::Chart& c, const std::string& name) {
  const std::string file = testing::TempDir() + "/" + name + ".svg";
  EXPECT_TRUE(opt::write_svg(c, file));
  std::ifstream in(file);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(text.find("nan"), std::string::npos) << file;
  EXPECT_EQ(text.find("inf"), std::string::npos) << file;
  return std::filesystem::file_size(file);
}

TEST(ChartSvg, DegenerateDataGivesASmallFile) {
  const double x = 2960.6069564924892;
  const std::vector<std::vector<double>> ys{
      {x, std::nextafter(x, kInf)}, {0, 0}, {0, 1e-300}, {-1e300, 1e300}, {-kMax, kMax},
      {kNaN, kInf}, {kNaN, 1.0}, {-kInf, 1e300}};
  for (size_t i = 0; i < ys.size(); ++i) {
    opt::Chart c{"title <&>", "x", "y", {}};
    c.series.push_back({"line", {ys[i][0], ys[i][1]}, ys[i], opt::Series::Style::line});
    c.series.push_back({"markers", ys[i], ys[i], opt::Series::Style::markers});
    EXPECT_LT(svg_bytes(c, "degenerate_" + std::to_string(i)), 20000u) << i;
  }
}

TEST(ChartSvg, MillionPointsAreThinned) {
  opt::Series line{"line", {}, {}, opt::Series::Style::line};
  opt::Series dots{"dots", {}, {}, opt::Series::Style::markers};
  for (int i = 0; i < 1000000; ++i) {
    line.x.push_back(i), line.y.push_back(std::sin(i * 1e-3));
    dots.x.push_back(i), dots.y.push_back(std::cos(i * 1e-3));
  }
  opt::Chart c{"many points", "i", "value", {line, dots}};
  EXPECT_LT(svg_bytes(c, "million"), 200000u);
}

// The two repro configs end in seconds with a small output directory. The
// pareto study may end with exit 1 and a message if a single-objective
// optimum fails; never a signal, a hang, or a file of gigabytes. The time
// limit is for a hang: the crank_radius 0.8 front takes ~5 s of CPU in
// Release (Ipopt, ~1100 evaluations) and ~60 s under ASan.
constexpr int kHangSeconds = cli::kSanitized ? 400 : 60;

void run_repro(const std::string& config) {
  const std::string dir = cli::fresh_dir("repro_" + config);
  const cli::Outcome o = cli::run("run " + cli::source("tests/repro/" + config + ".yaml") +
                                  " --output " + dir, kHangSeconds);
  EXPECT_FALSE(o.timed_out) << o.output.substr(0, 2000);
  EXPECT_EQ(o.signal, 0) << o.output.substr(0, 2000);
  EXPECT_TRUE(o.exit_code == 0 || o.exit_code == 1 || o.exit_code == 2) << o.exit_code;
  if (o.exit_code == 0) {
    EXPECT_TRUE(std::filesystem::exists(dir + "/pareto.svg")) << o.output;
  } else {
    EXPECT_NE(o.output.find("mechopt: "), std::string::npos) << "no message:\n" << o.output;
  }
  EXPECT_LT(cli::directory_bytes(dir), 1000000u);
}

TEST(ReproCharts, AxisSpanFewUlp) { run_repro("chart_axis_span_few_ulp"); }
TEST(ReproCharts, ParetoCrankRadius08) { run_repro("chart_axis_pareto_crank_radius_08"); }

}  // namespace
