// The mechanism drawn as SVG (problems/linkage/drawing.hpp): the chain
// solved on doubles at the drawn crank angles and along a revolution for
// the paths, every shape placed in metres, then mapped to pixels by one
// scale for x and y (x to the right, y up) chosen so the whole scene fits.
// Symbols (joints, sliders, ground) keep their size in pixels.
#include "problems/linkage/drawing.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <limits>
#include <numbers>
#include <ostream>
#include <sstream>
#include <stdexcept>

#include "mech/linkage/kinematics.hpp"
#include "opt/chart.hpp"

namespace problems::linkage {
namespace {

using mech::linkage::Chain;
using mech::linkage::GroupType;
using mech::linkage::kNone;
using mech::linkage::Link;
constexpr double kTwoPi = 2 * std::numbers::pi;

struct Pt {
  double x, y;
};

// The chain at one crank angle: every point and each link's unit axis, or
// the group that could not assemble.
struct Pose {
  double phi;
  std::string failed;  // "" when it assembled
  std::vector<Pt> point, axis;
};

Pose pose_at(const Chain& c, const double* v, double phi, mech::linkage::State<double>& st) {
  Pose p{phi, "", {}, {}};
  if (!mech::linkage::solve(c, v, phi, st)) {
    p.failed = c.group_name(st.failed);
    return p;
  }
  for (const auto& q : st.point) p.point.push_back({q.x.v, q.y.v});
  for (const auto& e : st.axis) p.axis.push_back({e.x.v, e.y.v});
  return p;
}

// A ground line a slider runs on: the pin's path T + s u over [lo, hi].
struct GroundLine {
  int link;
  Pt t, u;
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
};

// Where a link's shape has its corners: its origin, the end of its length
// along its axis, its local points.
std::vector<Pt> link_vertices(const Link& l, const double* v, const Pose& p, size_t k) {
  const Pt o = p.point[static_cast<size_t>(l.origin)], e = p.axis[k];
  std::vector<Pt> out = {o};
  if (l.length != kNone) out.push_back({o.x + v[l.length] * e.x, o.y + v[l.length] * e.y});
  for (const auto& lp : l.points) out.push_back(p.point[static_cast<size_t>(lp.point)]);
  return out;
}

std::string num(double x) {
  char b[32];
  std::snprintf(b, sizeof b, "%.3f", x);
  return b;
}

std::string deg(double phi) {
  std::ostringstream s;
  s.precision(6);
  s << phi * 180 / std::numbers::pi + 0.0;
  return s.str();
}

std::string escape(const std::string& text) {
  std::string out;
  for (char ch : text) out += ch == '&' ? "&amp;" : ch == '<' ? "&lt;" : ch == '>' ? "&gt;" : ch == '\'' ? "&apos;" : std::string(1, ch);
  return out;
}

// Lines of at most `width` characters, broken at spaces.
std::vector<std::string> wrap(const std::string& text, size_t width) {
  std::vector<std::string> lines(1);
  std::istringstream words(text);
  for (std::string w; words >> w;) {
    if (!lines.back().empty() && lines.back().size() + 1 + w.size() > width) lines.emplace_back();
    lines.back() += (lines.back().empty() ? "" : " ") + w;
  }
  return lines;
}

const char* kPathColors[] = {"#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#17becf"};
constexpr const char* kLink = "#1f77b4";

// Metres to pixels: x to the right, y up, one scale for both.
struct Canvas {
  double x0 = 0, y1 = 0, s = 1, left = 70, top = 44, width = 690, height = 400;
  double X(double x) const { return left + (x - x0) * s; }
  double Y(double y) const { return top + (y1 - y) * s; }
  std::string at(Pt p) const { return num(X(p.x)) + "," + num(Y(p.y)); }

