// The mechanism's drawing (problems/linkage/drawing.hpp): read back from
// the SVG text as a reader of the file would, the joints drawn at each
// crank angle sit where an independent closed form puts them, a path's
// vertices lie on its point's curve, an angle that cannot assemble is left
// out and said, and the file is well-formed XML that renders.
//
// The closed forms are the slider-crank's, written here: crank angle
// theta = phase + sense phi, A = r (cos theta, sin theta), the ram's pin on
// the line y = y0 at B = (A.x + sqrt(l^2 - (A.y - y0)^2), y0) (ahead of the
// crank), a point (u, v) of the rod at A + u e + v rot90(e), e = (B - A) / l.
//
// Metres from pixels: the drawing's map is read from its axis ticks (each
// label's value at its pixel position), so the test checks what a reader
// of the axes sees. Every coordinate is printed to 3 decimals (half a unit
// of rounding, 5e-4 px, on a tick and on a circle), and the scale taken
// from the first and last ticks adds at most 1e-3 px across the plot: a
// position read back is within 2e-3 px, divided by the scale in metres.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <numbers>
#include <string>
#include <unistd.h>
#include <vector>

#include "cli.hpp"
#include "opt/registry.hpp"
#include "problems/linkage/description.hpp"
#include "problems/linkage/drawing.hpp"

