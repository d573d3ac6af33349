// Ipopt behind the Driver interface: exact gradients and a dense constraint
// Jacobian from the problem's autodiff, the Hessian by limited-memory
// quasi-Newton (L-BFGS). A design the model cannot evaluate makes the
// callback return false, and Ipopt cuts its step back.
//
// Maxima over the crank cycle (Problem::local_maxima) are nonsmooth where two
// peaks are equal. With `epigraph` on, the driver minimises a bound t instead
// of such an objective, with one constraint "local maximum j <= t" per peak,
// and expands a constrained maximum into one constraint per peak: each row is
// smooth, and the rows are refreshed at every design (the peaks move with it).
// The row count is fixed at the start (the peaks at x0, plus two spare rows;
// missing peaks repeat the least, and with more peaks than rows the largest
// are kept); each row keeps its peak by angle as the design moves.
//
// Nothing non-finite reaches Ipopt: a value or derivative that is not finite
// makes the callback return false, as for an infeasible design (a NaN or inf
// in the Jacobian used to reach MUMPS, whose matching crashed on it). The
// time limit is the wall clock (Ipopt's max_cpu_time counts CPU time), checked
// around every evaluation like the stop request; once either fires, the
// callbacks evaluate no more and intermediate_callback stops Ipopt.
#include <IpIpoptApplication.hpp>
#include <IpTNLP.hpp>
#include <IpAlgBuilder.hpp>  // Ipopt-internal (tools/ipopt_headers.sh)
#include <IpTNLPAdapter.hpp>

#include <algorithm>
#include <cmath>
#include <exception>
#include <limits>
#include <sstream>
#include <time.h>

#include "drivers/ipopt_dense_solver.hpp"
#include "opt/drivers/ipopt.hpp"

// Ipopt times each part of an iteration (its TimedTask start and stop) with
// CpuTime() and SysTime(), two getrusage system calls each: on the
// conveyor's 3-variable epigraph run a quarter of the time went to the
// kernel. mechopt never reads those statistics (print_timing_statistics is
// off) and sets no max_cpu_time (the time limit is the wall clock, checked
// by the callbacks), so these definitions, which take the place of Ipopt's
// own (libipopt.so calls them through its PLT), answer from the vDSO clock:
// CPU time reads as elapsed time, which is never less, and system time as 0.
// tests/test_ipopt_driver.cpp checks that Ipopt's calls land here.
namespace Ipopt {
Number CpuTime() {
  timespec t{};
  clock_gettime(CLOCK_MONOTONIC, &t);
  opt::detail::ipopt_clock_reads.fetch_add(1, std::memory_order_relaxed);
  return static_cast<Number>(t.tv_sec) + 1e-9 * static_cast<Number>(t.tv_nsec);
}
Number SysTime() { return 0; }
}  // namespace Ipopt

namespace opt {
namespace {

using Ipopt::Index;
using Ipopt::Number;

constexpr double kInf = 1e20;  // Ipopt's default bound infinity is 1e19
constexpr int kSpareRows = 2;
// A variable bound farther than this many times max(1, |x0|) from the start
// goes to Ipopt as no bound (kInf). With a slack of 1e12 the barrier's
// complementarity sets the adaptive barrier parameter near 1e10, and the
// first step jumps by 6e10 (repro ipopt_huge_upper_bound.yaml).
constexpr double kFarBound = 1e6;

bool far(double bound, double x0) { return std::abs(bound - x0) > kFarBound * std::max(1.0, std::abs(x0)); }

bool all_finite(const Number* v, Index n) {
  return std::all_of(v, v + n, [](Number a) { return std::isfinite(a); });
}

// One constraint row group: a metric (or its local maxima) against a bound.
struct Row {
  Constraint constraint;
  int peaks = 0;  // 0: the metric itself; > 0: that many local-maximum rows
};

class Nlp : public Ipopt::TNLP {
 public:
  Nlp(const Problem& p, const Objective& obj, std::vector<Row> rows, int objective_peaks,
      double scale, const Eigen::VectorXd& x0, double t0, Result& result, bool history,
      detail::StopCheck& stop)
      : p_(p), obj_(obj), rows_(std::move(rows)), objective_peaks_(objective_peaks),
        scale_(scale), x0_(x0), t0_(t0), result_(result), history_(history), stop_(stop) {
    nx_ = static_cast<int>(x0.size());
    for (const auto& r : rows_) {
      wanted_.add(r.constraint.id);
      m_ += r.peaks ? r.peaks : 1;
    }
    m_ += objective_peaks_;
    wanted_.add(obj.id);
    row_peaks_.resize(rows_.size());
  }

