// The doe study end to end: factors set through x or in the model, rows
// checked against closed forms, results independent of the thread count,
// exact resume after a stop or a SIGKILL, a changed config refused.
#include <gtest/gtest.h>
#include <sqlite3.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <sstream>
#include <fcntl.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <thread>
#include <tuple>
#include <unistd.h>

#include "cli.hpp"
#include "opt/doe/batch.hpp"
#include "opt/doe/store.hpp"
#include "opt/interrupt.hpp"
#include "opt/registry.hpp"

namespace {

namespace fs = std::filesystem;

// Rows of `select COLUMNS from samples order by idx`, each cell as text ("" for NULL).
std::vector<std::vector<std::string>> rows(const std::string& dir, const std::string& columns) {
  sqlite3* db = nullptr;
  EXPECT_EQ(sqlite3_open_v2((dir + "/store.sqlite").c_str(), &db, SQLITE_OPEN_READONLY, nullptr), SQLITE_OK);
  sqlite3_stmt* st = nullptr;
  const std::string sql = "select " + columns + " from samples order by idx";
  EXPECT_EQ(sqlite3_prepare_v2(db, sql.c_str(), -1, &st, nullptr), SQLITE_OK) << sqlite3_errmsg(db);
  std::vector<std::vector<std::string>> out;
  while (st && sqlite3_step(st) == SQLITE_ROW) {
    std::vector<std::string> r;
    for (int c = 0; c < sqlite3_column_count(st); ++c) {
      const auto* t = sqlite3_column_text(st, c);
      r.push_back(t ? reinterpret_cast<const char*>(t) : "");
    }
    out.push_back(std::move(r));
  }
  sqlite3_finalize(st);
  sqlite3_close(db);
  return out;
}


struct Run {
  opt::ConfigNode root;
  std::unique_ptr<opt::Problem> problem;
  opt::doe::DoeSpec spec;
};

Run parse(const std::string& yaml) {
  Run r{opt::ConfigNode::parse(yaml, "<doe>"), nullptr, {}};
  r.problem = opt::make_problem(r.root);
  for (const auto& e : opt::registry())
    if (e.name == r.problem->name()) r.spec = opt::doe::parse_doe(r.root, e.parameters, *r.problem);
  return r;
}

nlohmann::json run(const std::string& yaml, const std::string& dir, int threads,
                   const opt::doe::ProblemFactory& make = opt::make_problem, bool fresh = false,
                   opt::doe::Shard shard = {}, std::size_t segment_rows = 65536) {
  const Run r = parse(yaml);
  opt::doe::BatchOptions o;
  o.segment_rows = segment_rows;
  o.shard = shard;
  o.output_directory = dir;
  o.threads = threads;
  o.progress = "none";
  o.fresh = fresh;
  std::ostringstream out, err;
  return opt::doe::run_batch(r.root, make, r.spec, o, out, err);
}

// crank_radius and rod_length through x, crank_speed in the model (the
// problem is rebuilt per sample); the first factor varies slowest.
const char* kFactorial = R"(problem: slider_crank
study:
  type: doe
  factors:
    crank_radius: [0.1 m, 0.15 m, 0.2 m]
    rod_length: {min: 0.8 m, max: 1.2 m, count: 3}
    crank_speed: [5 rad/s, 10 rad/s]
)";

