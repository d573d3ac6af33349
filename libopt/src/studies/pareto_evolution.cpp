// The evolutionary Pareto front (driver library: pagmo): pagmo's NSGA-II,
// MOEA/D or NSPSO evolves a population over the study's variables, the
// designs evaluated through opt::evaluate_rows. pagmo's multi-objective
// algorithms take no constraints, so the constraints enter the objective
// values, feasibility first (Penalised below). Built where CMake finds
// pagmo (MECHOPT_PAGMO); the config is refused before any evaluation
// otherwise (config/run_spec.cpp).
#include <atomic>
#include <chrono>
#include <cmath>
#include <iostream>
#include <limits>
#include <memory>

#include "core/text.hpp"
#include "opt/display_units.hpp"
#include "opt/evaluate_rows.hpp"
#include "opt/interrupt.hpp"
#include "opt/record.hpp"
#include "report/report.hpp"
#include "studies/front.hpp"
#include "studies/studies.hpp"

#ifdef MECHOPT_PAGMO
#include <pagmo/algorithm.hpp>
#include <pagmo/algorithms/moead.hpp>
#include <pagmo/algorithms/nsga2.hpp>
#include <pagmo/algorithms/nspso.hpp>
#include <pagmo/batch_evaluators/member_bfe.hpp>
#include <pagmo/bfe.hpp>
#include <pagmo/population.hpp>
#include <pagmo/problem.hpp>
#endif

namespace opt::studies {

#ifdef MECHOPT_PAGMO
namespace {

using text::fmt;
using Clock = std::chrono::steady_clock;

// A design as the front sees it: its objectives, its constraints' total
// violation (each in units of its bound's size, at least 1, as
// Constraint::tolerance measures; 0 where the constraint is met within that
// tolerance), and its status.
struct Assessed {
  Objectives f{};
  double violation = 0;
  Status status = Status::evaluation_error;
  bool feasible() const { return status == Status::ok && violation == 0; }
};

// The objective values pagmo sees: normalised to the two ends (the ideal
// at 0, the nadir at 1, so that MOEA/D's decomposition and NSPSO's
// distances weigh both objectives alike), feasibility first:
// - a feasible design: its normalised objectives;
// - a design that breaks a constraint: for each objective, the worst value
//   of any feasible design evaluated so far plus 1 + its violation;
// - a design whose status is not ok (or that a stop left unevaluated): the
//   same with a violation of kNotOk.
// So every feasible design dominates every infeasible one, a smaller
// violation dominates a larger, and an infeasible design lies beyond 2,
// outside the hypervolume's reference point (1.1, 1.1): a population's
// hypervolume is its feasible designs'. The worst feasible values start at
// the nadir (the ends are feasible designs) and are updated after each
// batch, in the designs' order, so a run repeats bit for bit at any thread
// count.
class Penalised {
 public:
  static constexpr double kNotOk = 1e9;

  Penalised(const Problem& p, const RunSpec& s, const FrontEnds& ends)
      : p_(p), cons_(s.constraints), f1_(p.metric_id(s.objectives[0])), f2_(p.metric_id(s.objectives[1])),
        threads_(s.threads), norm_(ends.normalisation()) {
    wanted_.add(f1_);
    wanted_.add(f2_);
    for (auto& c : cons_) wanted_.add(c.id = p.metric_id(c.metric));
  }

  // Rows [0, n) of X, k = the variables' count values each, over the
  // threads; a stop request leaves the rest unevaluated (their status
  // evaluation_error). `whole`: every row, one thread, whatever a stop
  // request says (the final population, which the front is made of).
  std::vector<Assessed> assess(const double* X, std::int64_t n, bool whole = false) {
    std::vector<Assessed> a(static_cast<size_t>(n));
    const auto k = static_cast<Eigen::Index>(p_.variables().size());
    std::atomic<std::int64_t> done{0};
    auto put = [&](std::int64_t i, const Evaluation& e) {
      ++done;
      Assessed& r = a[static_cast<size_t>(i)];
      r.status = e.status;
      if (!e.ok()) return;
      r.f = {e[f1_].value, e[f2_].value};
      for (const auto& c : cons_) {
        const double v = e[c.id].value;
        if (!c.met(v)) r.violation += c.violation(v) / std::max(1.0, std::abs(c.bound));
      }
    };
    if (whole) {
      Evaluation e;
      for (std::int64_t i = 0; i < n; ++i) {
        p_.evaluate(Eigen::Map<const Eigen::VectorXd>(X + i * k, k), wanted_, false, e);
        put(i, e);
      }
    } else {
      evaluate_rows(p_, X, n, k, wanted_, false, n > 1 ? threads_ : 1, put);
      evaluations_ += done;
    }
    return a;
  }

