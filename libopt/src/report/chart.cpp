#include "opt/chart.hpp"

#include "opt/display_units.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iterator>
#include <limits>
#include <sstream>

namespace opt {
namespace {

// "Nice" tick step: 1, 2 or 5 times a power of ten, at least raw (raw > 0).
double nice_step(double raw) {
  const double p = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0})
    if (m * p >= raw) return m * p;
  return 10 * p;
}

std::string fmt(double v, int digits = 6) {
  std::ostringstream s;
  s.precision(digits);
  s << v + 0.0;  // no "-0"
  return s.str();
}

// Text for SVG content and single-quoted attributes, at most 100 characters.
std::string escape(const std::string& text) {
  std::string out;
  for (char c : text.substr(0, 100)) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '\'': out += "&apos;"; break;
      default: out += c;
    }
  }
  return out;
}

const char* kColors[] = {"#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd",
                         "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22", "#17becf"};
constexpr size_t kNumColors = std::size(kColors);

// Every stride-th point of a series is drawn: 1 up to kMaxDrawnPoints points.
size_t stride(const Series& s) {
  return (std::min(s.x.size(), s.y.size()) + kMaxDrawnPoints - 1) / kMaxDrawnPoints;
}

// A legend entry cut to `chars` bytes (at a UTF-8 character boundary), "..." marking the cut.
std::string fit(const std::string& text, size_t chars) {
  if (text.size() <= chars) return text;
  size_t n = chars > 3 ? chars - 3 : 0;
  while (n > 0 && (static_cast<unsigned char>(text[n]) & 0xC0) == 0x80) --n;
  return text.substr(0, n) + "...";
}

}  // namespace

Axis make_axis(const std::vector<double>& values, double pad) {
  constexpr double big = std::numeric_limits<double>::max();
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (double v : values)
    if (std::isfinite(v)) lo = std::min(lo, v), hi = std::max(hi, v);
  if (!(lo <= hi)) lo = 0, hi = 1;
  // Centre and half-span from halves: finite for any finite lo, hi.
  const double mid = lo / 2 + hi / 2, mag = std::max(std::abs(lo), std::abs(hi));
  double half = hi / 2 - lo / 2;
  if (!(half > 1e-9 * mag) || half < 1e-300) half = mag > 0 ? std::max(0.05 * mag, 1e-300) : 1.0;
  half *= 1 + std::clamp(pad, 0.0, 1.0);
  Axis a;
  a.lo = std::max(mid - half, -big);
  a.hi = std::min(mid + half, big);
  // About 6 ticks; a coarser step while there would be more than kMaxTicks.
  // Every loop below has a fixed bound.
  const double h = a.hi / 2 - a.lo / 2;
  double step = nice_step(h / 3);
  for (int attempt = 0; attempt < 8 && a.ticks.empty(); ++attempt, step = nice_step(step * 1.5)) {
    if (!std::isfinite(step) || !(step > 0)) break;
    const double first = std::ceil(a.lo / step), last = std::floor(a.hi / step);
    if (!(last - first < kMaxTicks)) continue;
    for (int i = 0; i <= static_cast<int>(last - first); ++i) {
      const double t = (first + i) * step;
      if (t >= a.lo && t <= a.hi) a.ticks.push_back(t);
    }
    if (!a.ticks.empty()) {
      // From the largest tick's leading digit down to the step's digit, and
      // at least its integer digits (%g would switch to an exponent).
      const double top = std::max({std::abs(a.ticks.front()), std::abs(a.ticks.back()), step});
      const double e = std::floor(std::log10(top));
      const double d = std::max(e + 1, e - std::floor(std::log10(step)) + 1);
      a.digits = static_cast<int>(std::clamp(d, 3.0, 15.0));
    }
  }
  if (a.ticks.empty()) a.ticks = {a.lo, a.hi};
  return a;
}

void Chart::set_x(const std::string& name, const std::string& si) {
  x_label = shown_label(name, si);
  x_scale = shown_unit(si).scale;
  if (si == "rad") x_tick_step = 45;  // write_svg's own ticks when 45 deg gives fewer than 3
}

void Chart::set_y(const std::string& name, const std::string& si) {
  y_label = shown_label(name, si);
  y_scale = shown_unit(si).scale;
}