  // The scene [lo, hi] with a margin, as wide as the plot and between 260
  // and 600 px high.
  void fit(Pt lo, Pt hi) {
    const double span = std::max({hi.x - lo.x, hi.y - lo.y, 1e-6}), pad = 0.08 * span;
    double w = hi.x - lo.x + 2 * pad, h = hi.y - lo.y + 2 * pad;
    s = width / w;
    height = std::clamp(s * h, 260.0, 600.0);
    if (s * h > height) s = height / h, w = width / s;
    h = height / s;
    x0 = (lo.x + hi.x) / 2 - w / 2;
    y1 = (lo.y + hi.y) / 2 + h / 2;
  }
};

// A rectangle of half sizes a (along u) and b, centred at c (pixels).
std::string box(const Canvas& cv, Pt c, Pt u, double a, double b, const std::string& style) {
  const double cx = cv.X(c.x), cy = cv.Y(c.y), ux = u.x, uy = -u.y;  // u on the screen
  std::string pts;
  for (const auto& [i, j] : {std::pair{1, 1}, {-1, 1}, {-1, -1}, {1, -1}})
    pts += num(cx + i * a * ux - j * b * uy) + "," + num(cy + i * a * uy + j * b * ux) + " ";
  return "<polygon points='" + pts + "' " + style + "/>\n";
}

class Drawing {
 public:
  Drawing(const Description& d, const std::vector<double>& v, const std::vector<double>& angles, int path_points)
      : c_(d.chain), v_(v.data()), ground_(c_.point_names().size(), false), joint_(ground_) {
    for (const auto& [p, xy] : c_.ground_points()) ground_[static_cast<size_t>(p)] = true;
    joint_[static_cast<size_t>(c_.crank().pivot)] = joint_[static_cast<size_t>(c_.crank().joint)] = true;
    std::vector<int> end(c_.links().size(), kNone);  // the joint at the end of a link's length
    end[static_cast<size_t>(c_.crank().link)] = c_.crank().joint;
    for (const auto& g : c_.groups()) {
      for (int p : {g.p, g.q, g.joint})
        if (p != kNone) joint_[static_cast<size_t>(p)] = true;
      if (g.type != GroupType::RPR) end[static_cast<size_t>(g.first)] = g.joint;
      if (g.type == GroupType::RRR) end[static_cast<size_t>(g.second)] = g.joint;
    }
    for (const auto& o : d.outputs) trace(c_.links()[static_cast<size_t>(o.link)].origin), trace(end[static_cast<size_t>(o.link)]);
    for (const auto& l : c_.links())
      for (const auto& lp : l.points) trace(lp.point);
    for (size_t k = 0; k < c_.links().size(); ++k) {
      const Link& l = c_.links()[k];
      if (l.line_through == kNone || l.line_on != kNone) continue;
      const double a = v_[l.line_angle], off = l.line_offset == kNone ? 0.0 : v_[l.line_offset];
      const Pt xy = ground_xy(l.line_through);
      lines_.push_back({static_cast<int>(k), {xy.x - off * std::sin(a), xy.y + off * std::cos(a)}, {std::cos(a), std::sin(a)}});
    }
    mech::linkage::State<double> st;
    st.resize(c_);
    for (double phi : angles) poses_.push_back(pose_at(c_, v_, phi, st));
    paths_.assign(traced_.size(), std::vector<std::vector<Pt>>(1));
    for (int k = 0; k <= path_points; ++k) {
      const bool ok = mech::linkage::solve(c_, v_, kTwoPi * k / path_points, st);
      for (size_t i = 0; i < traced_.size(); ++i) {
        auto& segments = paths_[i];
        if (ok) segments.back().push_back({st.point[static_cast<size_t>(traced_[i])].x.v, st.point[static_cast<size_t>(traced_[i])].y.v});
        else if (!segments.back().empty()) segments.emplace_back();
      }
      gaps_ = gaps_ || !ok;
      for (auto& gl : lines_)
        if (ok) gl.lo = std::min(gl.lo, st.slide[static_cast<size_t>(gl.link)].v), gl.hi = std::max(gl.hi, st.slide[static_cast<size_t>(gl.link)].v);
    }
    for (auto& segments : paths_)
      if (segments.back().empty()) segments.pop_back();
    for (size_t i = 0; i < poses_.size() && full_ < 0; ++i)
      if (poses_[i].failed.empty()) full_ = static_cast<int>(i);
  }

