// Minimal SVG line charts: series of (x, y) drawn as lines or markers, with
// axes, ticks and a legend. No dependency beyond the standard library.
#pragma once
#include <string>
#include <vector>

namespace opt {

struct Series {
  std::string label;
  std::vector<double> x, y;
  enum class Style { line, markers, star } style = Style::line;
};

struct Chart {
  std::string title, x_label, y_label;
  std::vector<Series> series;
  double x_tick_step = 0;  // > 0: x ticks at its multiples (e.g. 45 for degrees), unless too many
  double x_scale = 1, y_scale = 1;  // every point's x and y are multiplied by these when drawn
  // The axis of a quantity whose values (in the series) are in SI unit
  // `si`: labelled "name [unit]", an angle shown in degrees (scaled, with
  // ticks every 30 or 45 deg on x), a plain number as [-].
  void set_x(const std::string& name, const std::string& si);
  void set_y(const std::string& name, const std::string& si);
};

// Writes the chart as SVG; returns false if the file cannot be written.
// Points with a non-finite coordinate are skipped; a series with more than
// kMaxDrawnPoints points is thinned to every k-th point (said in its legend),
// so a chart file stays under about 1 MB whatever the data. The legend
// beside the plot takes at most 30% of the width (longer labels are cut) and
// as many rows as fit, the last then "+ k more".
bool write_svg(const Chart& chart, const std::string& file);

constexpr int kMaxTicks = 12;
constexpr size_t kMaxDrawnPoints = 1000;

// One chart axis: the plotted range and its ticks.
struct Axis {
  double lo = 0, hi = 1;      // finite, lo < hi
  std::vector<double> ticks;  // increasing, inside [lo, hi], at most kMaxTicks
  int digits = 6;             // significant digits that tell neighbouring ticks apart
};

// The axis for these values, in bounded work whatever they are: non-finite
// values are skipped; no finite value gives [0, 1]; a flat range (a span
// under 1e-9 of its magnitude: zero, a few ulp) is padded around its value
// (by 5% of it, or 1 for zero); `pad` widens the range by that fraction of
// its half-span on each side; the range never leaves the finite doubles.
Axis make_axis(const std::vector<double>& values, double pad = 0);

}  // namespace opt