namespace {

namespace fs = std::filesystem;
using problems::linkage::mechanism_svg;
using problems::linkage::read_description;
constexpr double kPi = std::numbers::pi;
constexpr double kPixels = 2e-3;  // a position read back, in pixels (above)

struct Pt {
  double x, y;
};

// The opening tag of the element with this id, or "".
std::string tag_of(const std::string& svg, const std::string& id) {
  const size_t at = svg.find("id='" + id + "'");
  if (at == std::string::npos) return "";
  const size_t open = svg.rfind('<', at);
  return svg.substr(open, svg.find('>', at) - open);
}
std::string attr(const std::string& tag, const std::string& name) {
  const size_t at = tag.find(" " + name + "='");
  if (at == std::string::npos) return "";
  const size_t from = at + name.size() + 3;
  return tag.substr(from, tag.find('\'', from) - from);
}

// Pixels to metres, from the tick labels: px = a + s x, py = b - s y.
struct Map {
  double a = 0, sx = 0, b = 0, sy = 0;
  Pt metres(Pt p) const { return {(p.x - a) / sx, (b - p.y) / sy}; }
};
// (pixel, value) of each tick label of class `cls`, its pixel in attribute `at`.
std::vector<std::pair<double, double>> ticks(const std::string& svg, const std::string& cls, const std::string& at) {
  std::vector<std::pair<double, double>> out;
  for (size_t i = svg.find("class='" + cls + "'"); i != std::string::npos; i = svg.find("class='" + cls + "'", i + 1)) {
    const size_t open = svg.rfind('<', i), end = svg.find('>', i);
    const std::string tag = svg.substr(open, end - open);
    out.emplace_back(std::stod(attr(tag, at)), std::stod(svg.substr(end + 1, svg.find('<', end) - end - 1)));
  }
  return out;
}
Map read_map(const std::string& svg) {
  const auto xs = ticks(svg, "xtick", "x"), ys = ticks(svg, "ytick", "y");
  Map m;
  EXPECT_GE(xs.size(), 2u);
  EXPECT_GE(ys.size(), 2u);
  if (xs.size() < 2 || ys.size() < 2) return m;
  m.sx = (xs.back().first - xs.front().first) / (xs.back().second - xs.front().second);
  m.a = xs.front().first - m.sx * xs.front().second;
  m.sy = (ys.front().first - ys.back().first) / (ys.back().second - ys.front().second);
  m.b = ys.front().first + m.sy * ys.front().second;
  for (const auto& [px, x] : xs) EXPECT_NEAR(px, m.a + m.sx * x, kPixels);
  for (const auto& [py, y] : ys) EXPECT_NEAR(py, m.b - m.sy * y, kPixels);
  EXPECT_NEAR(m.sx, m.sy, 2 * kPixels / (xs.back().second - xs.front().second));  // one scale for x and y
  return m;
}
// The centre of circle `id` in metres.
Pt circle(const std::string& svg, const Map& m, const std::string& id) {
  const std::string tag = tag_of(svg, id);
  EXPECT_FALSE(tag.empty()) << "no circle " << id;
  if (tag.empty()) return {NAN, NAN};
  return m.metres({std::stod(attr(tag, "cx")), std::stod(attr(tag, "cy"))});
}
// The vertices of polyline `id` in metres.
std::vector<Pt> polyline(const std::string& svg, const Map& m, const std::string& id) {
  std::vector<Pt> out;
  const std::string points = attr(tag_of(svg, id), "points");
  const char* s = points.c_str();
  for (char* end = nullptr;; s = end + 1) {
    const double x = std::strtod(s, &end);
    if (end == s || *end != ',') break;
    s = end + 1;
    const double y = std::strtod(s, &end);
    out.push_back(m.metres({x, y}));
  }
  return out;
}

// The slider-crank's joints: crank r at crank angle theta, rod l, the line y = y0.
struct SliderCrank {
  double r, l, y0;
  Pt A(double theta) const { return {r * std::cos(theta), r * std::sin(theta)}; }
  Pt B(double theta) const {
    const Pt a = A(theta);
    return {a.x + std::sqrt(l * l - (a.y - y0) * (a.y - y0)), y0};
  }
  Pt on_rod(double theta, double u, double v) const {
    const Pt a = A(theta), b = B(theta), e{(b.x - a.x) / l, (b.y - a.y) / l};
    return {a.x + u * e.x - v * e.y, a.y + u * e.y + v * e.x};
  }
};

void expect_at(Pt got, Pt want, double tol, const std::string& what) {
  EXPECT_NEAR(got.x, want.x, tol) << what;
  EXPECT_NEAR(got.y, want.y, tol) << what;
}

std::string slider_crank_yaml(const std::string& crank, const std::string& s0, const std::string& rod = "{length: 0.8 m}") {
  return "problem: linkage\nmodel:\n  ground: {O: [0 m, 0 m], S0: " + s0 + "}\n  crank: " + crank +
         "\n  links:\n    crank: {length: 0.2 m}\n    rod: " + rod +
         "\n    ram: {line: {fixed_to: ground, through: S0, angle: 0 deg}}\n"
         "  groups:\n    - {type: RRP, links: [rod, ram], from: A, joint: B, branch: 1}\n  outputs: [ram]\n";
}

// configs/linkage/slider_crank.yaml as a run draws it (its variables at
// their initial values: r = 0.2 m, l = 0.8 m, the line at y = -0.02 m), at
// 0, 60, ..., 300 deg, the first in full.
TEST(LinkageDrawing, JointsSitAtTheSliderCranksClosedForm) {
  const auto p = opt::make_problem(opt::ConfigNode::load(cli::source("configs/linkage/slider_crank.yaml")));
  const std::string svg = p->mechanism_svg(p->initial_point(), "its start");
  const Map m = read_map(svg);
  const double tol = kPixels / m.sx;
  const SliderCrank sc{0.2, 0.8, -0.02};
  for (int k = 0; k < 6; ++k) {
    const double theta = k * kPi / 3;
    expect_at(circle(svg, m, "A." + std::to_string(k)), sc.A(theta), tol, "A at " + std::to_string(60 * k) + " deg");
    expect_at(circle(svg, m, "B." + std::to_string(k)), sc.B(theta), tol, "B at " + std::to_string(60 * k) + " deg");
  }
  expect_at(circle(svg, m, "O.ground"), {0, 0}, tol, "O");
  expect_at(circle(svg, m, "S0.ground"), {0, -0.02}, tol, "S0");
  EXPECT_EQ(attr(tag_of(svg, "angle.0"), "opacity"), "");  // in full
  EXPECT_EQ(attr(tag_of(svg, "angle.3"), "opacity"), "0.3");
  EXPECT_NE(svg.find("Crank angles drawn [deg]: 0 (in full), 60, 120, 180, 240, 300."), std::string::npos);
  // The ram's pin's path: 361 vertices at 2 pi k / 360 on the line.
  const auto path = polyline(svg, m, "path.B");
  ASSERT_EQ(path.size(), 361u);
  for (size_t k = 0; k < path.size(); k += 7) expect_at(path[k], sc.B(2 * kPi * k / 360), tol, "path of B");
}

// A clockwise crank at a phase, a point E on the rod: E's path is its
// coupler curve vertex by vertex, and E drawn at any angle is on it.
TEST(LinkageDrawing, PathsLieOnTheCouplerCurve) {
  const auto d = read_description(opt::ConfigNode::parse(
      slider_crank_yaml("{link: crank, pivot: O, joint: A, phase: 20 deg, speed: 60 rpm, sense: cw}", "[0 m, 0.05 m]",
                        "{length: 0.8 m, points: {E: [0.3 m, 0.1 m]}}"),
      "<drawing>"));
  const std::string svg = mechanism_svg(d, d.chain.defaults(), {0.3, 2.0}, "E's curve");
  const Map m = read_map(svg);
  const double tol = kPixels / m.sx, phase = 20 * kPi / 180;
  const SliderCrank sc{0.2, 0.8, 0.05};
  const auto path = polyline(svg, m, "path.E");
  ASSERT_EQ(path.size(), 361u);
  for (size_t k = 0; k < path.size(); ++k)
    expect_at(path[k], sc.on_rod(phase - 2 * kPi * k / 360, 0.3, 0.1), tol, "vertex " + std::to_string(k));
  EXPECT_TRUE(tag_of(svg, "path.E.2").empty());
  for (const auto& [k, phi] : {std::pair{0, 0.3}, {1, 2.0}}) {
    expect_at(circle(svg, m, "E." + std::to_string(k)), sc.on_rod(phase - phi, 0.3, 0.1), tol, "E");
    expect_at(circle(svg, m, "B." + std::to_string(k)), sc.B(phase - phi), tol, "B");
  }
  EXPECT_NE(svg.find("Paths over a revolution: B, E."), std::string::npos);
}

// The line at y = -0.7 m: the rod (0.8 m) cannot reach it while
// 0.2 sin(phi) + 0.7 > 0.8, sin(phi) > 1/2: 90 deg is left out and said;
// the paths break over that arc.
TEST(LinkageDrawing, AnAngleThatCannotAssembleIsLeftOutAndSaid) {
  const auto d = read_description(opt::ConfigNode::parse(
      slider_crank_yaml("{link: crank, pivot: O, joint: A, phase: 0 deg, speed: 60 rpm}", "[0 m, -0.7 m]"), "<drawing>"));
  const std::string svg = mechanism_svg(d, d.chain.defaults(), {0, kPi / 2, kPi, 1.5 * kPi}, "a gap");
  const Map m = read_map(svg);
  const double tol = kPixels / m.sx;
  const SliderCrank sc{0.2, 0.8, -0.7};
  EXPECT_TRUE(tag_of(svg, "angle.1").empty());
  EXPECT_TRUE(tag_of(svg, "A.1").empty());
  EXPECT_TRUE(tag_of(svg, "B.1").empty());
  for (int k : {0, 2, 3}) expect_at(circle(svg, m, "B." + std::to_string(k)), sc.B(k * kPi / 2), tol, "B");
  EXPECT_NE(svg.find("Cannot assemble, not drawn: 90 deg (RRP (rod, ram))."), std::string::npos);
  EXPECT_NE(svg.find("(broken where the mechanism cannot assemble)"), std::string::npos);
  // Two pieces, 0..30 deg and 150..360 deg (the ends, sin = 1/2, may fall either way).
  const auto first = polyline(svg, m, "path.B"), second = polyline(svg, m, "path.B.2");
  EXPECT_GE(first.size(), 30u);
  EXPECT_LE(first.size(), 31u);
  EXPECT_GE(second.size(), 210u);
  EXPECT_LE(second.size(), 211u);
  EXPECT_TRUE(tag_of(svg, "path.B.3").empty());
  for (size_t k = 0; k < first.size(); ++k) expect_at(first[k], sc.B(2 * kPi * k / 360), tol, "first piece");
  for (size_t k = 0; k < second.size(); ++k)
    expect_at(second[k], sc.B(2 * kPi * (360 - second.size() + 1 + k) / 360), tol, "second piece");
}

// A directory of this process's own: runs of this test from several
// build trees at once must not remove each other's files.
std::string own_dir(const std::string& name) { return cli::fresh_dir(name + "_" + std::to_string(getpid())); }

std::string read(const std::string& file) {
  std::ifstream in(file);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Every shipped linkage drawn: well-formed XML (Python's parser) that
// rsvg-convert renders (when installed).
TEST(LinkageDrawing, EveryLinkageIsWellFormedAndRenders) {
  const std::string dir = own_dir("linkage_drawing");
  fs::create_directories(dir);
  const bool rsvg = std::system("command -v rsvg-convert > /dev/null 2>&1") == 0;
  for (const auto& e : fs::directory_iterator(cli::source("configs/linkage"))) {
    const std::string name = e.path().stem().string(), file = dir + "/" + name + ".svg";
    SCOPED_TRACE(name);
    const auto p = opt::make_problem(opt::ConfigNode::load(e.path().string()));
    std::ofstream(file) << p->mechanism_svg(p->initial_point(), "its start");
    const std::string parse = "/usr/bin/python3 -c 'import sys, xml.etree.ElementTree as E; E.parse(sys.argv[1])' " + file;
    EXPECT_EQ(std::system(parse.c_str()), 0) << parse;
    if (!rsvg) continue;
    const std::string render = "rsvg-convert -o " + dir + "/" + name + ".png " + file;
    EXPECT_EQ(std::system(render.c_str()), 0) << render;
    EXPECT_EQ(read(dir + "/" + name + ".png").substr(0, 4), "\x89PNG");
  }
  if (!HasFailure()) fs::remove_all(dir);
}

// A run writes mechanism.svg of its final design beside cycle.svg (the
// crank drawn at the optimum's length); `mechopt kinematics --svg` draws
// the asked angles.
TEST(LinkageDrawing, RunAndKinematicsWriteIt) {
  const std::string dir = own_dir("linkage_drawing_run");
  const auto r = cli::run("run " + cli::source("configs/linkage/slider_crank.yaml") + " --output " + dir);
  ASSERT_TRUE(r.exited(0)) << r.output;
  const auto j = nlohmann::json::parse(read(dir + "/result.json"));
  EXPECT_NE(j["charts"].dump().find("mechanism.svg"), std::string::npos) << j["charts"];
  const std::string svg = read(dir + "/mechanism.svg");
  EXPECT_NE(svg.find("linkage: the mechanism at optimum"), std::string::npos);
  const double crank = j["variables"]["links.crank.length"]["value"];
  const Map m = read_map(svg);
  expect_at(circle(svg, m, "A.0"), {crank, 0}, kPixels / m.sx, "A at the optimum");

  const std::string file = dir + "/kinematics.svg";
  const auto k = cli::run("kinematics " + cli::source("configs/linkage/whitworth_shaper.yaml") +
                          " --angles '0, 37, 90 deg' --svg " + file);
  ASSERT_TRUE(k.exited(0)) << k.output;
  EXPECT_EQ(nlohmann::json::parse(k.output)["angles"].size(), 3u);
  const std::string drawn = read(file);
  for (const char* id : {"angle.0", "angle.1", "angle.2", "C.2", "D.1", "O4.ground", "path.C"})
    EXPECT_FALSE(tag_of(drawn, id).empty()) << id;
  // A file that cannot be written stops it before any JSON.
  const auto bad = cli::run("kinematics " + cli::source("configs/linkage/slider_crank.yaml") + " --svg " + dir +
                            "/no_such_dir/k.svg");
  EXPECT_FALSE(bad.exited(0));
  EXPECT_EQ(bad.output, "mechopt: failed: cannot write " + dir + "/no_such_dir/k.svg\n");
  if (!HasFailure()) fs::remove_all(dir);
}

}  // namespace