  std::string svg(const std::string& title) {
    const std::vector<std::string> caption = captions();
    fit();
    const double W = cv_.left + cv_.width + 20, H = cv_.top + cv_.height + 52 + 16.0 * static_cast<double>(caption.size());
    out_ << "<svg xmlns='http://www.w3.org/2000/svg' version='1.1' width='" << W << "' height='" << H
         << "' font-family='sans-serif' font-size='12'>\n<rect width='100%' height='100%' fill='white'/>\n"
         << "<text x='" << W / 2 << "' y='24' text-anchor='middle' font-size='15'>" << escape(title) << "</text>\n";
    axes();
    for (const auto& gl : lines_) ground_line(gl);
    for (size_t i = 0; i < paths_.size(); ++i) path(i);
    for (size_t i = 0; i < poses_.size(); ++i)
      if (static_cast<int>(i) != full_ && poses_[i].failed.empty()) pose(i);
    if (full_ >= 0) pose(static_cast<size_t>(full_));
    ground();
    for (size_t i = 0; i < caption.size(); ++i)
      out_ << "<text x='" << cv_.left << "' y='" << cv_.top + cv_.height + 62 + 16.0 * static_cast<double>(i) << "'>"
           << escape(caption[i]) << "</text>\n";
    out_ << "</svg>\n";
    return out_.str();
  }

 private:
  Pt ground_xy(int p) const {
    for (const auto& [q, xy] : c_.ground_points())
      if (q == p) return {v_[xy.first], v_[xy.second]};
    return {0, 0};
  }
  void trace(int p) {
    if (p != kNone && !ground_[static_cast<size_t>(p)] && std::find(traced_.begin(), traced_.end(), p) == traced_.end())
      traced_.push_back(p);
  }

  // The scale that shows every ground point, drawn pose, path and ground line.
  void fit() {
    Pt lo{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()}, hi{-lo.x, -lo.y};
    auto grow = [&](Pt p) {
      if (!std::isfinite(p.x) || !std::isfinite(p.y)) return;
      lo = {std::min(lo.x, p.x), std::min(lo.y, p.y)}, hi = {std::max(hi.x, p.x), std::max(hi.y, p.y)};
    };
    for (const auto& [p, xy] : c_.ground_points()) grow(ground_xy(p));
    for (const auto& pose : poses_)
      for (size_t k = 0; k < pose.axis.size(); ++k)
        for (Pt q : link_vertices(c_.links()[k], v_, pose, k)) grow(q);
    for (const auto& segments : paths_)
      for (const auto& seg : segments)
        for (Pt q : seg) grow(q);
    for (const auto& gl : lines_)
      for (double s : {gl.lo, gl.hi}) grow({gl.t.x + s * gl.u.x, gl.t.y + s * gl.u.y});
    if (!(lo.x <= hi.x)) lo = {-1, -1}, hi = {1, 1};
    cv_.fit(lo, hi);
  }

  // The frame, a light grid at the ticks in metres, "x [m]" and "y [m]".
  void axes() {
    const double r = cv_.left + cv_.width, b = cv_.top + cv_.height;
    out_ << "<rect x='" << cv_.left << "' y='" << cv_.top << "' width='" << cv_.width << "' height='" << cv_.height
         << "' fill='none' stroke='black'/>\n";
    const opt::Axis ax = opt::make_axis({cv_.x0, cv_.x0 + cv_.width / cv_.s});
    const opt::Axis ay = opt::make_axis({cv_.y1 - cv_.height / cv_.s, cv_.y1});
    auto tick_text = [](double t, int digits) {
      std::ostringstream s;
      s.precision(digits);
      s << t + 0.0;
      return s.str();
    };
    for (double t : ax.ticks)
      out_ << "<line x1='" << num(cv_.X(t)) << "' y1='" << cv_.top << "' x2='" << num(cv_.X(t)) << "' y2='" << b
           << "' stroke='#eee'/><text class='xtick' x='" << num(cv_.X(t)) << "' y='" << b + 16
           << "' text-anchor='middle'>" << tick_text(t, ax.digits) << "</text>\n";
    for (double t : ay.ticks)
      out_ << "<line x1='" << cv_.left << "' y1='" << num(cv_.Y(t)) << "' x2='" << r << "' y2='" << num(cv_.Y(t))
           << "' stroke='#eee'/><text class='ytick' x='" << cv_.left - 6 << "' y='" << num(cv_.Y(t))
           << "' text-anchor='end' dominant-baseline='middle'>" << tick_text(t, ay.digits) << "</text>\n";
    out_ << "<text x='" << cv_.left + cv_.width / 2 << "' y='" << b + 36 << "' text-anchor='middle'>x [m]</text>\n"
         << "<text transform='translate(18," << cv_.top + cv_.height / 2
         << ") rotate(-90)' text-anchor='middle'>y [m]</text>\n";
  }