// Closed forms of the centred slider-crank (e = 0), r/l <= 1/4: stroke 2r;
// peak |x''| = r w^2 (1 + r/l), at the crank angle 0; max pressure angle
// asin(r/l), at 90 degrees.
TEST(DoeBatch, FactorialRowsMatchClosedForms) {
  const std::string dir = cli::fresh_dir("doe_factorial");
  const auto j = run(kFactorial, dir, 2);
  EXPECT_EQ(j["run_status"], "complete");
  const auto table = rows(dir, "idx, status, crank_radius, rod_length, crank_speed, stroke, "
                               "peak_slider_acceleration, max_pressure_angle");
  ASSERT_EQ(table.size(), 18u);
  const double radii[] = {0.1, 0.15, 0.2}, rods[] = {0.8, 1.0, 1.2}, speeds[] = {5, 10};
  for (size_t i = 0; i < table.size(); ++i) {
    const auto& t = table[i];
    const double r = radii[i / 6], l = rods[i / 2 % 3], w = speeds[i % 2];
    EXPECT_EQ(std::stoll(t[0]), static_cast<long long>(i));
    ASSERT_EQ(t[1], "ok") << i;
    EXPECT_DOUBLE_EQ(std::stod(t[2]), r);
    EXPECT_NEAR(std::stod(t[3]), l, 1e-15);
    EXPECT_DOUBLE_EQ(std::stod(t[4]), w);
    EXPECT_NEAR(std::stod(t[5]), 2 * r, 1e-12);
    EXPECT_NEAR(std::stod(t[6]), r * w * w * (1 + r / l), 1e-9 * r * w * w);
    EXPECT_NEAR(std::stod(t[7]), std::asin(r / l), 1e-12);
  }
}

// `columns` names what a row stores: those metrics with the objective's and
// the constraints' (the summary reads them back), in the problem's order, and
// the model computes nothing else. A metric computed alone has the same bits
// as computed beside every other (the run without `columns`, same samples).
TEST(DoeBatch, ColumnsAreWhatARowStores) {
  const std::string doe = R"(problem: recuperative_drive
objective: {minimize: mean_kinetic_energy}
constraints: {peak_crank_torque: {max: 3000 N m}}
study:
  type: doe
  sampler: sobol
  samples: 256
  factors: {rod_length: {min: 0.3 m, max: 1.6 m}, phase_shift: {min: 0 deg, max: 180 deg}}
)";
  const std::string all = cli::fresh_dir("doe_columns_all"), some = cli::fresh_dir("doe_columns_some");
  run(doe, all, 2);
  run(doe + "  columns: [k1]\n", some, 2);
  // The canonical dumps (%.17g: every double exactly) as header -> column.
  auto columns = [](const std::string& dir) {
    std::istringstream in(cli::canonical_dump(dir));
    std::vector<std::string> head, line;
    std::map<std::string, std::vector<std::string>> by_name;
    for (std::string row; std::getline(in, row);) {
      std::vector<std::string> cells;
      std::istringstream cs(row);
      for (std::string c; std::getline(cs, c, ',');) cells.push_back(c);
      if (head.empty()) head = cells;
      else
        for (size_t k = 0; k < cells.size() && k < head.size(); ++k) by_name[head[k]].push_back(cells[k]);
    }
    return std::make_pair(head, by_name);
  };
  const auto [head_some, some_rows] = columns(some);
  const auto [head_all, all_rows] = columns(all);
  EXPECT_EQ(head_some, (std::vector<std::string>{"idx", "status", "message", "rod_length", "phase_shift",
                                                  "mean_kinetic_energy", "k1", "peak_crank_torque"}));
  EXPECT_GT(head_all.size(), head_some.size() + 5) << "every metric without columns";
  for (const auto& name : head_some) EXPECT_EQ(some_rows.at(name), all_rows.at(name)) << name;
  ASSERT_EQ(some_rows.at("k1").size(), 256u);
}

// An infeasible design is a row with its status, never a crash.
TEST(DoeBatch, InfeasibleDesignsAreRows) {
  const std::string dir = cli::fresh_dir("doe_infeasible");
  run(R"(problem: slider_crank
study: {type: doe, factors: {crank_radius: [0.2 m, 0.9 m], rod_length: [0.8 m, 1 m]}}
)", dir, 1);
  const auto table = rows(dir, "status, stroke");
  ASSERT_EQ(table.size(), 4u);
  EXPECT_EQ(table[0][0], "ok");
  EXPECT_EQ(table[2][0], "cannot_assemble") << "r = 0.9 m cannot turn with l = 0.8 m";
  EXPECT_EQ(table[2][1], "") << "no metric for an infeasible design";
}

const char* kSobol = R"(problem: slider_crank
study:
  type: doe
  sampler: sobol
  samples: 512
  seed: 11
  factors:
    crank_radius: {min: 0.05 m, max: 0.25 m}
    rod_length: {min: 0.6 m, max: 1.4 m}
    crank_speed: {min: 5 rad/s, max: 15 rad/s}
)";