  // The values pagmo sees for rows [0, n) of X, into F (n rows of two).
  void operator()(const double* X, std::int64_t n, double* F) {
    const std::vector<Assessed> a = assess(X, n);
    for (const auto& r : a)
      if (r.feasible())
        for (int i = 0; i < 2; ++i) worst_[i] = std::max(worst_[i], norm_(r.f)[i]);
    for (size_t d = 0; d < a.size(); ++d) {
      const double v = a[d].feasible() ? 0 : a[d].status == Status::ok ? a[d].violation : kNotOk;
      for (int i = 0; i < 2; ++i) F[2 * d + i] = v == 0 ? norm_(a[d].f)[i] : worst_[i] + 1 + v;
    }
  }

  std::int64_t evaluations() const { return evaluations_; }

 private:
  const Problem& p_;
  std::vector<Constraint> cons_;
  MetricId f1_, f2_;
  MetricSet wanted_;
  int threads_;
  Normalisation norm_;
  Objectives worst_{1, 1};  // normalised
  std::int64_t evaluations_ = 0;
};

// pagmo's user-defined problem: the study's variables in their bounds, two
// objectives, batches evaluated at once (pagmo's member_bfe calls
// batch_fitness with a whole population). The copies pagmo makes share one
// Penalised.
struct Udp {
  std::shared_ptr<Penalised> values;
  pagmo::vector_double lower, upper;
  std::string name;

