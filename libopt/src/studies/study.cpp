#include <filesystem>
#include <iostream>

#include "core/text.hpp"
#include "opt/doe/batch.hpp"
#include "opt/interrupt.hpp"
#include "opt/record.hpp"
#include "opt/registry.hpp"
#include "opt/study.hpp"
#include "report/report.hpp"
#include "studies/studies.hpp"

namespace opt {

nlohmann::json metrics_json(const Problem& p, const Eigen::VectorXd& x) {
  const Evaluation e = p.evaluate(x, MetricSet::all(), false);
  nlohmann::json m = nlohmann::json::object();
  for (MetricId i = 0; i < static_cast<MetricId>(p.metric_names().size()); ++i)
    if (e.has(i)) m[p.metric_names()[static_cast<size_t>(i)]] = e[i].value;
  nlohmann::json j = {{"status", mech::to_string(e.status)}, {"metrics", m}};
  if (!e.message.empty()) j["message"] = e.message;
  return j;
}

bool is_doe(const ConfigNode& root) {
  return root.has("study") && root.at("study").has("type") && root.at("study").at("type").text() == "doe";
}

nlohmann::json run_config(const ConfigNode& root, const Problem& problem, doe::BatchOptions& options,
                          std::ostream& out, std::ostream& err) {
  const bool doe = is_doe(root);
  RunSpec spec = parse_run(root, problem, options.force || doe);
  if (options.output_directory.empty()) options.output_directory = spec.output_directory;
  if (doe)
    return doe::run_batch(root, make_problem,
                          doe::parse_doe(root, model_parameters(root), problem, options.force || options.dry_run),
                          options, out, err);
  spec.output_directory = options.output_directory;
  spec.threads = options.threads;
  spec.force = options.force;
  return run_study(problem, spec, out);
}

nlohmann::json run_study(const Problem& p, const RunSpec& s, std::ostream& out) {
  namespace fs = std::filesystem;
  fs::create_directories(s.output_directory);
  const std::string dir = s.output_directory + "/";
  remove_previous_outputs(dir);
  nlohmann::json j = {{"mechopt_version", MECHOPT_VERSION},
                      {"problem", p.name()},
                      {"study", s.type},
                      {"settings", p.record()}};
  out << "mechopt " << MECHOPT_VERSION << " — " << p.name() << ", " << s.type << "\n";
  std::vector<std::string> files;
  auto finish = [&]() {
    // Stopped by SIGINT/SIGTERM: what was done is written, and says so.
    j["run_status"] = stop_requested() ? "interrupted" : "complete";
    j["charts"] = files;
    write_file_atomically(dir + "result.json", j.dump(2) + "\n");
    out << "written: " << dir << "result.json" << (j.contains("sweep") ? ", sweep.csv" : "")
        << (j.contains("history") ? ", history.csv" : "") << (j.contains("pareto") ? ", pareto.csv" : "");
    for (const auto& f : files) out << ", " << f.substr(dir.size());
    out << "\n";
    return j;
  };

  if (s.type == "evaluate") {
    const Eigen::VectorXd x = p.initial_point(false);
    const nlohmann::json e = metrics_json(p, x);
    j["design_status"] = e["status"];
    j["metrics"] = e["metrics"];
    if (e.contains("message")) j["message"] = e["message"];
    out << "every metric at the model values: " << e["status"].get<std::string>()
        << (e.contains("message") ? " — " + e["message"].get<std::string>() : "") << "\n";
    report::print_metrics(out, p, j["metrics"]);
    if (s.chart && !stop_requested())
      for (const auto& f : report::write_cycle_chart(p, {{"model values", x}}, dir)) files.push_back(f);
    return finish();
  }
  if (s.type == "pareto") {
    j["pareto"] = studies::pareto(p, s, out, dir, files);
    return finish();
  }
  studies::SweepOutcome grid;
  if (s.type == "sweep") {
    grid = studies::sweep(p, s, out, dir);
    j["sweep"] = grid.json;
  }
  studies::OptimizeOutcome o;
  const bool optimized = (s.type == "optimize" || s.optimize) && !stop_requested();
  if (optimized) {
    o = studies::optimize(p, s, out, dir);
    j.update(o.json);
  }
  if (!s.chart || stop_requested()) return finish();
  if (p.variables().size() == 1 && !s.columns.empty())
    for (const auto& f : report::write_charts(p, s, grid.x, grid.e, optimized ? &o.json : nullptr, dir))
      files.push_back(f);
  // Cycle curves at the grid designs (up to 8) and at the optimum.
  std::vector<std::pair<std::string, Eigen::VectorXd>> designs;
  if (grid.x.size() <= 8)
    for (const auto& x : grid.x) {
      std::string label;
      for (int d = 0; d < x.size(); ++d)
        label += (d ? ", " : "") + p.variables()[d].name + " = " + text::fmt(x[d], 4);
      designs.emplace_back(label, x);
    }
  if (optimized && o.result.success()) designs.emplace_back("optimum", o.result.x);
  if (designs.empty()) designs.emplace_back("model values", p.initial_point());
  for (const auto& f : report::write_cycle_chart(p, designs, dir)) files.push_back(f);
  return finish();
}

}  // namespace opt