  // A slider's ground line: its centre line (dash-dot) over the pin's travel
  // and a hatched surface under the slider.
  void ground_line(const GroundLine& gl) {
    if (!(gl.lo <= gl.hi)) return;
    const double m = 24 / cv_.s;
    const Pt a{gl.t.x + (gl.lo - m) * gl.u.x, gl.t.y + (gl.lo - m) * gl.u.y};
    const Pt b{gl.t.x + (gl.hi + m) * gl.u.x, gl.t.y + (gl.hi + m) * gl.u.y};
    out_ << "<line x1='" << num(cv_.X(a.x)) << "' y1='" << num(cv_.Y(a.y)) << "' x2='" << num(cv_.X(b.x)) << "' y2='"
         << num(cv_.Y(b.y)) << "' stroke='#888' stroke-dasharray='8,3,2,3'/>\n";
    const double dx = gl.u.y * 9, dy = gl.u.x * 9;  // 9 px to the right of u on the screen
    const double len = std::hypot(cv_.X(b.x) - cv_.X(a.x), cv_.Y(b.y) - cv_.Y(a.y));
    out_ << "<path stroke='black' fill='none' d='M" << num(cv_.X(a.x) + dx) << "," << num(cv_.Y(a.y) + dy) << " L"
         << num(cv_.X(b.x) + dx) << "," << num(cv_.Y(b.y) + dy);
    for (double at = 4; at < len; at += 10) {
      const double hx = cv_.X(a.x) + dx + at * gl.u.x, hy = cv_.Y(a.y) + dy - at * gl.u.y;
      out_ << " M" << num(hx) << "," << num(hy) << " l" << num(gl.u.y * 6 - gl.u.x * 6) << "," << num(gl.u.x * 6 + gl.u.y * 6);
    }
    out_ << "'/>\n";
  }

  void path(size_t i) {
    const std::string& name = c_.point_names()[static_cast<size_t>(traced_[i])];
    for (size_t s = 0; s < paths_[i].size(); ++s) {
      out_ << "<polyline id='path." << name;
      if (s > 0) out_ << "." << s + 1;
      out_ << "' fill='none' stroke='" << color(i) << "' stroke-width='1.2' points='";
      for (Pt q : paths_[i][s]) out_ << cv_.at(q) << " ";
      out_ << "'><title>path of " << name << "</title></polyline>\n";
    }
  }
  const char* color(size_t traced) const { return kPathColors[traced % std::size(kPathColors)]; }

