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
};

// Writes the chart as SVG; returns false if the file cannot be written.
bool write_svg(const Chart& chart, const std::string& file);

}  // namespace opt