const char* kColumns = "idx, status, crank_radius, rod_length, crank_speed, stroke, peak_slider_acceleration";

// A sample's values depend on (seed, index) only: 1, 2 and 3 threads give
// stores whose canonical dumps (rows by index, %.17g, no wall times) are
// byte-identical.
TEST(DoeBatch, ThreadCountDoesNotChangeResults) {
  std::vector<std::string> dumps;
  for (int threads : {1, 2, 3}) {
    const std::string dir = cli::fresh_dir("doe_threads_" + std::to_string(threads));
    run(kSobol, dir, threads);
    dumps.push_back(cli::canonical_dump(dir));
  }
  EXPECT_EQ(std::count(dumps[0].begin(), dumps[0].end(), '\n'), 513) << "a header and 512 rows";
  EXPECT_EQ(dumps[0].rfind("idx,status,message,crank_radius,rod_length,crank_speed,", 0), 0u) << dumps[0].substr(0, 200);
  EXPECT_EQ(dumps[0], dumps[1]);
  EXPECT_EQ(dumps[0], dumps[2]);
}

// Small segments (3000 rows) and more threads than cores: each thread
// writes store.sqlite when it is free and a segment of its own when it is
// busy; the segments are closed and folded by the first thread as the run
// goes, the rest at its end, and no segment is left. Every row once, as
// one thread writes them.
TEST(DoeBatch, ThreadsWriteFilesOfTheirOwnFoldedIntoOne) {
  const char* yaml = R"(problem: slider_crank
study:
  type: doe
  sampler: sobol
  samples: 50000
  factors:
    crank_radius: {min: 0.05 m, max: 0.25 m}
    rod_length: {min: 0.6 m, max: 1.4 m}
)";
  std::vector<std::vector<std::vector<std::string>>> stores;
  for (int threads : {1, 5}) {
    const std::string dir = cli::fresh_dir("doe_turns_" + std::to_string(threads));
    const auto j = run(yaml, dir, threads, opt::make_problem, false, {}, 3000);
    EXPECT_EQ(j["evaluated"], 50000);
    EXPECT_EQ(j["run_status"], "complete");
    EXPECT_TRUE(cli::segment_files(dir).empty()) << threads << " threads";
    stores.push_back(rows(dir, "idx, status, crank_radius, rod_length, stroke, peak_slider_acceleration"));
  }
  ASSERT_EQ(stores[0].size(), 50000u);
  for (std::size_t i = 0; i < stores[0].size(); ++i) ASSERT_EQ(stores[0][i][0], std::to_string(i));
  EXPECT_TRUE(stores[0] == stores[1]);
}

// Stopped after some samples, run again: the second run evaluates only the
// rest, and the store equals an uninterrupted run's.
TEST(DoeBatch, StoppedRunResumesExactly) {
  const std::string whole = cli::fresh_dir("doe_whole"), parts = cli::fresh_dir("doe_parts");
  run(kSobol, whole, 2);
  std::atomic<int> made{0};
  const opt::doe::ProblemFactory stop_after_100 = [&](const opt::ConfigNode& root) {
    if (++made == 100) opt::request_stop();
    return opt::make_problem(root);
  };
  const auto first = run(kSobol, parts, 2, stop_after_100);
  opt::clear_stop();
  EXPECT_EQ(first["run_status"], "interrupted");
  const long done = first["done"].get<long>();
  EXPECT_GT(done, 50);
  EXPECT_LT(done, 512);
  const auto second = run(kSobol, parts, 2);
  EXPECT_EQ(second["run_status"], "complete");
  EXPECT_EQ(second["evaluated"].get<long>(), 512 - done) << "finished samples are not evaluated again";
  EXPECT_EQ(rows(parts, kColumns), rows(whole, kColumns));
}