  // One drawn angle: links, sliders and blocks, joints; names in full only.
  void pose(size_t i) {
    const Pose& p = poses_[i];
    const bool full = static_cast<int>(i) == full_;
    out_ << "<g id='angle." << i << "'" << (full ? "" : " opacity='0.3'") << "><title>crank angle " << deg(p.phi)
         << " deg</title>\n";
    for (size_t k = 0; k < c_.links().size(); ++k) {
      const Link& l = c_.links()[k];
      std::vector<Pt> vs = link_vertices(l, v_, p, k);
      if (l.length == kNone) {  // a slider or a block: its rectangle, a line to each of its points
        for (size_t j = 1; j < vs.size(); ++j)
          out_ << "<line x1='" << num(cv_.X(vs[0].x)) << "' y1='" << num(cv_.Y(vs[0].y)) << "' x2='" << num(cv_.X(vs[j].x))
               << "' y2='" << num(cv_.Y(vs[j].y)) << "' stroke='" << kLink << "' stroke-width='3'/>\n";
        if (l.line_on != kNone) guide(l, p, vs[0], p.axis[k]);
        const bool slider = l.line_through != kNone;
        out_ << box(cv_, vs[0], p.axis[k], slider ? 15 : 12, slider ? 8 : 6,
                    "fill='#cfe0f0' stroke='" + std::string(kLink) + "' stroke-width='1.5'");
        continue;
      }
      if (vs.size() > 2) {  // a plate: its points in turn about their centre
        Pt m{0, 0};
        for (Pt q : vs) m = {m.x + q.x / static_cast<double>(vs.size()), m.y + q.y / static_cast<double>(vs.size())};
        std::sort(vs.begin(), vs.end(), [&](Pt a, Pt b) { return std::atan2(a.y - m.y, a.x - m.x) < std::atan2(b.y - m.y, b.x - m.x); });
      }
      out_ << "<polygon points='";
      for (Pt q : vs) out_ << cv_.at(q) << " ";
      out_ << "' fill='" << kLink << "' fill-opacity='0.15' stroke='" << kLink
           << "' stroke-width='3' stroke-linejoin='round'><title>" << l.name << "</title></polygon>\n";
    }
    for (size_t q = 0; q < p.point.size(); ++q) {
      if (ground_[q]) continue;
      const std::string& name = c_.point_names()[q];
      out_ << "<circle id='" << name << "." << i << "' cx='" << num(cv_.X(p.point[q].x)) << "' cy='"
           << num(cv_.Y(p.point[q].y)) << "' " << (joint_[q] ? "r='4' fill='white' stroke='black' stroke-width='1.5'" : "r='2.5' fill='black'")
           << "/>\n";
      const auto t = std::find(traced_.begin(), traced_.end(), static_cast<int>(q));
      if (full) label(p.point[q], name, t == traced_.end() ? "black" : color(static_cast<size_t>(t - traced_.begin())));
    }
    out_ << "</g>\n";
  }

  // A slider's line on a moving link, drawn as a part of that link: from
  // the line's point T to its origin T + offset n, then along the line over
  // the origin and the pin b, 24 px past each.
  void guide(const Link& l, const Pose& p, Pt b, Pt u) {
    const Pt t = p.point[static_cast<size_t>(l.line_through)];
    const double off = l.line_offset == kNone ? 0.0 : v_[l.line_offset];
    const Pt o{t.x - off * u.y, t.y + off * u.x};
    const double s = (b.x - o.x) * u.x + (b.y - o.y) * u.y, pad = 24 / cv_.s;
    const double lo = std::min(0.0, s) - pad, hi = std::max(0.0, s) + pad;
    out_ << "<polyline fill='none' stroke='#888' stroke-width='2' points='" << cv_.at(t) << " " << cv_.at(o) << " "
         << cv_.at({o.x + lo * u.x, o.y + lo * u.y}) << " " << cv_.at({o.x + hi * u.x, o.y + hi * u.y}) << "'/>\n";
  }

  void label(Pt at, const std::string& name, const char* fill) {
    out_ << "<text x='" << num(cv_.X(at.x) + 7) << "' y='" << num(cv_.Y(at.y) - 7) << "' fill='" << fill << "'>" << name
         << "</text>\n";
  }

