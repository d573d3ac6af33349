#include "opt/chart.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>

namespace opt {
namespace {

// "Nice" tick step: 1, 2 or 5 times a power of ten, about n ticks over span.
double tick_step(double span, int n) {
  const double raw = span / n;
  const double p = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0})
    if (m * p >= raw) return m * p;
  return 10 * p;
}

std::string fmt(double v) {
  std::ostringstream s;
  s.precision(6);
  s << v;
  return s.str();
}

const char* kColors[] = {"#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b"};

}  // namespace

bool write_svg(const Chart& chart, const std::string& file) {
  const double W = 780, H = 450, L = 80, R = 260, T = 40, B = 60;
  double x0 = std::numeric_limits<double>::infinity(), x1 = -x0, y0 = x0, y1 = -x0;
  for (const auto& s : chart.series)
    for (size_t i = 0; i < s.x.size(); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
      x0 = std::min(x0, s.x[i]); x1 = std::max(x1, s.x[i]);
      y0 = std::min(y0, s.y[i]); y1 = std::max(y1, s.y[i]);
    }
  if (!(x1 >= x0)) { x0 = 0; x1 = 1; y0 = 0; y1 = 1; }
  if (x1 == x0) { x0 -= 0.5; x1 += 0.5; }
  if (y1 == y0) { y0 -= 0.5; y1 += 0.5; }
  const double pad = 0.05 * (y1 - y0);
  y0 -= pad; y1 += pad;
  auto px = [&](double x) { return L + (x - x0) / (x1 - x0) * (W - L - R); };
  auto py = [&](double y) { return H - B - (y - y0) / (y1 - y0) * (H - T - B); };

  std::ofstream out(file);
  if (!out) return false;
  out << "<svg xmlns='http://www.w3.org/2000/svg' width='" << W << "' height='" << H
      << "' font-family='sans-serif' font-size='12'>\n<rect width='100%' height='100%' fill='white'/>\n";
  out << "<text x='" << W / 2 << "' y='22' text-anchor='middle' font-size='15'>" << chart.title
      << "</text>\n";
  out << "<rect x='" << L << "' y='" << T << "' width='" << W - L - R << "' height='"
      << H - T - B << "' fill='none' stroke='black'/>\n";
  for (int axis = 0; axis < 2; ++axis) {
    const double lo = axis ? y0 : x0, hi = axis ? y1 : x1, step = tick_step(hi - lo, 6);
    for (double t = std::ceil(lo / step) * step; t <= hi + 1e-9 * step; t += step) {
      if (axis == 0)
        out << "<line x1='" << px(t) << "' y1='" << H - B << "' x2='" << px(t) << "' y2='" << T
            << "' stroke='#ddd'/><text x='" << px(t) << "' y='" << H - B + 16
            << "' text-anchor='middle'>" << fmt(t) << "</text>\n";
      else
        out << "<line x1='" << L << "' y1='" << py(t) << "' x2='" << W - R << "' y2='" << py(t)
            << "' stroke='#ddd'/><text x='" << L - 6 << "' y='" << py(t) + 4
            << "' text-anchor='end'>" << fmt(t) << "</text>\n";
    }
  }
  out << "<text x='" << (L + W - R) / 2 << "' y='" << H - 18 << "' text-anchor='middle'>"
      << chart.x_label << "</text>\n";
  out << "<text transform='translate(18," << (T + H - B) / 2
      << ") rotate(-90)' text-anchor='middle'>" << chart.y_label << "</text>\n";
  for (size_t k = 0; k < chart.series.size(); ++k) {
    const Series& s = chart.series[k];
    const char* color = kColors[k % 6];
    if (s.style == Series::Style::line) {
      out << "<polyline fill='none' stroke='" << color << "' stroke-width='2' points='";
      for (size_t i = 0; i < s.x.size(); ++i)
        if (std::isfinite(s.y[i])) out << px(s.x[i]) << "," << py(s.y[i]) << " ";
      out << "'/>\n";
    } else {
      const double r = s.style == Series::Style::star ? 7 : 4;
      for (size_t i = 0; i < s.x.size(); ++i)
        if (std::isfinite(s.y[i]))
          out << "<circle cx='" << px(s.x[i]) << "' cy='" << py(s.y[i]) << "' r='" << r
              << "' fill='" << (s.style == Series::Style::star ? color : "none")
              << "' stroke='" << color << "' stroke-width='2'/>\n";
    }
    const double ly = T + 14 + 20 * k;
    out << "<rect x='" << W - R + 12 << "' y='" << ly - 8 << "' width='14' height='4' fill='"
        << color << "'/><text x='" << W - R + 32 << "' y='" << ly << "'>" << s.label
        << "</text>\n";
  }
  out << "</svg>\n";
  return static_cast<bool>(out);
}

}  // namespace opt
