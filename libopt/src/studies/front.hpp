// What the two kinds of Pareto front share (studies/pareto.cpp): the ends
// found by a gradient driver, the normalisation they fix, the printed table,
// the JSON and the chart. The epsilon-constraint front is in pareto.cpp, the
// evolutionary one (pagmo) in pareto_evolution.cpp.
#pragma once
#include <iosfwd>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "opt/driver.hpp"
#include "opt/front.hpp"
#include "opt/run_spec.hpp"

namespace opt::studies {

// f1 and f2 at x, or NaN for both where the design is not ok.
Objectives objectives_at(const Problem& p, const Eigen::VectorXd& x, const std::string& f1, const std::string& f2);

// Each objective minimised alone under the config's constraints, from the
// model design: the front's two ends. Throws when either fails.
struct FrontEnds {
  Result a, b;        // least f1, least f2
  Objectives fa, fb;  // (f1, f2) at each
  Normalisation normalisation() const { return {{fa[0], fb[1]}, {fb[0], fa[1]}}; }
};
FrontEnds front_ends(const Problem& p, const RunSpec& s, const DriverOptions& driver);

// The front's printed table: `lead` columns (metrics by name, each in its
// shown unit), then the variables and the status.
class FrontTable {
 public:
  FrontTable(const Problem& p, std::ostream& out, const std::vector<std::string>& lead,
             const std::vector<std::string>& lead_units);
  void row(const std::vector<double>& lead, const Eigen::VectorXd& x, const std::string& status) const;

 private:
  std::ostream& out_;
  std::vector<std::string> head_;
  std::vector<double> scale_;  // of each column, to its shown unit
};

// result.json's "pareto" for either kind: objectives, both ends, the model
// design, the normalisation and the hypervolume of `front` under it.
nlohmann::json front_json(const Problem& p, const RunSpec& s, const FrontEnds& ends,
                          const std::vector<Objectives>& front);

// pareto.svg: the front (a line, or markers for a population), both ends
// and the model design.
void write_front_chart(const Problem& p, const RunSpec& s, const FrontEnds& ends, const std::vector<Objectives>& front,
                       bool line, const std::string& dir, std::vector<std::string>& files);

}  // namespace opt::studies