// Another config against an existing store is refused, naming what differs;
// --new moves the old store aside.
TEST(DoeBatch, ChangedConfigIsRefused) {
  const std::string dir = cli::fresh_dir("doe_changed");
  run(kSobol, dir, 1);
  std::string changed = kSobol;
  changed.replace(changed.find("seed: 11"), 8, "seed: 12");
  try {
    run(changed, dir, 1);
    ADD_FAILURE() << "no exception";
  } catch (const opt::doe::StoreMismatch& e) {
    EXPECT_NE(std::string(e.what()).find("sampler"), std::string::npos) << e.what();
  }
  const auto j = run(changed, dir, 1, opt::make_problem, true);
  EXPECT_EQ(j["evaluated"], 512);
  bool moved = false;
  for (const auto& e : fs::directory_iterator(dir)) moved = moved || e.path().filename().string().rfind("store.sqlite.old-", 0) == 0;
  EXPECT_TRUE(moved);
}

// Shards of a job array: each writes its own store; merged, the three give
// the canonical dump of one run, byte for byte; `--shard auto` reads Slurm's
// array variables.
TEST(DoeBatch, ShardsMergeIntoOneRun) {
  const std::string whole = cli::fresh_dir("doe_shard_whole"), a = cli::fresh_dir("doe_shard_a"),
                    b = cli::fresh_dir("doe_shard_b"), c = cli::fresh_dir("doe_shard_c"),
                    merged = cli::fresh_dir("doe_shard_merged");
  run(kSobol, whole, 2);
  EXPECT_EQ(run(kSobol, a, 1, opt::make_problem, false, {0, 3})["done"], 170);  // [0, 170)
  EXPECT_EQ(run(kSobol, b, 2, opt::make_problem, false, {1, 3})["done"], 171);  // [170, 341)
  fs::create_directories(c);
  std::ofstream(c + "/config.yaml") << kSobol;
  const auto o = cli::run("run " + c + "/config.yaml --output " + c + " --progress=none --shard auto",
                          120);
  EXPECT_FALSE(o.exited(0)) << "no Slurm variables: refused";
  EXPECT_NE(o.output.find("SLURM_ARRAY_TASK_ID"), std::string::npos) << o.output;
  setenv("SLURM_ARRAY_TASK_ID", "9", 1);  // --array=7-9: the third of three tasks
  setenv("SLURM_ARRAY_TASK_MIN", "7", 1);
  setenv("SLURM_ARRAY_TASK_COUNT", "3", 1);
  const auto s = cli::run("run " + c + "/config.yaml --output " + c + " --progress=none --shard auto");
  for (const char* v : {"SLURM_ARRAY_TASK_ID", "SLURM_ARRAY_TASK_MIN", "SLURM_ARRAY_TASK_COUNT"}) unsetenv(v);
  ASSERT_TRUE(s.exited(0)) << s.output;
  EXPECT_NE(s.output.find("shard 2/3"), std::string::npos) << s.output;
  try {
    opt::doe::merge_stores(merged, {a, c});
    ADD_FAILURE() << "a missing third is not refused";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("171 indices missing: 170, 171,"), std::string::npos) << e.what();
  }
  fs::remove_all(merged);
  const auto report = opt::doe::merge_stores(merged, {a, b, c});
  EXPECT_EQ(report.rows, 512);
  EXPECT_EQ(cli::canonical_dump(merged), cli::canonical_dump(whole));
}

// A sample past the per-sample time limit is a row with status timed_out
// (the drive's integration checks the clock in its callbacks); the batch
// goes on. 1 us is far below one steady cycle's integration (~1 ms).
TEST(DoeBatch, SamplePastItsTimeLimitIsARow) {
  const std::string config = R"(problem: elastic_drive
model: {ode: {method: erk, rtol: 1e-8}}
study:
  type: doe
  factors: {stiffness: [60000 N m/rad, 110000 N m/rad]}
  sample_time_limit: LIMIT
)";
  auto with = [&](const std::string& limit) {
    std::string c = config;
    return c.replace(c.find("LIMIT"), 5, limit);
  };
  const std::string dir = cli::fresh_dir("doe_time_limit"), fine = cli::fresh_dir("doe_time_fine");
  const auto j = run(with("1 us"), dir, 2);
  EXPECT_EQ(j["run_status"], "complete");
  EXPECT_EQ(j["statuses"]["timed_out"], 2);
  const auto table = rows(dir, "status, message, peak_coupling_torque");
  ASSERT_EQ(table.size(), 2u);
  EXPECT_EQ(table[0][0], "timed_out");
  EXPECT_NE(table[0][1].find("time limit"), std::string::npos);
  EXPECT_EQ(table[0][2], "");
  EXPECT_EQ(run(with("60 s"), fine, 2)["statuses"]["ok"], 2) << "a generous limit changes nothing";
}