  std::exception_ptr error;
  Eigen::VectorXd solution;
  int iterations = 0;  // Ipopt's, restoration phase included
  // The last evaluation, for the final report.
  const detail::EvaluationAt& last() const { return last_; }

  bool get_nlp_info(Index& n, Index& m, Index& nnz_jac, Index& nnz_h,
                    IndexStyleEnum& style) override {
    n = nx_ + (objective_peaks_ ? 1 : 0);
    m = m_;
    nnz_jac = n * m;
    nnz_h = 0;
    style = C_STYLE;
    return true;
  }

  bool get_bounds_info(Index n, Number* xl, Number* xu, Index m, Number* gl, Number* gu) override {
    return guard([&] {
      const Eigen::VectorXd lb = p_.lower_bounds(), ub = p_.upper_bounds();
      for (int i = 0; i < nx_; ++i) {
        xl[i] = far(lb[i], x0_[i]) ? -kInf : lb[i];
        xu[i] = far(ub[i], x0_[i]) ? kInf : ub[i];
      }
      if (n > nx_) xl[nx_] = -kInf, xu[nx_] = kInf;
      Index j = 0;
      for (const auto& r : rows_)
        for (int k = 0; k < std::max(1, r.peaks); ++k, ++j) gl[j] = r.constraint.equal ? 0.0 : -kInf, gu[j] = 0.0;
      for (; j < m; ++j) gl[j] = -kInf, gu[j] = 0.0;
      return true;
    });
  }

  bool get_starting_point(Index n, bool, Number* x, bool, Number*, Number*, Index, bool, Number*) override {
    for (int i = 0; i < nx_; ++i) x[i] = x0_[i];
    if (n > nx_) x[nx_] = t0_;
    return true;
  }

  bool eval_f(Index, const Number* x, bool, Number& f) override {
    return guard([&] {
      if (!update(x, false)) return false;
      f = objective_peaks_ ? x[nx_] : sign() * at()[obj_.id].value / scale_;
      return std::isfinite(f);
    });
  }

  bool eval_grad_f(Index n, const Number* x, bool, Number* g) override {
    return guard([&] {
      std::fill(g, g + n, 0.0);
      if (objective_peaks_) {
        g[nx_] = 1.0;
        return true;
      }
      if (!update(x, true)) return false;
      const auto& gr = at()[obj_.id].gradient;
      for (int i = 0; i < nx_; ++i) g[i] = sign() * gr[i] / scale_;
      return all_finite(g, n);
    });
  }

  bool eval_g(Index, const Number* x, bool, Index m, Number* g) override {
    return guard([&] {
      if (!update(x, false)) return false;
      fill_rows(x, g, nullptr);
      return all_finite(g, m);
    });
  }

  bool eval_jac_g(Index n, const Number* x, bool, Index m, Index, Index* iRow, Index* jCol,
                  Number* values) override {
    if (!values) {  // dense structure
      for (Index j = 0, k = 0; j < m; ++j)
        for (Index i = 0; i < n; ++i, ++k) iRow[k] = j, jCol[k] = i;
      return true;
    }
    return guard([&] {
      if (!update(x, true)) return false;
      std::fill(values, values + n * m, 0.0);
      fill_rows(x, nullptr, values);
      return all_finite(values, n * m);
    });
  }

  bool intermediate_callback(Ipopt::AlgorithmMode, Index iter, Number, Number, Number, Number, Number,
                             Number, Number, Number, Index, const Ipopt::IpoptData*,
                             Ipopt::IpoptCalculatedQuantities*) override {
    iterations = std::max(iterations, static_cast<int>(iter));  // iter 0 is the start point
    return !error && !stop_();  // stop once a callback has thrown, on the time limit or a stop request
  }

  void finalize_solution(Ipopt::SolverReturn, Index n, const Number* x, const Number*,
                         const Number*, Index, const Number*, const Number*, Number,
                         const Ipopt::IpoptData*, Ipopt::IpoptCalculatedQuantities*) override {
    guard([&] {
      solution = Eigen::Map<const Eigen::VectorXd>(x, std::min<Index>(n, nx_));
      return true;
    });
  }

 private:
  double sign() const { return obj_.maximize ? -1.0 : 1.0; }

  // No exception crosses into Ipopt: the first is kept, the callback fails,
  // intermediate_callback stops Ipopt, and minimize re-throws it.
  template <class F>
  bool guard(F&& f) {
    try {
      return f();
    } catch (...) {
      if (!error) error = std::current_exception();
      return false;
    }
  }

  const Evaluation& at() const { return last_.e; }