  // The ground points: dots, then pivots (the joints) on hatched triangles,
  // then their names, one label for points that coincide.
  void ground() {
    for (const bool pivots : {false, true})
      for (const auto& [p, xy] : c_.ground_points()) {
        if (joint_[static_cast<size_t>(p)] != pivots) continue;
        const double x = cv_.X(v_[xy.first]), y = cv_.Y(v_[xy.second]);
        const std::string id = c_.point_names()[static_cast<size_t>(p)] + ".ground";
        if (!pivots) {
          out_ << "<circle id='" << id << "' cx='" << num(x) << "' cy='" << num(y) << "' r='2.5' fill='#555'/>\n";
          continue;
        }
        out_ << "<path fill='#ddd' stroke='black' d='M" << num(x) << "," << num(y) << " L" << num(x - 9) << ","
             << num(y + 14) << " L" << num(x + 9) << "," << num(y + 14) << " Z M" << num(x - 13) << "," << num(y + 14)
             << " L" << num(x + 13) << "," << num(y + 14);
        for (int k = 0; k < 5; ++k) out_ << " M" << num(x - 11 + 6 * k) << "," << num(y + 14) << " l-5,6";
        out_ << "'/>\n<circle id='" << id << "' cx='" << num(x) << "' cy='" << num(y)
             << "' r='4' fill='white' stroke='black' stroke-width='1.5'/>\n";
      }
    std::vector<std::pair<Pt, std::string>> names;
    for (const auto& [p, xy] : c_.ground_points()) {
      const Pt g{v_[xy.first], v_[xy.second]};
      const std::string& name = c_.point_names()[static_cast<size_t>(p)];
      const auto same = std::find_if(names.begin(), names.end(), [&](const auto& n) { return n.first.x == g.x && n.first.y == g.y; });
      if (same == names.end()) names.emplace_back(g, name);
      else same->second += ", " + name;
    }
    for (const auto& [g, name] : names) label(g, name, "black");
  }

  std::vector<std::string> captions() const {
    std::string drawn, failed;
    for (size_t i = 0; i < poses_.size(); ++i) {
      const Pose& p = poses_[i];
      if (!p.failed.empty()) failed += std::string(failed.empty() ? "" : ", ") + deg(p.phi) + " deg (" + p.failed + ")";
      else drawn += (drawn.empty() ? "" : ", ") + deg(p.phi) + (static_cast<int>(i) == full_ ? " (in full)" : "");
    }
    std::string text = drawn.empty() ? "No drawn crank angle assembles." : "Crank angles drawn [deg]: " + drawn + ".";
    if (!failed.empty()) text += " Cannot assemble, not drawn: " + failed + ".";
    if (!traced_.empty()) {
      text += " Paths over a revolution:";
      for (size_t i = 0; i < traced_.size(); ++i) text += (i ? ", " : " ") + c_.point_names()[static_cast<size_t>(traced_[i])];
      text += gaps_ ? " (broken where the mechanism cannot assemble)." : ".";
    }
    return wrap(text, 105);
  }

  const Chain& c_;
  const double* v_;
  std::vector<bool> ground_, joint_;  // per point
  std::vector<int> traced_;           // the points whose paths are drawn
  std::vector<GroundLine> lines_;
  std::vector<Pose> poses_;
  std::vector<std::vector<std::vector<Pt>>> paths_;  // per traced point, its pieces
  bool gaps_ = false;
  int full_ = -1;  // the pose drawn in full
  Canvas cv_;
  std::ostringstream out_;
};

}  // namespace

std::vector<double> drawn_angles() {
  std::vector<double> out;
  for (int k = 0; k < 6; ++k) out.push_back(kTwoPi * k / 6);
  return out;
}

std::string mechanism_svg(const Description& d, const std::vector<double>& v, const std::vector<double>& angles,
                          const std::string& title, int path_points) {
  return Drawing(d, v, angles, std::max(path_points, 1)).svg(title);
}

void kinematics_command(const opt::ConfigNode& root, const std::vector<double>& angles, const std::string& svg,
                        std::ostream& out) {
  if (root.at("problem").text() != "linkage") root.at("problem").fail("kinematics takes a `problem: linkage` config");
  std::ofstream file;  // opened first: a file that cannot be written stops before any output
  if (!svg.empty()) {
    file.open(svg);
    if (!file) throw std::runtime_error("cannot write " + svg);
  }
  out << kinematics_report(root, angles).dump(2) << "\n";
  if (svg.empty()) return;
  const Description d = read_description(root);
  file << mechanism_svg(d, d.chain.defaults(), angles, "linkage: the mechanism at its model values");
  if (!file.flush()) throw std::runtime_error("cannot write " + svg);
}

}  // namespace problems::linkage