// Located errors for what a doe study cannot take.
TEST(DoeBatch, BadStudiesAreLocatedErrors) {
  auto error = [](const std::string& study) {
    try {
      parse("problem: slider_crank\nstudy: " + study + "\n");
    } catch (const opt::ConfigError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(error("{type: doe, factors: {crank_radus: [0.1 m]}}").find("no model value 'crank_radus'"),
            std::string::npos);
  EXPECT_NE(error("{type: doe, factors: {kinematics: {min: 0, max: 1}}}").find("expected a list of levels"),
            std::string::npos);
  EXPECT_NE(error("{type: doe, sampler: sobol, factors: {crank_radius: {min: 0.1 m, max: 0.2 m}}}")
                .find("needs samples"),
            std::string::npos);
  EXPECT_NE(error("{type: doe, factors: {crank_radius: {min: 0.1 m, max: 0.2 m}}}").find("count or step"),
            std::string::npos);
  EXPECT_NE(error("{type: doe, factors: {crank_radius: [-0.1 m]}}").find("<doe>:2:"), std::string::npos)
      << "outside the row's domain, located";
  EXPECT_NE(error("{type: doe, sampler: sobol, samples: 8, maximin: true, factors: {crank_radius: {min: 0.1 m, "
                  "max: 0.2 m}}}")
                .find("maximin goes with"),
            std::string::npos);
}

// --dry-run writes nothing and says what the store already holds, the time
// and the size; a run over the limit needs --force after it; a store of
// another config is bad input (exit 2) for a run and a dry run alike.
TEST(DoeBatch, DryRunShowsTheCostFirst) {
  const std::string dir = cli::fresh_dir("doe_dry");
  fs::create_directories(dir);
  std::string big = kSobol;
  big.replace(big.find("samples: 512"), 12, "samples: 2e7");
  std::ofstream(dir + "/big.yaml") << big;
  std::ofstream(dir + "/small.yaml") << kSobol;
  std::string other = kSobol;
  other.replace(other.find("seed: 11"), 8, "seed: 12");
  std::ofstream(dir + "/other.yaml") << other;

  auto o = cli::run("run " + dir + "/big.yaml --output " + dir + "/big");
  EXPECT_TRUE(o.exited(2)) << o.output;
  EXPECT_NE(o.output.find("big.yaml:5:12: key 'study.samples': 20000000 samples is more than 10000000: --dry-run"),
            std::string::npos) << o.output;
  o = cli::run("run " + dir + "/big.yaml --output " + dir + "/big --dry-run");
  EXPECT_TRUE(o.exited(0)) << o.output;
  for (const char* line : {"dry run: 20000000 samples, 0 already in", "20000000 to evaluate", "us a row in the store",
                           "estimated time:",
                           "estimated store size:", "more than 10000000 samples: run with --force to go ahead"})
    EXPECT_NE(o.output.find(line), std::string::npos) << line << "\n" << o.output;
  EXPECT_FALSE(fs::exists(dir + "/big")) << "a dry run writes nothing";

  o = cli::run("run " + dir + "/small.yaml --output " + dir + "/out --shard 0/2 --progress=none");
  ASSERT_TRUE(o.exited(0)) << o.output;
  o = cli::run("run " + dir + "/small.yaml --output " + dir + "/out --dry-run");
  EXPECT_NE(o.output.find("dry run: 512 samples, 256 already in " + dir + "/out/store.sqlite, 256 to evaluate"),
            std::string::npos) << o.output;
  o = cli::run("run " + dir + "/small.yaml --output " + dir + "/out --dry-run --new");
  EXPECT_NE(o.output.find("512 samples, 0 already in"), std::string::npos) << "--new would move the store aside\n"
                                                                              << o.output;
  EXPECT_EQ(cli::stored_rows(dir + "/out"), 256) << "the dry run moved nothing";
  for (const std::string flags : {"", " --dry-run"}) {
    o = cli::run("run " + dir + "/other.yaml --output " + dir + "/out --progress=none" + flags);
    EXPECT_TRUE(o.exited(2)) << flags << "\n" << o.output;
    EXPECT_NE(o.output.find("mechopt: error: " + dir + "/out/store.sqlite: written by another configuration"),
              std::string::npos) << o.output;
  }
}

// refine: local optimisations from the best feasible samples, recorded in
// the store's `refined` table. Reference: the seed-000 rod-length optimum
// l* = 0.60864008996547893 m with T_cp = 2390.1336147556022 J at 100 rpm
// (tools/reference_seed000.json, mpmath). T scales as w^2, so l* is the same
// at 200 rpm and T_cp four times larger: the crank speed, a model-value
// factor, must stay at each start's own value.
TEST(DoeBatch, RefineFromTheBestSamples) {
  const std::string dir = cli::fresh_dir("doe_refine");
  const std::string yaml = R"(problem: recuperative_drive
model: {crank_radius: 0.2 m, cart_mass: 1000 kg, rod_mass_per_length: 80 kg/m, efficiency: 0.9,
        cart_resistance: 3562 N, phase_shift: 90 deg, layout: opposed}
objective: {minimize: mean_kinetic_energy}
study:
  type: doe
  sampler: sobol
  samples: 64
  factors:
    rod_length: {min: 0.5 m, max: 1.5 m}
    crank_speed: [100 rpm, 200 rpm]
  refine: {best: 40, driver: {algorithm: LD_SLSQP, xtol_rel: 1e-12}}
)";
  auto refined = [&](const nlohmann::json& j) {
    std::vector<std::tuple<long, double, double, double, double>> out;  // start, speed, l, T_cp, seconds
    sqlite3* db = nullptr;
    sqlite3_open_v2((dir + "/store.sqlite").c_str(), &db, SQLITE_OPEN_READONLY, nullptr);
    sqlite3_stmt* st = nullptr;
    sqlite3_prepare_v2(db, "select start, crank_speed, rod_length, value, seconds from refined order by rank", -1, &st,
                       nullptr);
    while (st && sqlite3_step(st) == SQLITE_ROW)
      out.emplace_back(sqlite3_column_int64(st, 0), sqlite3_column_double(st, 1),
                       sqlite3_column_double(st, 2), sqlite3_column_double(st, 3), sqlite3_column_double(st, 4));
    sqlite3_finalize(st);
    sqlite3_close(db);
    EXPECT_EQ(j["refine"]["runs"].size(), out.size());
    return out;
  };
  const auto first = refined(run(yaml, dir, 2));
  ASSERT_EQ(first.size(), 40u) << "64 samples, all feasible";
  const double w100 = 100 * M_PI / 30;
  int fast = 0;
  for (const auto& [start, w, l, value, seconds] : first) {
    EXPECT_NEAR(l, 0.60864008996547893, 1e-7) << "start " << start;
    fast += std::abs(w - 2 * w100) < 1e-9;
    EXPECT_TRUE(std::abs(w - w100) < 1e-9 || std::abs(w - 2 * w100) < 1e-9) << w;
    EXPECT_NEAR(value, 2390.1336147556022 * (w / w100) * (w / w100), 1e-9 * value) << "start " << start;
  }
  EXPECT_GE(fast, 8) << "40 of 64 starts reach into the 200 rpm half";
  EXPECT_EQ(refined(run(yaml, dir, 2)), first) << "a rerun redoes no recorded run (same seconds)";
  std::string cobyla = yaml;
  cobyla.replace(cobyla.find("LD_SLSQP"), 8, "LN_COBYLA");
  const auto second = refined(run(cobyla, dir, 2));
  ASSERT_EQ(second.size(), 40u);
  EXPECT_NE(std::get<4>(second[0]), std::get<4>(first[0])) << "other refine settings: the runs are made afresh";

  auto error = [](const std::string& text) {
    try {
      parse(text);
    } catch (const opt::ConfigError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  std::string no_objective = yaml;
  no_objective.erase(no_objective.find("objective:"), no_objective.find("study:") - no_objective.find("objective:"));
  EXPECT_NE(error(no_objective).find("key 'study.refine': refine optimises the objective"), std::string::npos)
      << error(no_objective);
  std::string only_levels = yaml;
  only_levels.replace(only_levels.find("    rod_length: {min: 0.5 m, max: 1.5 m}\n"), 41, "");
  EXPECT_NE(error(only_levels).find("this study has none"), std::string::npos) << error(only_levels);
}

// `mechopt run CONFIG --output OUT --progress=none --threads 1` in a child
// process, its output discarded, for the tests that kill a run or start
// another beside it.
pid_t start_run(const std::string& config, const std::string& out, const char* threads = "1") {
  const pid_t pid = fork();
  if (pid == 0) {
    freopen("/dev/null", "w", stdout);
    freopen("/dev/null", "w", stderr);
    execl(MECHOPT_BINARY, "mechopt", "run", config.c_str(), "--output", out.c_str(), "--progress=none", "--threads",
          threads, static_cast<char*>(nullptr));
    _exit(127);
  }
  return pid;
}

// kSobol with `samples` samples, written to DIR/config.yaml.
std::string sobol_config(const std::string& dir, long samples) {
  fs::create_directories(dir);
  std::string yaml = kSobol;
  yaml.replace(yaml.find("samples: 512"), 12, "samples: " + std::to_string(samples));
  std::ofstream(dir + "/config.yaml") << yaml;
  return dir + "/config.yaml";
}

// Polls until OUT/store.sqlite holds more than `rows` rows (120 s at most).
void wait_for_rows(const std::string& out, long rows) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (std::chrono::steady_clock::now() < deadline && cli::stored_rows(out) <= rows)
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
}

// Whether OUT/store.lock exists and no process holds it: a run could write.
bool lock_is_free(const std::string& out) {
  const int fd = open((out + "/store.lock").c_str(), O_RDWR | O_CLOEXEC);
  if (fd < 0) return false;
  const bool free = flock(fd, LOCK_EX | LOCK_NB) == 0;
  close(fd);  // and the lock with it
  return free;
}

// Killed with SIGKILL at 20 moments (6 under ASan) drawn from a fixed seed, each after
// this round committed something and before the whole design was (the test
// checks both), resumed each time, on one thread and four in turn (whose
// rows go to segments when store.sqlite is busy; DoeStore.KilledWriter...
// leaves one for certain): the lock is free after each kill, whatever
// segments a kill left are folded by the next run, and the final store's
// canonical dump equals a run's that was never killed, every index once.
TEST(DoeBatch, SigkillAtTwentyMomentsLosesNothingCommitted) {
  const std::string dir = cli::fresh_dir("doe_kill"), clean = cli::fresh_dir("doe_kill_clean");
  // A round commits <= ~0.3 s of its threads' work; the rounds take under
  // half of a whole run's evaluations (13 s in Release, 15 s under ASan).
  constexpr long kSamples = cli::kSanitized ? 50000 : 200000;
  constexpr int kRounds = cli::kSanitized ? 6 : 20;
  const std::string config = sobol_config(dir, kSamples);
  std::mt19937 moments(20261123);
  long kept = 0;
  for (int k = 0; k < kRounds; ++k) {
    const pid_t pid = start_run(config, dir + "/out", k % 2 ? "4" : "1");
    // After a commit of this round, then 0-50 ms more: mid-batch or mid-commit.
    wait_for_rows(dir + "/out", kept);
    std::this_thread::sleep_for(std::chrono::milliseconds(std::uniform_int_distribution<int>(0, 50)(moments)));
    kill(pid, SIGKILL);
    int status = 0;
    waitpid(pid, &status, 0);
    ASSERT_TRUE(WIFSIGNALED(status)) << "round " << k << ": the run ended before it was killed";
    EXPECT_TRUE(lock_is_free(dir + "/out")) << "round " << k << ": the killed run left its lock held";
    const long now = cli::stored_rows(dir + "/out");
    EXPECT_GT(now, kept) << "round " << k << ": killed before anything was committed";
    ASSERT_LT(now, kSamples) << "round " << k << ": killed after everything was committed";
    kept = now;
  }
  // On a loaded machine, more than cli::run's 120 s.
  const auto again = cli::run("run " + config + " --output " + dir + "/out --progress=none", 600);
  ASSERT_TRUE(again.exited(0)) << again.output;
  EXPECT_NE(again.output.find("resuming: " + std::to_string(kept) + " done"), std::string::npos) << again.output;
  const auto resumed = rows(dir + "/out", "idx");
  ASSERT_EQ(resumed.size(), static_cast<size_t>(kSamples));
  for (long i = 0; i < kSamples; ++i) ASSERT_EQ(resumed[static_cast<size_t>(i)][0], std::to_string(i));
  EXPECT_TRUE(cli::segment_files(dir + "/out").empty());  // folded
  const auto ok = cli::run("run " + config + " --output " + clean + " --progress=none", 600);
  ASSERT_TRUE(ok.exited(0)) << ok.output;
  EXPECT_TRUE(cli::canonical_dump(dir + "/out") == cli::canonical_dump(clean));
}

// Two runs on one output directory at once: the second is refused before it
// evaluates anything (exit 2), naming the first by pid, host and start time;
// a reader exports the store meanwhile (rows the store ends with); the first
// ends complete, with the canonical dump of a run alone.
TEST(DoeBatch, SecondRunOnAStoreInUseIsRefused) {
  const std::string dir = cli::fresh_dir("doe_busy"), clean = cli::fresh_dir("doe_busy_clean");
  // One thread: seconds (7 s in Release, 7 s under ASan), so the first is still running.
  constexpr long kSamples = cli::kSanitized ? 25000 : 100000;
  const std::string config = sobol_config(dir, kSamples);
  const pid_t first = start_run(config, dir + "/out");
  wait_for_rows(dir + "/out", 0);
  const auto second = cli::run("run " + config + " --output " + dir + "/out --progress=none --threads 1");
  const auto reader = cli::run("export " + dir + "/out/store.sqlite --canonical");
  int status = 0;
  ASSERT_EQ(waitpid(first, &status, WNOHANG), 0) << "the first run ended before the second was tried";
  EXPECT_TRUE(second.exited(2)) << second.output;
  EXPECT_NE(second.output.find("pid " + std::to_string(first) + ", host "), std::string::npos) << second.output;
  EXPECT_NE(second.output.find(", started 20"), std::string::npos) << second.output;
  EXPECT_EQ(second.output.find("samples to evaluate"), std::string::npos) << second.output;
  EXPECT_TRUE(reader.exited(0)) << reader.output.substr(0, 1000);
  waitpid(first, &status, 0);
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "the first run: status " << status;
  const auto ok = cli::run("run " + config + " --output " + clean + " --progress=none");
  ASSERT_TRUE(ok.exited(0)) << ok.output;
  const std::string dump = cli::canonical_dump(dir + "/out");
  EXPECT_TRUE(dump == cli::canonical_dump(clean));
  // Both by index: each line the reader saw is a line of the end's, in order.
  std::istringstream seen(reader.output), end(dump);
  long lines = 0;
  std::string at;
  for (std::string line; std::getline(seen, line); ++lines) {
    while (at != line && std::getline(end, at)) {
    }
    ASSERT_EQ(at, line) << "the reader saw a row the store does not end with";
  }
  EXPECT_GT(lines, 1) << "the reader saw no rows";
}

// Progress as JSON lines for scripts; the last line says finished.
TEST(DoeBatch, ProgressAsJsonLines) {
  const std::string dir = cli::fresh_dir("doe_progress");
  fs::create_directories(dir);
  std::ofstream(dir + "/config.yaml") << kSobol;
  const auto o = cli::run("run " + dir + "/config.yaml --output " + dir + "/out --progress=jsonl --threads 2");
  ASSERT_TRUE(o.exited(0)) << o.output;
  nlohmann::json last;
  std::istringstream lines(o.output);
  for (std::string line; std::getline(lines, line);)
    if (!line.empty() && line[0] == '{') last = nlohmann::json::parse(line);
  EXPECT_EQ(last["event"], "finished");
  EXPECT_EQ(last["done"], 512);
  EXPECT_EQ(last["failures"], 0);
}

}  // namespace
