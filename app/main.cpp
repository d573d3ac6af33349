// mechopt command line: parse, dispatch, print. Exit codes: 0 done, 1 runtime
// failure, 2 bad input (config or arguments) or a run that cannot start (its
// store is another run's to write).
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#if defined(__GLIBC__)
#include <malloc.h>
#endif
#include <iostream>
#include <string>
#include <vector>

#include "opt/dakota.hpp"
#include "opt/derivatives.hpp"
#include "opt/doe/batch.hpp"
#include "opt/doe/recover.hpp"
#include "opt/doe/store.hpp"
#include "opt/drivers/nlopt.hpp"
#include "opt/interrupt.hpp"
#include "opt/record.hpp"
#include "opt/study.hpp"
#include "opt/units.hpp"
#include "opt/registry.hpp"
#include "problems/linkage/drawing.hpp"
#include "help.hpp"

namespace {

struct Args {
  std::string command, config, output;
  bool markdown = false;  // list --markdown
  std::vector<std::pair<std::string, std::string>> sets;
  opt::doe::BatchOptions batch;
  bool batch_flags = false;  // any of the doe flags given
  bool doe_only_flags = false;  // --progress, --shard, --new, --dry-run (a sweep takes --threads, --force)
  std::string export_format;               // export: csv | json | canonical
  std::vector<std::string> stores;         // export, merge, check, recover
  std::string angles = "0,30,60,90,120,150,180,210,240,270,300,330 deg", svg;  // kinematics
};

[[noreturn]] void usage_error(const std::string& what) {
  std::cerr << "mechopt: " << what << "\n\n" << kUsage;
  std::exit(2);
}

// --shard I/N with 0 <= I < N, or `auto` from a Slurm job array's environment.
opt::doe::Shard parse_shard(const std::string& text) {
  std::string t = text;
  if (t == "auto") {
    const char* id = std::getenv("SLURM_ARRAY_TASK_ID");
    const char* count = std::getenv("SLURM_ARRAY_TASK_COUNT");
    if (!id || !count) usage_error("--shard auto needs SLURM_ARRAY_TASK_ID and SLURM_ARRAY_TASK_COUNT");
    // An array may start anywhere (--array=1-8): shard 0 is its first task.
    const char* first = std::getenv("SLURM_ARRAY_TASK_MIN");
    t = std::to_string(std::atol(id) - (first ? std::atol(first) : 0)) + "/" + count;
  }
  opt::doe::Shard s;
  char tail = 0;
  if (std::sscanf(t.c_str(), "%d/%d%c", &s.index, &s.count, &tail) != 2 || s.count < 1 || s.index < 0 ||
      s.index >= s.count)
    usage_error("--shard expects I/N with 0 <= I < N, got '" + text + "'");
  return s;
}

Args parse_args(int argc, char** argv) {
  Args a;
  std::vector<std::string> v(argv + 1, argv + argc);
  if (v.empty()) usage_error("missing command");
  a.command = v[0];
  for (size_t i = 1; i < v.size(); ++i)
    if (v[i] == "--help" || v[i] == "-h" || (a.command == "help" && i == 1)) {
      const std::string& name = a.command == "help" ? v[i] : a.command;
      for (const auto& c : kCommands)
        if (name == c.name) {
          std::cout << c.help;
          std::exit(0);
        }
      usage_error("unknown command '" + name + "'");
    }
  for (size_t i = 1; i < v.size(); ++i) {
    // --flag=value is --flag value
    if (const auto eq = v[i].find('='); v[i].rfind("--", 0) == 0 && eq != std::string::npos) {
      v.insert(v.begin() + static_cast<long>(i) + 1, v[i].substr(eq + 1));
      v[i] = v[i].substr(0, eq);
    }
    auto value = [&] {
      if (i + 1 == v.size()) usage_error(v[i] + " needs a value");
      return v[++i];
    };
    if (v[i] == "--threads") {
      const std::string t = value();
      char* end = nullptr;
      const long n = std::strtol(t.c_str(), &end, 10);
      if (*end || n < 1 || n > 4096) usage_error("--threads expects a whole number from 1 to 4096, got '" + t + "'");
      a.batch.threads = static_cast<int>(n);
      a.batch_flags = true;
    } else if (v[i] == "--progress") {
      a.batch.progress = value();
      if (a.batch.progress != "bar" && a.batch.progress != "jsonl" && a.batch.progress != "none")
        usage_error("--progress expects bar, jsonl or none, got '" + a.batch.progress + "'");
      a.batch_flags = a.doe_only_flags = true;
    } else if (v[i] == "--shard") {
      a.batch.shard = parse_shard(value());
      a.batch_flags = a.doe_only_flags = true;
    } else if (v[i] == "--new" || v[i] == "--force" || v[i] == "--dry-run") {
      (v[i] == "--new" ? a.batch.fresh : v[i] == "--force" ? a.batch.force : a.batch.dry_run) = true;
      a.batch_flags = true;
      a.doe_only_flags = a.doe_only_flags || v[i] != "--force";
    } else if ((v[i] == "--csv" || v[i] == "--json" || v[i] == "--canonical") && a.command == "export") {
      a.export_format = v[i].substr(2);
    } else if ((a.command == "export" || a.command == "merge" || a.command == "check" || a.command == "recover" ||
                a.command == "dakota") &&
               v[i][0] != '-') {
      a.stores.push_back(v[i]);  // (dakota: PARAMS and RESULTS)
    } else if (v[i] == "--config" && a.command == "dakota") {
      a.config = value();
    } else if (v[i] == "--output" || v[i] == "--set") {
      if (i + 1 == v.size()) usage_error(v[i] + " needs a value");
      const std::string val = v[++i];
      if (v[i - 1] == "--output") {
        a.output = val;
      } else {
        const auto eq = val.find('=');
        if (eq == std::string::npos || eq == 0) usage_error("--set expects KEY=VALUE, got '" + val + "'");
        a.sets.emplace_back(val.substr(0, eq), val.substr(eq + 1));
      }
    } else if ((v[i] == "--angles" || v[i] == "--svg") && a.command == "kinematics" && i + 1 < v.size()) {
      (v[i] == "--svg" ? a.svg : a.angles) = v[i + 1], ++i;
    } else if (v[i] == "--markdown" && a.command == "list") {
      a.markdown = true;
    } else if (a.config.empty() && v[i][0] != '-') {
      a.config = v[i];
    } else {
      usage_error("unexpected argument '" + v[i] + "'");
    }
  }
  const bool takes_config =
      a.command == "run" || a.command == "eval" || a.command == "check-derivatives" || a.command == "kinematics";
  if (takes_config && a.config.empty())
    usage_error(a.command + " needs a CONFIG file");
  if (!a.sets.empty() && a.command != "eval" && a.command != "check-derivatives")
    usage_error("--set goes with eval or check-derivatives");
  if (!a.output.empty() && a.command != "run") usage_error("--output goes with run");
  if (a.batch_flags && a.command != "run") usage_error("--threads, --progress, --shard, --new, --force and --dry-run go with run");
  if (a.command == "export" && (a.stores.size() != 1 || a.export_format.empty()))
    usage_error("export expects one STORE and --csv, --json or --canonical");
  if (a.command == "merge" && a.stores.size() < 2) usage_error("merge expects OUT and at least one STORE");
  if (a.command == "check" && a.stores.size() != 1) usage_error("check expects one STORE");
  if (a.command == "recover" && a.stores.size() != 2) usage_error("recover expects STORE and OUT");
  if (a.command == "dakota" && (a.stores.size() != 2 || a.config.empty()))
    usage_error("dakota expects PARAMS RESULTS --config CONFIG");
  return a;
}

// The unit grammar, the dimensions with their SI units and the symbols with
// the prefixes, as opt/units.hpp reads them.
void list_units(bool markdown) {
  const auto& prefixes = opt::unit_prefixes();
  if (!markdown) {
    std::cout << "units: " << opt::unit_grammar() << "\n  symbols (* takes a prefix):";
    for (const auto& s : opt::unit_symbols()) std::cout << " " << s.name << (s.prefixed ? "*" : "");
    std::cout << "\n  prefixes:";
    for (const auto& p : prefixes) std::cout << " " << p.name;
    std::cout << "\n";
    return;
  }
  std::cout << "## Units\n\n"
               "A value with a dimension is `NUMBER UNIT` (`0.2 m`, `250mm`); a bare number is SI. A unit is a "
               "product of symbols, each with an optional SI prefix and power (`^2`, `^-1`, `²`, `⁻¹`), separated "
               "by a space, `*`, `·` or `.`; everything after its one `/` is the denominator (`kg/m s` is "
               "kg/(m s)), and `1/` starts a reciprocal: `2 kN m s/rad`, `0.11 MN*m/rad`, `100 rev/min`, "
               "`363 kgf`, `0.08 kg/mm`, `2 kgf/cm²`, `1 тс`. A unit fits a key when its exponents of mass, "
               "length, time and angle are the key's dimension's (the radian counts: `rev/min` is an angular "
               "speed, `N m/rad` a rotational stiffness). A torque and an energy have equal exponents, and the "
               "spelling tells them apart: a unit with `J` or `W` is an energy, any other (`N m`, `kgf m`) a "
               "torque. Constraint bounds take the metric's dimension. The SI value is within one ulp of the "
               "exact product.\n\n| dimension | SI unit | also, e.g. |\n|---|---|---|\n";
  for (const auto d : opt::unit_dimensions()) {
    const std::string name = opt::to_string(d);
    std::cout << "| " << name.substr(name.find(' ') + 1) << " | `" << opt::si_unit(d) << "` |";
    for (const char* e : opt::unit_examples(d)) std::cout << " `" << e << "`";
    std::cout << " |\n";
  }
  std::cout << "\n| symbol | is | prefixes |\n|---|---|---|\n";
  for (const auto& s : opt::unit_symbols())
    std::cout << "| `" << s.name << "` | " << s.meaning << " | " << (s.prefixed ? "yes" : "") << " |\n";
  std::cout << "\nPrefixes:";
  for (const auto& p : prefixes) std::cout << " `" << p.name << "` 10^" << p.power;
  std::cout << " (the Cyrillic ones with Cyrillic symbols: `кН`, `мм`, `см`). A name is looked up whole "
               "before it is split into a prefix and a symbol: `min` is the minute, `mm` the millimetre.\n";
}

// Problems with their parameter tables and metrics, and the drivers; with
// `markdown`, the config reference kept in docs/config.md.
void list(bool markdown) {
  if (markdown) {
    list_units(true);
    std::cout << "\nA value in a config may take any unit of its dimension. What mechopt prints (tables, "
                 "summaries, the defaults and domains below) and draws shows angles in deg, other quantities in "
                 "SI; result.json, the CSV files and the store hold SI (angles in rad), for scripts.\n";
    std::cout << "\n## Model keys\n\nEvery key under `model:`, from each problem's parameter table; a key "
                 "marked *variable* may be freed under `variables:` (its bounds, initial value and grid "
                 "points must lie in its domain). A dotted key sits in a section: `fidelity.rod` is "
                 "`model: {fidelity: {rod: full}}`.\n\n";
  }
  std::cout << (markdown ? "" : "problems:\n");
  for (const auto& e : opt::registry()) {
    const auto p = e.make(opt::ConfigNode::parse("problem: " + e.name, "<list>"));
    if (markdown) {
      std::cout << "### " << e.name << "\n\n" << e.summary << ".\n\n"
                << "| key | default | domain | variable | meaning | source |\n|---|---|---|---|---|---|\n";
      auto cell = [](const std::string& t) {  // a '|' inside a cell would end it
        std::string out;
        for (const char ch : t) (ch == '|' ? out += "\\|" : out += ch);
        return out;
      };
      for (const auto& r : e.parameters)
        std::cout << "| `" << r.name << "` | " << opt::value_text(r) << " | " << opt::domain_text(r) << " | "
                  << (r.variable ? "yes" : "") << " | " << cell(r.doc) << " | " << r.equation << " |\n";
      std::cout << "\nMetrics (SI):";
      for (const auto& m : p->metric_names()) {
        const std::string u = p->metric_unit(m);
        std::cout << " `" << m << "`" << (u.empty() ? "" : " [" + u + "]");
      }
      std::cout << "\n\n";
      continue;
    }
    std::cout << "  " << e.name << " — " << e.summary << "\n    model: key = default  (domain)  meaning; source   (* may be a variable)\n";
    for (const auto& r : e.parameters)
      std::cout << "      " << (r.variable ? "* " : "  ") << r.name << " = " << opt::value_text(r) << "  ("
                << opt::domain_text(r) << ")  " << r.doc << (r.equation.empty() ? "" : "; " + r.equation) << "\n";
    std::cout << "    metrics:";
    for (const auto& m : p->metric_names()) std::cout << " " << m;
    std::cout << "\n";
  }
  if (markdown) return;
  list_units(false);
  std::cout << "drivers:\n  nlopt:";
  for (const auto& a : opt::nlopt_algorithms()) std::cout << " " << a;
  std::cout << "\n  ipopt: interior point, L-BFGS Hessian, epigraph rows for cycle maxima\n"
            << "  line: one variable, Brent on the derivative\n"
            << (opt::evolutionary_fronts_built() ? "  pagmo (pareto fronts): nsga2 moead nspso\n"
                                                 : "  pagmo (pareto fronts): not in this build (libpagmo-dev)\n");
}

int check(const opt::Problem& p) {
  const Eigen::VectorXd x = p.initial_point(false);
  if (p.variables().empty()) {
    std::cerr << "mechopt: check-derivatives needs at least one entry under 'variables'\n";
    return 2;
  }
  if (!p.provides_gradients()) {
    std::cerr << "mechopt: " << p.name() << " has no exact gradients to check\n";
    return 2;
  }
  const auto e = p.evaluate(x, opt::MetricSet::all(), false);
  if (!e.ok()) {
    std::cerr << "mechopt: the model values give an infeasible design (" << mech::to_string(e.status) << ")\n";
    return 1;
  }
  const auto checks = opt::check_derivatives(p, x);
  int bad = 0;
  std::printf("%-34s %-16s %16s %16s %10s\n", "metric", "variable", "autodiff", "central diff", "rel error");
  for (const auto& c : checks) {
    bad += !c.ok;
    std::printf("%-34s %-16s %16.9g %16.9g %10.2e%s\n", c.metric.c_str(), c.variable.c_str(),
                c.autodiff, c.central, c.error, c.ok ? "" : "  MISMATCH");
  }
  std::printf("%zu checks, %d mismatches (tolerance 1e-7 relative to max(1, |value|))\n", checks.size(), bad);
  return bad ? 1 : 0;
}

// SIGINT/SIGTERM: the evaluation under way finishes, what is done is written
// and marked interrupted, and the exit code is 128 + the signal.
int stopped(const std::string& where) {
  if (!opt::stop_requested()) return 0;
  const int sig = opt::stop_signal() ? opt::stop_signal() : SIGINT;
  std::cerr << "mechopt: interrupted by " << (sig == SIGTERM ? "SIGTERM" : "SIGINT") << "; what was done is in "
            << where << "\n";
  return 128 + sig;
}

// What `check` and `recover` found, on stdout.
void print_check(const opt::doe::StoreCheck& c) {
  std::cout << "store: " << c.file << "\nconfig hash: "
            << c.config_hash.value_or("none (the config given to the next run supplies it)") << "\n";
  if (c.hi >= 0)
    std::cout << "samples: " << c.intact << " intact of [" << c.lo << ", " << c.hi << "), " << c.missing << " missing"
              << (c.finished ? " (the store says finished)" : "") << "\n";
  else
    std::cout << "samples: " << c.intact << " intact rows (the run's range is unknown)\n";
  std::cout << "by status:";
  for (const auto& [status, n] : c.statuses) std::cout << " " << status << " " << n;
  std::cout << (c.checksums ? "" : "\nrows without checksums (a store from before them): their values are unverified")
            << "\n" << (c.sound() ? "sound\n" : "damaged:\n");
  for (const auto& p : c.problems) std::cout << "  " << p << "\n";
}

// Exit 2: the config (or the store it meets) is wrong, with the message that says where.
int bad_input(const std::exception& e) {
  std::cerr << "mechopt: error: " << e.what() << "\n";
  opt::doe::abort_peers(2);  // the other MPI ranks, if any, would wait forever
  return 2;
}

int run(const Args& a) {
  const opt::ConfigNode root = opt::with_model_values(opt::ConfigNode::load(a.config), a.sets);
  const auto problem = opt::make_problem(root);
  if (a.command == "eval") {
    nlohmann::json j = opt::metrics_json(*problem, problem->initial_point(false));
    j["problem"] = problem->name();
    j["settings"] = problem->record();
    j["mechopt_version"] = MECHOPT_VERSION;
    std::cout << j.dump(2) << "\n";
    return 0;
  }
  if (a.command == "check-derivatives") return check(*problem);
  const bool doe = opt::is_doe(root);
  if (a.doe_only_flags && !doe) usage_error("--progress, --shard, --new and --dry-run go with a doe study");
  if (a.batch_flags && !doe) {
    const opt::RunSpec s = opt::parse_run(root, *problem, a.batch.force);
    if (s.type != "sweep" && !(s.driver.library == "pagmo" && !a.batch.force))
      usage_error("--threads and --force go with a doe or sweep study (--threads also with a pagmo front)");
  }
  opt::install_stop_handlers();
  opt::doe::BatchOptions o = a.batch;
  o.output_directory = a.output;
  if (doe) o.peers = opt::doe::mpi_peers();
  opt::run_config(root, *problem, o, std::cout, std::cerr);
  return stopped(o.output_directory + (doe ? "/store.sqlite" : "/result.json"));
}

// Freed memory stays with the process (up to 64 MB at the top of each
// thread's heap, blocks under 32 MB from the heap) instead of going back to
// the kernel on every free past glibc's default 128 KiB: a model that builds
// buffers per evaluation (the elastic drive's trajectories) had each sample
// return them and fault them back in, ~35 page faults a sample, and with
// two threads the shootdowns of one address space. The DOEs run 2-6%
// faster so, for some 7 MB more peak memory (docs/performance.md).
void keep_freed_memory() {
#if defined(__GLIBC__)
  mallopt(M_TRIM_THRESHOLD, 64 << 20);
  mallopt(M_MMAP_THRESHOLD, 32 << 20);
#endif
}

}  // namespace

