// Every config in configs/ runs through the command line: exit code 0, a
// result.json whose status is a success, and the files a user expects.
#include <gtest/gtest.h>

#include <cstdio>
#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <nlohmann/json.hpp>
#include <sys/wait.h>

#include "opt/display_units.hpp"
#include "opt/registry.hpp"
#include "paths.hpp"

namespace {

namespace fs = std::filesystem;

std::vector<std::string> configs() {
  std::vector<std::string> out;
  for (const auto& e : fs::recursive_directory_iterator(std::string(MECHOPT_SOURCE_DIR) + "/configs"))
    if (e.path().extension() == ".yaml")
      out.push_back(fs::relative(e.path(), std::string(MECHOPT_SOURCE_DIR) + "/configs").string());
  std::sort(out.begin(), out.end());
  return out;
}

class Config : public ::testing::TestWithParam<std::string> {};

// The text of every <text> element of an SVG file, in order, with whether it
// is rotated (the y axis label).
struct SvgText {
  std::string text;
  bool rotated;
};
std::vector<SvgText> svg_texts(const std::string& svg) {
  std::vector<SvgText> out;
  for (size_t at = svg.find("<text"); at != std::string::npos; at = svg.find("<text", at + 1)) {
    const size_t open_end = svg.find('>', at), close = svg.find("</text>", at);
    if (open_end == std::string::npos || close == std::string::npos) break;
    const std::string tag = svg.substr(at, open_end - at);
    out.push_back({svg.substr(open_end + 1, close - open_end - 1), tag.find("rotate(-90)") != std::string::npos});
  }
  return out;
}

size_t count(const std::string& text, const std::string& what) {
  size_t n = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

// cycle.svg: the x axis in degrees of crank angle (or seconds), the y axis
// labelled with the unit of the problem's primary cycle curve (never
// "[SI]"), every curve the problem plots with it named (on the axis or in
// the legend; neither cut), and the legend beside the plot at most 30% of
// the chart's width; cycle.csv headed "name [unit]". What the problem plots
// comes from the problem itself (opt::CycleCurves at the config's start).
void check_cycle_chart(const std::string& dir, const std::string& config) {
  const auto p = opt::make_problem(opt::ConfigNode::load(config));
  const opt::CycleCurves curves = p->cycle_curves(p->initial_point(), 8);
  ASSERT_FALSE(curves.plotted().empty()) << p->name() << " draws cycle.svg but gives no curves at its start";
  std::ifstream in(dir + "/cycle.svg");
  const std::string svg((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(svg.find("[SI]"), std::string::npos);
  const auto texts = svg_texts(svg);
  const auto y = std::find_if(texts.begin(), texts.end(), [](const SvgText& t) { return t.rotated; });
  ASSERT_NE(y, texts.end()) << "no y axis label";
  ASSERT_NE(y, texts.begin());
  const std::string x_label = std::prev(y)->text;
  EXPECT_TRUE(x_label == "crank_angle [deg]" || x_label == "time [s]") << x_label;
  const std::string unit = opt::shown_unit(curves.units[curves.primary]).unit;
  EXPECT_NE(y->text.find(" [" + unit + "]"), std::string::npos) << y->text << ", expected [" << unit << "]";
  for (size_t k : curves.plotted()) {
    const std::string& name = curves.names[k];
    EXPECT_TRUE(std::any_of(y, texts.end(), [&](const SvgText& t) { return t.text.find(name) != std::string::npos; }))
        << name << " neither on the y axis nor in the legend";
  }
  const size_t plot = svg.find("<rect x='80' y='40' width='");
  ASSERT_NE(plot, std::string::npos);
  EXPECT_GE(std::strtod(svg.c_str() + plot + 27, nullptr), 780 - 80 - 0.3 * 780);  // the legend: at most 30%
  std::ifstream csv(dir + "/cycle.csv");
  std::string head;
  std::getline(csv, head);
  EXPECT_TRUE(head.rfind("crank_angle [rad],", 0) == 0 || head.rfind("time [s],", 0) == 0) << head;
  EXPECT_EQ(count(head, "["), count(head, ",") + 1) << head;
}

// Every chart a run writes renders to a PNG (rsvg-convert, from
// librsvg2-bin, which `make deps` installs: a missing renderer fails, never
// skips), and both its axis labels end in a unit, "[unit]": angles in
// degrees, a plain number as [-], never [], [SI] or [rad].
void check_every_chart(const std::string& dir) {
  ASSERT_EQ(std::system("command -v rsvg-convert > /dev/null 2>&1"), 0) << "rsvg-convert (librsvg2-bin) not installed";
  for (const auto& e : fs::directory_iterator(dir)) {
    if (e.path().extension() != ".svg") continue;
    const std::string svg_file = e.path().string(), png = svg_file.substr(0, svg_file.size() - 4) + ".png";
    SCOPED_TRACE(svg_file);
    const std::string render = "rsvg-convert -o " + png + " " + svg_file;
    ASSERT_EQ(std::system(render.c_str()), 0) << render;
    std::ifstream png_in(png, std::ios::binary);
    char magic[8] = {};
    png_in.read(magic, 8);
    EXPECT_EQ(std::string(magic + 1, 3), "PNG");
    std::ifstream in(svg_file);
    const auto texts = svg_texts(std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>()));
    const auto y = std::find_if(texts.begin(), texts.end(), [](const SvgText& t) { return t.rotated; });
    ASSERT_NE(y, texts.end()) << "no y axis label";
    ASSERT_NE(y, texts.begin());
    for (const std::string& label : {std::prev(y)->text, y->text}) {
      const size_t open = label.rfind(" [");
      ASSERT_NE(open, std::string::npos) << "no unit: " << label;
      const std::string unit = label.substr(open + 2);
      EXPECT_TRUE(unit.size() > 1 && unit.back() == ']') << label;
      for (const char* bad : {"]", "SI]", "rad]"}) EXPECT_NE(unit, bad) << label;
    }
  }
}

// A doe config of more than kSlice samples runs its first shard of about
// kSlice samples (`--shard 0/K`, as a job array's first task would): every
// key is read and every step runs, without 10^6 evaluations per test run
// (minutes under the sanitizers).
constexpr long kSlice = 5000;

std::string shard_flag(const std::string& config) {
  std::ifstream in(config);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  // (no std::regex: GCC 12's <regex> trips -Wmaybe-uninitialized in the sanitizer build)
  const std::string key = "\n  samples: ";
  const auto at = text.find(key);
  if (at == std::string::npos) return "";
  const long n = static_cast<long>(std::strtod(text.c_str() + at + key.size(), nullptr));
  return n > kSlice ? " --shard 0/" + std::to_string((n + kSlice - 1) / kSlice) : "";
}

TEST_P(Config, RunsAndWritesResults) {
  const std::string dir = testing::TempDir() + "/e2e_" + std::to_string(std::hash<std::string>{}(GetParam()));
  fs::remove_all(dir);
  const std::string config = std::string(MECHOPT_SOURCE_DIR) + "/configs/" + GetParam();
  const std::string cmd = std::string(MECHOPT_BINARY) + " run " + config + shard_flag(config) + " --output " + dir +
                          " > " + dir + ".log 2>&1";
  const int status = std::system(cmd.c_str());
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "see " << dir << ".log";
  std::ifstream in(dir + "/result.json");
  ASSERT_TRUE(in) << "no result.json";
  const auto j = nlohmann::json::parse(in);
  // configs/PROBLEM/NAME.yaml, or configs/doe/PROBLEM[_NAME].yaml
  const fs::path p(GetParam());
  const std::string problem = j["problem"];
  if (p.parent_path() == "doe") EXPECT_EQ(p.stem().string().rfind(problem, 0), 0u) << problem;
  else EXPECT_EQ(problem, p.parent_path().string());
  EXPECT_FALSE(j["mechopt_version"].get<std::string>().empty());
  EXPECT_TRUE(j.contains("settings"));
  if (j.contains("status")) {
    EXPECT_EQ(j["status"], "converged") << j["message"];
    EXPECT_EQ(j["design_status"], "ok");
    EXPECT_GT(j["evaluations"].get<int>(), 0);
    for (const auto& [name, v] : j["metrics"].items()) EXPECT_TRUE(v.is_number()) << name;
    EXPECT_TRUE(fs::exists(dir + "/history.csv"));
  }
  if (j["study"] == "sweep") {
    EXPECT_TRUE(fs::exists(dir + "/sweep.csv"));
  }
  if (j["study"] == "sweep" || j["study"] == "doe") {  // the store closed: its WAL checkpointed and gone
    EXPECT_FALSE(fs::exists(dir + "/store.sqlite-wal"));
    EXPECT_FALSE(fs::exists(dir + "/store.sqlite-shm"));
  }
  if (j["study"] == "doe") {
    EXPECT_TRUE(fs::exists(dir + "/store.sqlite"));
    EXPECT_EQ(j["run_status"], "complete");
  }
  if (j.contains("charts")) {  // (const json's [] on a missing key is undefined)
    for (const auto& f : j["charts"]) EXPECT_TRUE(fs::exists(f.get<std::string>())) << f;
  }
  if (fs::exists(dir + "/cycle.svg")) {
    SCOPED_TRACE("cycle.svg of " + GetParam());
    check_cycle_chart(dir, config);
  }
  check_every_chart(dir);
  if (j.contains("variables") && j["variables"].size() == 1) {
    EXPECT_TRUE(fs::exists(dir + "/chart.svg"));
  }
}

INSTANTIATE_TEST_SUITE_P(All, Config, ::testing::ValuesIn(configs()), [](const auto& info) {
  std::string n = info.param;
  for (char& c : n)
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  return n;
});

}  // namespace

namespace {

// The sawmill's chart at the paper's design: the improved and the original
// balancing torque, two lines on one axis in N m, rendered to a PNG.
TEST(CycleChart, SawmillDrawsBothTorques) {
  const std::string dir = testing::TempDir() + "/cycle_sawmill";
  fs::remove_all(dir);
  const std::string cmd = std::string(MECHOPT_BINARY) + " run " + MECHOPT_SOURCE_DIR +
                          "/configs/balanced_slider_crank/paper.yaml --output " + dir + " > " + dir + ".log 2>&1";
  const int status = std::system(cmd.c_str());
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "see " << dir << ".log";
  std::ifstream in(dir + "/cycle.svg");
  const std::string svg((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(count(svg, "<polyline"), 2u);
  check_cycle_chart(dir, std::string(MECHOPT_SOURCE_DIR) + "/configs/balanced_slider_crank/paper.yaml");
  check_every_chart(dir);
  EXPECT_GT(fs::file_size(dir + "/cycle.png"), 5000u);
}

}  // namespace
