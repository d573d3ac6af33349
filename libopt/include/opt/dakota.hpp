// Dakota's analysis-driver files, for `mechopt dakota PARAMS RESULTS
// --config C` (docs/interfaces.md): Dakota writes a parameters file, the
// driver evaluates the config's problem there and writes a results file.
#pragma once
#include <string>
#include <vector>

#include "opt/problem.hpp"
#include "opt/run_spec.hpp"

namespace opt {

// A parameters file as Dakota writes it (its standard format, or APREPRO's
// `{ label = value }`), each entry with its line for messages.
struct DakotaParams {
  struct Entry {
    std::string label;
    std::string value;  // as written
    int line = 0;
  };
  std::string file;
  std::vector<Entry> variables;             // value: the variable's, label: its descriptor
  std::vector<Entry> functions;             // value: the ASV (1 value, 2 gradient, 4 Hessian), label: the response's
  std::vector<Entry> derivative_variables;  // value: a 1-based position in `variables`
  std::vector<Entry> analysis_components;
  std::string eval_id;
};

// Reads a parameters file; an unreadable or malformed one is a ConfigError
// naming the file and line and what was expected.
DakotaParams read_dakota_params(const std::string& file);

// The metrics Dakota's default labels stand for: the config's objective,
// inequality and equality constraints in that order (Dakota's own order of
// responses).
std::vector<std::string> dakota_responses(const RunSpec& spec);

// The results file for `params` on `problem`: the variables by label (a
// variable the file leaves out stays at its initial value); each function
// is the metric its label names, or else the i-th of `responses`
// (dakota_responses). The values first, one `value
// label` line for each function whose ASV has bit 1, then one bracketed
// gradient over the derivative variables for each with bit 2, exact (the
// problem's autodiff). "FAIL" alone when the design's status is not ok.
// A Hessian asked for (bit 4), an unknown label or a function that names
// no metric is a ConfigError naming the file and line.
std::string dakota_results(const Problem& problem, const std::vector<std::string>& responses,
                           const DakotaParams& params);

}  // namespace opt