int main(int argc, char** argv) {
  keep_freed_memory();
  const Args a = parse_args(argc, argv);
  if (a.command == "--help" || a.command == "-h" || a.command == "help") {
    std::cout << kUsage;
    return 0;
  }
  if (a.command == "--version") {
    std::cout << "mechopt " << MECHOPT_VERSION << "\n";
    return 0;
  }
  try {
    if (a.command == "list") {
      list(a.markdown);
      return 0;
    }
    if (a.command == "run" || a.command == "eval" || a.command == "check-derivatives") return run(a);
    if (a.command == "kinematics") {
      std::vector<double> angles;
      try {
        angles = problems::linkage::crank_angles(a.angles);
      } catch (const std::invalid_argument& e) {
        usage_error(std::string("--angles: ") + e.what());
      }
      problems::linkage::kinematics_command(opt::ConfigNode::load(a.config), angles, a.svg, std::cout);
      return 0;
    }
    if (a.command == "export") {
      try {
        if (a.export_format == "json") opt::doe::export_json(a.stores[0], std::cout);
        else opt::doe::export_csv(a.stores[0], std::cout, a.export_format == "csv");
      } catch (const std::exception& e) {  // never a partial file in silence
        std::cout.flush();
        std::cerr << "mechopt: failed: " << e.what() << "\nmechopt: export: the output is incomplete\n";
        return 1;
      }
      return 0;
    }
    if (a.command == "check") {
      const auto c = opt::doe::check_store(a.stores[0]);
      print_check(c);
      return c.sound() ? 0 : 1;
    }
    if (a.command == "recover") {
      const auto c = opt::doe::recover_store(a.stores[0], a.stores[1]);
      print_check(c);
      if (c.saved < 0) {
        std::cerr << "mechopt: recover: nothing could be saved from " << c.file << "\n";
        return 1;
      }
      std::cout << "saved " << c.saved << " rows into " << a.stores[1] << "/store.sqlite"
                << (c.config_hash ? "" : " without meta: the config given to its next run supplies it") << "\n";
      return 0;
    }
    if (a.command == "dakota") {  // Dakota's analysis driver (docs/interfaces.md)
      const opt::ConfigNode root = opt::ConfigNode::load(a.config);
      const auto problem = opt::make_problem(root);
      const auto responses =  // what Dakota's default labels stand for, where the config says
          root.has("objective") ? opt::dakota_responses(opt::parse_run(root, *problem)) : std::vector<std::string>{};
      const std::string results = opt::dakota_results(*problem, responses, opt::read_dakota_params(a.stores[0]));
      opt::write_file_atomically(a.stores[1], results);
      return 0;
    }
    if (a.command == "merge") {
      const auto r = opt::doe::merge_stores(a.stores[0], {a.stores.begin() + 1, a.stores.end()});
      std::cout << "merged " << r.rows << " samples from " << r.inputs.size() << " stores into " << a.stores[0]
                << "/store.sqlite\n";
      return 0;
    }
    usage_error("unknown command '" + a.command + "'");
  } catch (const opt::ConfigError& e) {
    return bad_input(e);
  } catch (const opt::doe::StoreMismatch& e) {  // a store of another config: the input is wrong, not the run
    return bad_input(e);
  } catch (const opt::doe::StoreBusy& e) {  // another run writes that store: this one cannot start
    return bad_input(e);
  } catch (const std::exception& e) {
    std::cerr << "mechopt: failed: " << e.what() << "\n";
    opt::doe::abort_peers(1);
    return 1;
  }
}
