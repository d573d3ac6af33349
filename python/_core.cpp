// mechopt._core: the problems of libopt's registry as Python objects
// (pybind11). python/mechopt/__init__.py is the module users import; it
// wraps these in the documented surface (docs/python.md).
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <csignal>
#include <iostream>
#include <limits>
#include <memory>
#include <mutex>
#include <sstream>
#include <string>
#include <vector>

#include "opt/doe/batch.hpp"
#include "opt/evaluate_rows.hpp"
#include "opt/interrupt.hpp"
#include "opt/parameters.hpp"
#include "opt/registry.hpp"
#include "opt/study.hpp"

namespace py = pybind11;

namespace {

py::list parameter_list(const std::vector<opt::Parameter>& table) {
  py::list out;
  for (const auto& p : table) {
    py::dict d;
    d["name"] = p.name;
    d["unit"] = opt::si_unit(p.dimension);
    d["domain"] = opt::to_string(p.domain, p.dimension);
    d["default"] = p.value;
    d["doc"] = p.doc;
    d["equation"] = p.equation;
    d["choices"] = p.choices;
    d["variable"] = p.variable;
    out.append(d);
  }
  return out;
}

// SIGINT and SIGTERM go to opt::request_stop for the life of this object,
// then back to whoever had them (Python's handler).
class StopHandlers {
 public:
  StopHandlers() {
    sigaction(SIGINT, nullptr, &int_);
    sigaction(SIGTERM, nullptr, &term_);
    opt::clear_stop();
    opt::install_stop_handlers();
  }
  ~StopHandlers() {
    sigaction(SIGINT, &int_, nullptr);
    sigaction(SIGTERM, &term_, nullptr);
  }
  StopHandlers(const StopHandlers&) = delete;
  StopHandlers& operator=(const StopHandlers&) = delete;

 private:
  struct sigaction int_ {}, term_{};
};

// KeyboardInterrupt where a stop was requested (cleared for the next call).
void raise_if_stopped() {
  if (!opt::stop_requested()) return;
  opt::clear_stop();
  PyErr_SetNone(PyExc_KeyboardInterrupt);
  throw py::error_already_set();
}

// A config: the file `config` with `text` (YAML or JSON, named `origin` in
// errors) laid over it, or `text` alone.
opt::ConfigNode config_root(const std::string& text, const std::string& origin, const std::string& config) {
  return config.empty() ? opt::ConfigNode::parse(text, origin)
         : text.empty() ? opt::ConfigNode::load(config)
                        : opt::ConfigNode::load(config).with(YAML::Load(text), origin);
}

// The config's study as `mechopt run` runs it, into `output` (or the
// config's directory where ""), its printed lines on stdout unless quiet;
// result.json's content as JSON text. Ctrl-C stops it: what was done is
// written, marked interrupted, and KeyboardInterrupt is raised.
std::string run_config(const opt::ConfigNode& root, const opt::Problem& problem, const std::string& output,
                       int threads, bool quiet) {
  opt::doe::BatchOptions o;
  o.output_directory = output;
  o.threads = threads;
  o.progress = "none";
  std::ostringstream sink;
  nlohmann::json j;
  {
    py::gil_scoped_release free;
    StopHandlers stop;
    j = opt::run_config(root, problem, o, quiet ? sink : std::cout, quiet ? sink : std::cerr);
    std::cout.flush();
  }
  raise_if_stopped();
  return j.dump();
}

// A problem made from a config (config_root), kept with it for its runs.
class PyProblem {
 public:
  PyProblem(const std::string& text, const std::string& origin, const std::string& config)
      : root_(config_root(text, origin, config)) {
    problem_ = opt::make_problem(root_);
    parameters_ = parameter_list(opt::model_parameters(root_));
  }
  std::string name() const { return problem_->name(); }
  const std::vector<std::string>& metrics() const { return problem_->metric_names(); }
  py::dict units() const {
    py::dict d;
    for (const auto& m : problem_->metric_names()) d[py::str(m)] = problem_->metric_unit(m);
    return d;
  }
  py::list variables() const {
    py::list out;
    const Eigen::VectorXd x0 = problem_->initial_point(false);
    for (std::size_t i = 0; i < problem_->variables().size(); ++i) {
      const auto& v = problem_->variables()[i];
      py::dict d;
      d["name"] = v.name;
      d["unit"] = opt::si_unit(v.dimension);
      d["lower"] = v.lower;
      d["upper"] = v.upper;
      d["initial"] = x0[static_cast<Eigen::Index>(i)];
      out.append(d);
    }
    return out;
  }
  py::list parameters() const { return parameters_; }
  // The config's own study, or the study `text` (objective, constraints,
  // study, output: YAML or JSON named `origin` in errors) on this problem.
  std::string run(const std::string& text, const std::string& origin, const std::string& output, int threads,
                  bool quiet) const {
    if (!text.empty()) return run_config(opt::ConfigNode::parse(text, origin), *problem_, output, threads, quiet);
    opt::ConfigNode own = [&] {  // a copy for this run: yaml-cpp trees are not read from two threads at once
      std::lock_guard lock(root_m_);
      return root_.clone();
    }();
    return run_config(own, *problem_, output, threads, quiet);
  }
  Eigen::VectorXd initial() const { return problem_->initial_point(false); }
  std::string settings() const { return problem_->record().dump(); }

