// Shared by the studies: the printed tables, variables as JSON, and the
// charts along a variable and over the crank cycle.
#pragma once
#include <Eigen/Core>
#include <iosfwd>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "opt/problem.hpp"
#include "opt/run_spec.hpp"

namespace opt::report {

// The length of the longest name, at least `at_least`: a column of names as wide as it needs.
size_t longest(const std::vector<std::string>& names, size_t at_least = 0);
// Right-aligned cells, each as wide as its column's header (at least 12).
void print_row(std::ostream& out, const std::vector<std::string>& cells,
               const std::vector<std::string>& head);
void print_variables(std::ostream& out, const Problem& p, const Eigen::VectorXd& x);
void print_metrics(std::ostream& out, const Problem& p, const nlohmann::json& m);
nlohmann::json variables_json(const Problem& p, const Eigen::VectorXd& x);

// One chart per metric along the single variable: the continuous curve, the
// grid points, the paper's values, the constraint bound and the optimum.
// Returns the files written.
std::vector<std::string> write_charts(const Problem& p, const RunSpec& s,
                                      const std::vector<Eigen::VectorXd>& grid_x,
                                      const std::vector<Evaluation>& grid_e,
                                      const nlohmann::json* optimum, const std::string& dir);
// cycle.svg: the problem's primary cycle curve at each design in `xs`
// (labelled) and, at the last design, every other curve in its unit, over the
// crank angle in degrees (or time), the y axis in that unit; plus cycle.csv
// with every column at the last design in SI, each headed "name [unit]";
// and mechanism.svg, the problem's drawing of the last design, if it draws one.
std::vector<std::string> write_cycle_chart(const Problem& p,
                                           const std::vector<std::pair<std::string, Eigen::VectorXd>>& xs,
                                           const std::string& dir);

}  // namespace opt::report