  // Evaluates the metrics (gradients included: cheap next to the cycle) and
  // the local maxima the rows need at x, once per x; false where the design
  // is infeasible, a peak is not finite, or the run is stopping (then
  // nothing is evaluated).
  bool update(const Number* x, bool) {
    Eigen::Map<const Eigen::VectorXd> xv(x, nx_);
    if (last_.x.size() == nx_ && last_.x == xv) return usable_;
    if (error || stop_()) return false;
    last_.x = xv;
    last_.evaluate(p_, wanted_, true);  // storage and workspace reused
    auto usable_peaks = [](const std::vector<MetricValue>& list) {
      return !list.empty() && std::all_of(list.begin(), list.end(), [](const MetricValue& v) {
        return std::isfinite(v.value) && v.gradient.allFinite();
      });
    };
    usable_ = at().ok();
    for (size_t i = 0; i < rows_.size(); ++i)
      if (rows_[i].peaks) {
        row_peaks_[i] = p_.local_maxima(xv, rows_[i].constraint.id);
        usable_ = usable_ && usable_peaks(row_peaks_[i]);
      }
    if (objective_peaks_) {
      objective_peak_list_ = p_.local_maxima(xv, obj_.id);
      usable_ = usable_ && usable_peaks(objective_peak_list_);
    }
    ++result_.evaluations;
    if (!usable_) ++result_.infeasible_evaluations;
    if (history_)
      result_.history.push_back({result_.evaluations, at().status, xv,
                                 at().ok() ? at()[obj_.id].value
                                           : std::numeric_limits<double>::quiet_NaN()});
    stop_();  // after the evaluation under way
    return usable_;
  }

  // The k rows of a maximum: its local maxima (Problem::local_maxima lists
  // them by angle), the largest k if there are more, by angle still; the
  // least repeated if fewer. A row keeps its peak as the design moves: rows
  // ordered by value swapped their peaks wherever two were equal, which is
  // at the optimum, so each row was itself a kinked max or min of two
  // peaks, and Ipopt's multipliers went to the wrong rows at every swap
  // (on the conveyor's kink its dual infeasibility stayed near 1e-2 and 2
  // of 30 starts ran out of iterations there). A repeated least peak is an
  // inactive row (the largest, repeated, made active rows twins).
  static std::vector<const MetricValue*> peak_rows(const std::vector<MetricValue>& list, int k) {
    std::vector<const MetricValue*> rows;
    for (const auto& v : list) rows.push_back(&v);
    if (static_cast<int>(rows.size()) > k) {
      std::vector<const MetricValue*> by_value = rows;
      std::nth_element(by_value.begin(), by_value.begin() + (k - 1), by_value.end(),
                       [](auto a, auto b) { return a->value > b->value; });
      const double least_kept = by_value[k - 1]->value;
      std::vector<const MetricValue*> kept;
      for (const MetricValue* v : rows)  // by angle; ties at the cut, the first
        if (static_cast<int>(kept.size()) < k && v->value >= least_kept) kept.push_back(v);
      rows = std::move(kept);
    }
    const MetricValue* least = *std::min_element(rows.begin(), rows.end(),
                                                 [](auto a, auto b) { return a->value < b->value; });
    while (static_cast<int>(rows.size()) < k) rows.push_back(least);
    return rows;
  }

  // Row values g (if given) and dense Jacobian rows jac (if given), n columns.
  void fill_rows(const Number* x, Number* g, Number* jac) const {
    const int n = nx_ + (objective_peaks_ ? 1 : 0);
    int j = 0;
    auto put = [&](double value, const Eigen::VectorXd* grad, double gsign, double t_coef) {
      if (g) g[j] = value;
      if (jac) {
        if (grad)
          for (int i = 0; i < nx_; ++i) jac[j * n + i] = gsign * (*grad)[i];
        if (t_coef != 0) jac[j * n + nx_] = t_coef;
      }
      ++j;
    };
    for (size_t i = 0; i < rows_.size(); ++i) {
      const Row& r = rows_[i];
      const Constraint& k = r.constraint;
      const double s = k.upper ? 1.0 : -1.0;
      if (!r.peaks) {
        const auto& mv = at()[k.id];
        put(k.g(mv.value), &mv.gradient, s, 0.0);
      } else {
        for (const MetricValue* mv : peak_rows(row_peaks_[i], r.peaks)) put(k.g(mv->value), &mv->gradient, s, 0.0);
      }
    }
    if (objective_peaks_) {
      for (const MetricValue* mv : peak_rows(objective_peak_list_, objective_peaks_)) {
        const Eigen::VectorXd scaled = mv->gradient / scale_;
        put(mv->value / scale_ - x[nx_], &scaled, 1.0, -1.0);
      }
    }
  }