  // X: n rows of the variables (float64, C order: taken as it is, no copy).
  py::dict evaluate(py::array_t<double, py::array::c_style | py::array::forcecast> X,
                    const std::vector<std::string>& names, bool gradient, int threads) const {
    const auto k = static_cast<py::ssize_t>(problem_->variables().size());
    if (X.ndim() == 1 && k == 1) X = X.reshape({X.shape(0), py::ssize_t(1)});
    if (X.ndim() == 1 && X.shape(0) == k) X = X.reshape({py::ssize_t(1), k});
    if (X.ndim() != 2 || X.shape(1) != k)
      throw py::value_error("X: expected an array of shape (n, " + std::to_string(k) + ") for the variables " +
                            variable_names() + ", got " + shape_text(X));
    const std::int64_t n = X.shape(0);
    const std::vector<std::string>& all = problem_->metric_names();
    const std::vector<std::string>& wanted = names.empty() ? all : names;
    std::vector<opt::MetricId> ids;
    for (const auto& m : wanted) {
      const opt::MetricId id = problem_->metric_id(m);
      if (id < 0) throw py::value_error("unknown metric '" + m + "' of problem " + name());
      ids.push_back(id);
    }
    std::vector<py::array_t<double>> values, grads;
    std::vector<double*> value_at, grad_at;
    for (std::size_t j = 0; j < ids.size(); ++j) {
      values.emplace_back(n);
      value_at.push_back(values.back().mutable_data());
      if (gradient) {
        grads.emplace_back(std::vector<py::ssize_t>{static_cast<py::ssize_t>(n), k});
        grad_at.push_back(grads.back().mutable_data());
      }
    }
    py::array_t<std::int32_t> status(n);
    std::int32_t* status_at = status.mutable_data();
    std::vector<std::string> messages(static_cast<std::size_t>(n));
    opt::MetricSet set;
    for (auto id : ids) set.add(id);
    const double nan = std::numeric_limits<double>::quiet_NaN();
    bool done;
    {
      py::gil_scoped_release free;
      StopHandlers stop;
      done = opt::evaluate_rows(*problem_, X.data(), n, k, set, gradient, threads,
                                [&](std::int64_t i, const opt::Evaluation& e) {
        status_at[i] = static_cast<std::int32_t>(e.status);
        messages[static_cast<std::size_t>(i)] = e.message;
        for (std::size_t j = 0; j < ids.size(); ++j) {
          const bool has = e.has(ids[j]);
          value_at[j][i] = has ? e[ids[j]].value : nan;
          if (!gradient) continue;
          double* g = grad_at[j] + i * k;
          for (py::ssize_t c = 0; c < k; ++c)
            g[c] = has && e[ids[j]].gradient.size() == k ? e[ids[j]].gradient[c] : nan;
        }
      });
    }
    if (!done) raise_if_stopped();
    py::dict out;
    for (std::size_t j = 0; j < ids.size(); ++j) {
      out[py::str(wanted[j])] = values[j];
      if (gradient) out[py::str("d" + wanted[j])] = grads[j];
    }
    out["status"] = status;
    out["message"] = messages;
    return out;
  }

 private:
  std::string variable_names() const {
    std::string s = "[";
    for (const auto& v : problem_->variables()) s += (s.size() > 1 ? ", " : "") + v.name;
    return s + "]";
  }
  static std::string shape_text(const py::array& a) {
    std::string s = "(";
    for (py::ssize_t i = 0; i < a.ndim(); ++i) s += (i ? ", " : "") + std::to_string(a.shape(i));
    return s + (a.ndim() == 1 ? ",)" : ")");
  }

  opt::ConfigNode root_;
  mutable std::mutex root_m_;  // held while a run copies root_
  std::unique_ptr<opt::Problem> problem_;
  py::list parameters_;
};

}  // namespace

PYBIND11_MODULE(_core, m) {
  m.doc() = "mechopt's problems, evaluated in C++ (the module to import is mechopt)";
  m.attr("__version__") = MECHOPT_VERSION;
  py::register_exception<opt::ConfigError>(m, "ConfigError", PyExc_ValueError);
  py::list statuses;
  for (const auto& s : mech::kStatusNames) statuses.append(py::str(std::string(s)));
  m.attr("STATUS") = statuses;
  m.def("registry", [] {
    py::list out;
    for (const auto& e : opt::registry()) {
      py::dict d;
      d["name"] = e.name;
      d["summary"] = e.summary;
      d["parameters"] = parameter_list(e.parameters);
      out.append(d);
    }
    return out;
  });
  py::class_<PyProblem>(m, "Problem")
      .def(py::init<const std::string&, const std::string&, const std::string&>(), py::arg("text"),
           py::arg("origin"), py::arg("config"))
      .def_property_readonly("initial", &PyProblem::initial)
      .def_property_readonly("name", &PyProblem::name)
      .def_property_readonly("metrics", &PyProblem::metrics)
      .def_property_readonly("units", &PyProblem::units)
      .def_property_readonly("variables", &PyProblem::variables)
      .def_property_readonly("parameters", &PyProblem::parameters)
      .def_property_readonly("settings_json", &PyProblem::settings)
      .def("run", &PyProblem::run, py::arg("text"), py::arg("origin"), py::arg("output"), py::arg("threads"),
           py::arg("quiet"))
      .def("evaluate", &PyProblem::evaluate, py::arg("X"), py::arg("metrics"), py::arg("gradient"),
           py::arg("threads"));
}