bool write_svg(const Chart& drawn_chart, const std::string& file) {
  Chart chart = drawn_chart;  // its points in the units shown
  for (auto& s : chart.series) {
    for (double& x : s.x) x *= chart.x_scale;
    for (double& y : s.y) y *= chart.y_scale;
  }
  const double W = 780, H = 450, L = 80, T = 40, B = 60;
  // Legend entries, thinned lines saying so; the legend column beside the
  // plot is as wide as its longest entry, at most 30% of the width (longer
  // entries are cut), and lists as many entries as fit its height.
  constexpr double kCharWidth = 7.0;  // of the 12 px sans-serif, on average (DejaVu Sans: 6.9)
  std::vector<std::string> legend;
  size_t longest = 0;
  for (const auto& s : chart.series) {
    const size_t n = std::min(s.x.size(), s.y.size()), every = stride(s);
    legend.push_back(s.label +
                     (every > 1 ? " (every " + std::to_string(every) + "th of " + std::to_string(n) + ")" : ""));
    longest = std::max(longest, legend.back().size());
  }
  const size_t legend_chars = std::min(longest, static_cast<size_t>((0.3 * W - 44) / kCharWidth));
  const double R = std::max(44 + kCharWidth * static_cast<double>(legend_chars), 120.0);
  const size_t legend_rows = static_cast<size_t>((H - T - B) / 18);
  std::vector<double> xs, ys;
  for (const auto& s : chart.series)
    for (size_t i = 0; i < std::min(s.x.size(), s.y.size()); ++i)
      if (std::isfinite(s.x[i]) && std::isfinite(s.y[i])) xs.push_back(s.x[i]), ys.push_back(s.y[i]);
  Axis ax = make_axis(xs);
  const Axis ay = make_axis(ys, 0.05);
  // A fixed tick step when it gives 3 to kMaxTicks ticks on this span.
  if (const double step = chart.x_tick_step;
      step > 0 && std::floor(ax.hi / step) - std::ceil(ax.lo / step) + 1 >= 3 && (ax.hi / step - ax.lo / step) < kMaxTicks) {
    ax.ticks.clear();
    for (double t = std::ceil(ax.lo / step); t * step <= ax.hi; ++t) ax.ticks.push_back(t * step);
  }
  // Fractions along the axis from halves, so that a span near the largest double cannot overflow.
  auto px = [&](double x) { return L + (x / 2 - ax.lo / 2) / (ax.hi / 2 - ax.lo / 2) * (W - L - R); };
  auto py = [&](double y) { return H - B - (y / 2 - ay.lo / 2) / (ay.hi / 2 - ay.lo / 2) * (H - T - B); };

  std::ofstream out(file);
  if (!out) return false;
  out << "<svg xmlns='http://www.w3.org/2000/svg' width='" << W << "' height='" << H
      << "' font-family='sans-serif' font-size='12'>\n<rect width='100%' height='100%' fill='white'/>\n";
  out << "<text x='" << W / 2 << "' y='22' text-anchor='middle' font-size='15'>" << escape(chart.title)
      << "</text>\n";
  out << "<rect x='" << L << "' y='" << T << "' width='" << W - L - R << "' height='"
      << H - T - B << "' fill='none' stroke='black'/>\n";
  for (double t : ax.ticks)
    out << "<line x1='" << px(t) << "' y1='" << H - B << "' x2='" << px(t) << "' y2='" << T
        << "' stroke='#ddd'/><text x='" << px(t) << "' y='" << H - B + 16
        << "' text-anchor='middle'>" << fmt(t, ax.digits) << "</text>\n";
  for (double t : ay.ticks)
    out << "<line x1='" << L << "' y1='" << py(t) << "' x2='" << W - R << "' y2='" << py(t)
        << "' stroke='#ddd'/><text x='" << L - 6 << "' y='" << py(t) + 4
        << "' text-anchor='end'>" << fmt(t, ay.digits) << "</text>\n";
  out << "<text x='" << (L + W - R) / 2 << "' y='" << H - 18 << "' text-anchor='middle'>"
      << escape(chart.x_label) << "</text>\n";
  out << "<text transform='translate(18," << (T + H - B) / 2
      << ") rotate(-90)' text-anchor='middle'>" << escape(chart.y_label) << "</text>\n";
  for (size_t k = 0; k < chart.series.size(); ++k) {
    const Series& s = chart.series[k];
    const char* color = kColors[k % kNumColors];
    const size_t n = std::min(s.x.size(), s.y.size());
    const size_t every = stride(s);
    auto drawn = [&](size_t i) {
      return (i % every == 0 || i + 1 == n) && std::isfinite(s.x[i]) && std::isfinite(s.y[i]);
    };
    if (s.style == Series::Style::line) {
      out << "<polyline fill='none' stroke='" << color << "' stroke-width='2' points='";
      for (size_t i = 0; i < n; ++i)
        if (drawn(i)) out << px(s.x[i]) << "," << py(s.y[i]) << " ";
      out << "'/>\n";
    } else {
      const double r = s.style == Series::Style::star ? 7 : 4;
      for (size_t i = 0; i < n; ++i)
        if (drawn(i))
          out << "<circle cx='" << px(s.x[i]) << "' cy='" << py(s.y[i]) << "' r='" << r
              << "' fill='" << (s.style == Series::Style::star ? color : "none")
              << "' stroke='" << color << "' stroke-width='2'/>\n";
    }
    if (k >= legend_rows) continue;
    const double ly = T + 14 + 18 * static_cast<double>(k);
    const bool last_row = k + 1 == legend_rows && chart.series.size() > legend_rows;
    out << "<rect x='" << W - R + 12 << "' y='" << ly - 8 << "' width='14' height='4' fill='"
        << (last_row ? "none" : color) << "'/><text x='" << W - R + 32 << "' y='" << ly << "'>"
        << escape(last_row ? "+ " + std::to_string(chart.series.size() - k) + " more"
                           : fit(legend[k], legend_chars))
        << "</text>\n";
  }
  out << "</svg>\n";
  return static_cast<bool>(out);
}

}  // namespace opt