  const Problem& p_;
  const Objective& obj_;
  std::vector<Row> rows_;
  int objective_peaks_;
  double scale_;
  Eigen::VectorXd x0_;
  double t0_;
  Result& result_;
  bool history_;
  detail::StopCheck& stop_;
  int nx_ = 0, m_ = 0;
  MetricSet wanted_;
  detail::EvaluationAt last_;
  bool usable_ = false;
  std::vector<std::vector<MetricValue>> row_peaks_;  // by row, for rows with peaks
  std::vector<MetricValue> objective_peak_list_;
};

DriverStatus map_status(Ipopt::ApplicationReturnStatus s) {
  switch (s) {
    case Ipopt::Solve_Succeeded:
    case Ipopt::Solved_To_Acceptable_Level:
    case Ipopt::Feasible_Point_Found: return DriverStatus::converged;
    case Ipopt::Maximum_Iterations_Exceeded: return DriverStatus::max_evaluations;
    case Ipopt::Maximum_CpuTime_Exceeded: return DriverStatus::max_time;
    case Ipopt::Infeasible_Problem_Detected: return DriverStatus::infeasible;
    case Ipopt::Not_Enough_Degrees_Of_Freedom:
    case Ipopt::Invalid_Problem_Definition:
    case Ipopt::Invalid_Option: return DriverStatus::invalid_arguments;
    default: return DriverStatus::failure;
  }
}

const char* status_text(Ipopt::ApplicationReturnStatus s) {
  switch (s) {
    case Ipopt::Solve_Succeeded: return "Solve_Succeeded";
    case Ipopt::Solved_To_Acceptable_Level: return "Solved_To_Acceptable_Level";
    case Ipopt::Infeasible_Problem_Detected: return "Infeasible_Problem_Detected";
    case Ipopt::Search_Direction_Becomes_Too_Small: return "Search_Direction_Becomes_Too_Small";
    case Ipopt::Diverging_Iterates: return "Diverging_Iterates";
    case Ipopt::User_Requested_Stop: return "User_Requested_Stop";
    case Ipopt::Feasible_Point_Found: return "Feasible_Point_Found";
    case Ipopt::Maximum_Iterations_Exceeded: return "Maximum_Iterations_Exceeded";
    case Ipopt::Restoration_Failed: return "Restoration_Failed";
    case Ipopt::Error_In_Step_Computation: return "Error_In_Step_Computation";
    case Ipopt::Maximum_CpuTime_Exceeded: return "Maximum_CpuTime_Exceeded";
    case Ipopt::Not_Enough_Degrees_Of_Freedom: return "Not_Enough_Degrees_Of_Freedom";
    case Ipopt::Invalid_Problem_Definition: return "Invalid_Problem_Definition";
    case Ipopt::Invalid_Option: return "Invalid_Option";
    case Ipopt::Invalid_Number_Detected: return "Invalid_Number_Detected";
    default: return "internal error";
  }
}

// One Ipopt application per thread, made once: making one registers Ipopt's
// options, 1.25M instructions (one and a half iterations of a 1-variable
// problem). Each run sets every option it relies on. No ipopt.opt is read
// from the working directory: the config is the whole input.
Ipopt::IpoptApplication& application() {
  thread_local const Ipopt::SmartPtr<Ipopt::IpoptApplication> app = [] {
    Ipopt::SmartPtr<Ipopt::IpoptApplication> a = new Ipopt::IpoptApplication();
    a->Options()->SetIntegerValue("print_level", 0);
    std::istringstream no_options_file;
    a->Initialize(no_options_file);
    return a;
  }();
  return *app;
}

}  // namespace

std::string IpoptDriver::incompatibility(const Problem& p, const std::vector<Constraint>&) const {
  return p.provides_gradients()
             ? ""
             : "ipopt needs exact gradients, and " + p.name() + " has none: it takes derivative-free algorithms only";
}

Result IpoptDriver::minimize(const Problem& problem, const Objective& objective,
                             const std::vector<Constraint>& constraints,
                             const Eigen::VectorXd& x0) const {
  detail::StopCheck stop(options_.max_seconds);
  const std::string why = driver_incompatibility(options_, problem, objective, constraints);
  Result result = detail::no_work(why.empty() ? DriverStatus::failure : DriverStatus::invalid_arguments, why, x0);
  result.library = "ipopt";
  result.algorithm = options_.epigraph ? "interior-point, L-BFGS, epigraph" : "interior-point, L-BFGS";
  if (!why.empty()) return result;
  Eigen::VectorXd x = x0;
  const detail::Bound b(problem, objective, constraints);
  const detail::Start start = detail::prepare_start(problem, b, x, result, stop);
  const Objective& f = b.objective;

  // Rows: user constraints, then the problem's implicit ones; maxima
  // expanded into their peaks when bounded above.
  std::vector<Row> rows;
  auto add = [&](const Constraint& k) {
    int peaks = 0;
    if (options_.epigraph && k.upper && !k.equal) {
      const auto list = problem.local_maxima(x, k.id);
      if (!list.empty()) peaks = static_cast<int>(list.size()) + kSpareRows;
    }
    rows.push_back({k, peaks});
  };
  for (const auto& k : b.constraints) add(k);
  for (const auto& k : b.implicit) add(k);

  int objective_peaks = 0;
  double t0 = 0;
  if (options_.epigraph && !objective.maximize) {
    const auto list = problem.local_maxima(x, f.id);
    if (!list.empty()) {
      objective_peaks = static_cast<int>(list.size()) + kSpareRows;
      for (const auto& v : list)
        if (std::isfinite(v.value)) t0 = std::max(t0, v.value / start.scale);
      t0 *= 1 + 1e-6;
    }
  }

  Ipopt::SmartPtr<Nlp> nlp = new Nlp(problem, f, rows, objective_peaks, start.scale, x, t0,
                                     result, options_.record_history, stop);
  Ipopt::IpoptApplication& app = application();
  const Ipopt::SmartPtr<Ipopt::OptionsList> o = app.Options();
  o->SetIntegerValue("print_level", options_.print_level);
  o->SetStringValue("sb", "yes");
  o->SetStringValue("hessian_approximation", "limited-memory");
  // Cheap iterations for few variables (docs/drivers.md, "Ipopt's linear
  // solver"): the barrier parameter from Mehrotra's probing step (one more
  // solve) instead of the quality function's search (several), and the
  // L-BFGS update inside the KKT matrix instead of Sherman-Morrison solves.
  o->SetStringValue("mu_oracle", "probing");
  o->SetStringValue("limited_memory_aug_solver", "extended");
  o->SetNumericValue("tol", options_.tol);
  o->SetIntegerValue("max_iter", options_.max_iterations);
  o->SetNumericValue("constr_viol_tol", std::max(options_.constraint_tol, 1e-12));
  Ipopt::ApplicationReturnStatus status = Ipopt::Solve_Succeeded;
  if (!stop()) {
    const bool dense = options_.linear_solver == "dense";
    o->SetStringValue("linear_solver", dense ? "custom" : "mumps");
    Ipopt::SmartPtr<Ipopt::AlgorithmBuilder> builder =
        new Ipopt::AlgorithmBuilder(dense ? detail::dense_aug_system_solver() : nullptr);
    Ipopt::SmartPtr<Ipopt::NLP> adapter = new Ipopt::TNLPAdapter(Ipopt::GetRawPtr(nlp), Ipopt::ConstPtr(app.Jnlst()));
    status = app.OptimizeNLP(adapter, builder);
  }
  result.iterations = nlp->iterations;
  if (nlp->error) std::rethrow_exception(nlp->error);

  result.status = stop.reason ? *stop.reason : map_status(status);
  result.message = std::string("Ipopt: ") + status_text(status) + start.note;
  if (result.stopped()) result.message = detail::stop_message(result.status, options_) + " (" + result.message + ")";
  result.x = nlp->solution.size() == x.size() ? nlp->solution : x;
  // A bound too far to pass on (kFarBound) is still the user's bound.
  const Eigen::VectorXd inside = result.x.cwiseMax(problem.lower_bounds()).cwiseMin(problem.upper_bounds());
  if (inside != result.x) {
    result.x = inside;
    if (result.status == DriverStatus::converged) result.status = DriverStatus::failure;
    result.message += "; Ipopt ended beyond a variable bound given to it as none (more than " +
                      std::to_string(static_cast<int>(kFarBound)) + " x the start's magnitude away)";
  }
  detail::finish(problem, b, result, &nlp->last());
  if (!options_.epigraph && !objective.maximize && !stop.reason && result.status != DriverStatus::converged &&
      !problem.local_maxima(result.x, f.id).empty())
    result.message += "; " + objective.metric + " is a maximum over the cycle, with kinks where two peaks are " +
                      "equal: ipopt takes such objectives with epigraph: true";
  result.seconds = stop.seconds();
  return result;
}

}  // namespace opt