  pagmo::vector_double fitness(const pagmo::vector_double& x) const {
    pagmo::vector_double f(2);
    (*values)(x.data(), 1, f.data());
    return f;
  }
  pagmo::vector_double batch_fitness(const pagmo::vector_double& xs) const {
    const auto n = static_cast<std::int64_t>(xs.size() / lower.size());
    pagmo::vector_double f(2 * static_cast<size_t>(n));
    (*values)(xs.data(), n, f.data());
    return f;
  }
  std::pair<pagmo::vector_double, pagmo::vector_double> get_bounds() const { return {lower, upper}; }
  pagmo::vector_double::size_type get_nobj() const { return 2; }
  std::string get_name() const { return name; }
};

// One generation per evolve call, so the study can measure the front, report
// progress and stop between generations; the algorithm keeps its random
// engine from call to call, and NSPSO its swarm's velocities and memories
// (memory: true; without it every call would start a new swarm). NSGA-II's
// mutation rate is 1 / (variables), as Deb's paper sets it; everything else
// is pagmo's default.
pagmo::algorithm make_algorithm(const DriverOptions& d, size_t variables) {
  const auto seed = static_cast<unsigned>(d.seed);
  if (d.algorithm == "moead") {
    const auto neighbours = static_cast<pagmo::population::size_type>(std::min(20, d.population - 1));
    return pagmo::algorithm{pagmo::moead(1u, "grid", "tchebycheff", neighbours, 1.0, 0.5, 20., 0.9, 2u, true, seed)};
  }
  if (d.algorithm == "nspso") {
    pagmo::nspso a(1u, 0.6, 2.0, 2.0, 1.0, 0.5, 60u, "crowding distance", true, seed);
    a.set_bfe(pagmo::bfe{pagmo::member_bfe{}});
    return pagmo::algorithm{a};
  }
  pagmo::nsga2 a(1u, 0.95, 10., 1.0 / static_cast<double>(variables), 50., seed);
  a.set_bfe(pagmo::bfe{pagmo::member_bfe{}});
  return pagmo::algorithm{a};
}

std::vector<Objectives> objectives_of(const pagmo::population& pop) {
  std::vector<Objectives> f;
  for (const auto& v : pop.get_f()) f.push_back({v[0], v[1]});
  return f;
}

}  // namespace

nlohmann::json pareto_evolution(const Problem& p, const RunSpec& s, std::ostream& out, const std::string& dir,
                                std::vector<std::string>& files) {
  const DriverOptions& d = s.driver;
  const std::string f1 = s.objectives[0], f2 = s.objectives[1];
  const auto started = Clock::now();
  const FrontEnds ends = front_ends(p, s, s.anchor_driver);
  const double anchor_seconds = std::chrono::duration<double>(Clock::now() - started).count();
  out << "pareto front: pagmo " << d.algorithm << ", " << d.population << " designs, " << d.generations
      << " generations, seed " << d.seed << "; hypervolume of " << f1 << " and " << f2
      << " scaled to the two optima, reference point (1.1, 1.1)\n";

  auto values = std::make_shared<Penalised>(p, s, ends);
  Udp udp{values, {}, {}, "mechopt " + p.name()};
  for (const auto& v : p.variables()) udp.lower.push_back(v.lower), udp.upper.push_back(v.upper);
  const auto evolve_started = Clock::now();
  auto seconds = [&] { return std::chrono::duration<double>(Clock::now() - evolve_started).count(); };
  pagmo::population pop(pagmo::problem{udp}, pagmo::bfe{pagmo::member_bfe{}},
                        static_cast<pagmo::population::size_type>(d.population), static_cast<unsigned>(d.seed));
  pagmo::algorithm algorithm = make_algorithm(d, p.variables().size());

  CsvRecorder history_csv(dir + "generations.csv", {"generation", {}, {"evaluations", "seconds", "hypervolume"}});
  nlohmann::json history = nlohmann::json::array();
  const int every = std::max(1, d.generations / 10);  // printed progress: about ten lines
  int g = 0;
  std::string stopped_by = "generations";
  while (g < d.generations) {
    pop = algorithm.evolve(pop);
    ++g;
    const double hv = hypervolume(objectives_of(pop), kHypervolumeReference), t = seconds();
    const double cells[] = {static_cast<double>(values->evaluations()), t, hv};
    history_csv.record({g, Eigen::VectorXd(), "ok", cells});
    history.push_back({{"generation", g}, {"evaluations", values->evaluations()}, {"seconds", t}, {"hypervolume", hv}});
    if (g % every == 0 || g == d.generations)
      out << "generation " << g << "/" << d.generations << ": " << values->evaluations() << " designs, hypervolume "
          << fmt(hv, 6) << ", " << fmt(t, 3) << " s\n";
    if (stop_requested()) { stopped_by = "interrupted"; break; }
    if (t > d.max_seconds && g < d.generations) { stopped_by = "max_seconds"; break; }
  }
  history_csv.close(g == d.generations);
  const double evolve_seconds = seconds();
  const std::int64_t evaluations = values->evaluations();

  // The front: the final population's feasible designs that no other one
  // dominates, evaluated again for their status and constraints (after a
  // stop too: the front found so far is written).
  const auto xs = pop.get_x();
  const size_t k = p.variables().size();
  pagmo::vector_double flat;
  for (const auto& x : xs) flat.insert(flat.end(), x.begin(), x.end());
  const std::vector<Assessed> a = values->assess(flat.data(), static_cast<std::int64_t>(xs.size()), true);
  std::vector<Objectives> feasible_f;
  std::vector<size_t> feasible;
  for (size_t i = 0; i < a.size(); ++i)
    if (a[i].feasible()) feasible.push_back(i), feasible_f.push_back(a[i].f);
  std::vector<size_t> kept = non_dominated(feasible_f);
  std::reverse(kept.begin(), kept.end());  // from the least f2, as the epsilon-constraint front runs

  RecordLayout layout{"point", {}, {f1, f2}};
  for (const auto& v : p.variables()) layout.variables.push_back(v.name);
  CsvRecorder csv(dir + "pareto.csv", layout);
  out << "the front: " << kept.size() << " non-dominated feasible designs of " << xs.size() << "\n";
  const FrontTable table(p, out, {f1, f2}, {p.metric_unit(f1), p.metric_unit(f2)});
  std::vector<Objectives> front;
  nlohmann::json rows = nlohmann::json::array();
  for (size_t r = 0; r < kept.size(); ++r) {
    const size_t i = feasible[kept[r]];
    const Eigen::VectorXd x = Eigen::Map<const Eigen::VectorXd>(xs[i].data(), static_cast<Eigen::Index>(k));
    front.push_back(a[i].f);
    csv.record({static_cast<long>(r), x, "ok", a[i].f});
    table.row({a[i].f[0], a[i].f[1]}, x, "ok");
    rows.push_back({{f1, a[i].f[0]}, {f2, a[i].f[1]}, {"variables", report::variables_json(p, x)}});
  }
  csv.close(true);

  nlohmann::json j = front_json(p, s, ends, front);
  j.update({{"points", rows},
            {"evaluations", evaluations},
            {"seconds", evolve_seconds},
            {"anchor_seconds", anchor_seconds},
            {"driver", {{"library", "pagmo"}, {"algorithm", d.algorithm}, {"population", d.population},
                        {"generations", d.generations}, {"seed", d.seed}}},
            {"anchor_driver", {{"library", ends.a.library}, {"algorithm", ends.a.algorithm}}},
            {"generations_done", g},
            {"stopped_by", stopped_by},
            {"history", history},
            {"csv", dir + "pareto.csv"},
            {"generations_csv", dir + "generations.csv"}});
  out << "hypervolume " << fmt(j["hypervolume"].get<double>(), 6) << " after " << evaluations << " designs in "
      << fmt(evolve_seconds, 3) << " s (the two optima: " << fmt(anchor_seconds, 3) << " s)\n";
  write_front_chart(p, s, ends, front, false, dir, files);
  return j;
}

#else

nlohmann::json pareto_evolution(const Problem&, const RunSpec&, std::ostream&, const std::string&,
                                std::vector<std::string>&) {
  throw std::runtime_error("this mechopt was built without pagmo (libpagmo-dev)");
}

#endif

}  // namespace opt::studies

namespace opt {

bool evolutionary_fronts_built() {
#ifdef MECHOPT_PAGMO
  return true;
#else
  return false;
#endif
}

}  // namespace opt
