// The command line's usage and each command's help (`mechopt COMMAND
// --help`), for app/main.cpp.
#pragma once

namespace {

const char* kUsage = R"(mechopt — optimisation of planar mechanisms of heavy machines

usage:
  mechopt run CONFIG [--output DIR]       run the config's study; writes DIR/result.json,
                                          DIR/sweep.csv (sweeps) and DIR/chart.svg
      a doe study (docs/doe.md) writes DIR/store.sqlite and resumes it when run again:
      [--threads N] [--progress bar|jsonl|none] [--new] [--force] [--dry-run] [--shard I/N|auto]
  mechopt export STORE --csv|--json|--canonical
                                          a results store's rows on stdout (--canonical: the
                                          CSV without wall times, equal for equal results)
  mechopt merge OUT STORE...              shard stores into OUT/store.sqlite, checking that
                                          their configs agree and no sample is missing or doubled
  mechopt check STORE                     SQLite's integrity check, every row's checksum, every
                                          sample index once, counts by status, the config hash;
                                          exit 0 when sound, 1 with what is wrong
  mechopt recover STORE OUT               every readable, intact row of a damaged store (and its
                                          meta) into OUT/store.sqlite; running the config on OUT
                                          evaluates only the samples that were lost
  mechopt eval CONFIG [--set KEY=VALUE]   every metric at the config's model values as JSON
                                          (a variable at its initial); --set overrides
                                          model.KEY and a variable's initial (VALUE may carry a unit)
  mechopt check-derivatives CONFIG [--set KEY=VALUE]
                                          every metric's gradient (autodiff) against central
                                          differences at the model values, per variable
  mechopt kinematics CONFIG [--angles "0,37,90 deg"] [--svg FILE]
                                          a linkage's points, links, torque and energy at
                                          crank angles, as JSON; --svg draws it (docs/linkage.md)
  mechopt dakota PARAMS RESULTS --config CONFIG
                                          Dakota's analysis driver: the config's problem at
                                          Dakota's parameters file, its results file written
                                          (values, exact gradients; docs/interfaces.md)
  mechopt list [--markdown]               problems (every model key with its default, domain
                                          and source; variables; metrics) and algorithms
  mechopt COMMAND --help                  a command's arguments and options
  mechopt --help | --version

exit codes: 0 done, 1 runtime failure (or a derivative mismatch), 2 bad input (or an
  output directory whose store another run is writing),
  130/143 stopped by SIGINT/SIGTERM (what was done is written, marked interrupted)
)";

// `mechopt COMMAND --help`: each command's arguments and options.
struct Command {
  const char* name;
  const char* help;
};
const Command kCommands[] = {
    {"run", R"(usage: mechopt run CONFIG [options]

Runs the config's study and writes DIR/result.json with the study's files
(sweep.csv, history.csv, charts). A doe study (docs/doe.md) writes
DIR/store.sqlite and resumes it when run again; a sweep does too.

arguments:
  CONFIG                  the YAML config (keys: docs/config.md)

options:
  --output DIR            the output directory (default: the config's output.directory)
  --threads N             threads of a doe, a sweep or a pagmo front, 1 to 4096 (default: every core)
  --force                 a doe or sweep of more than 10^7 samples
  --progress bar|jsonl|none
                          doe: progress on stderr (default: a bar on a terminal, else jsonl)
  --new                   doe: move the existing store aside and start afresh
  --dry-run               doe: estimate the time and the store's size; writes nothing
  --shard I/N|auto        doe: run piece I of N into its own store (auto: from a Slurm
                          job array's SLURM_ARRAY_TASK_ID, _MIN and _COUNT)
  -h, --help              this help
)"},
    {"kinematics", R"(usage: mechopt kinematics CONFIG [--angles LIST] [--svg FILE]

Prints a `problem: linkage` config's mechanism at its model values as JSON
(SI): every point's position, velocity and acceleration, every link's angle,
rate and acceleration, each slider's motion along its line, the groups'
transmission and pressure angles, the driving torque and kinetic energy.

options:
  --angles LIST           crank angles, e.g. "0,37,90 deg" (a unit after the
                          last applies to those without one); default every 30 deg
  --svg FILE              also draws the mechanism at those angles into FILE (SVG)
  -h, --help              this help
)"},
    {"eval", R"(usage: mechopt eval CONFIG [--set KEY=VALUE]...

Prints every metric at the config's model values as JSON (SI), a variable at
its initial value.

arguments:
  CONFIG                  the YAML config

options:
  --set KEY=VALUE         sets model.KEY (a dotted KEY walks the model: ground.O4.x), and the
                          initial value of a variable KEY (VALUE may carry a unit:
                          --set rod_length=800mm); repeatable
  -h, --help              this help
)"},
    {"check-derivatives", R"(usage: mechopt check-derivatives CONFIG [--set KEY=VALUE]...

Compares every metric's gradient (autodiff) with central differences at the
model values, per variable; exit 1 on a mismatch.

arguments:
  CONFIG                  the YAML config, with at least one variable

options:
  --set KEY=VALUE         sets model.KEY, and the initial value of a variable KEY; repeatable
  -h, --help              this help
)"},
    {"export", R"(usage: mechopt export STORE --csv|--json|--canonical

Writes a doe store's rows on stdout, in SI.

arguments:
  STORE                   a store.sqlite file

options:
  --csv                   CSV, one row per sample, with wall times
  --json                  JSON
  --canonical             the CSV without wall times, rows by index, every number exact:
                          equal bytes for equal results whatever threads, ranks or shards
  -h, --help              this help
)"},
    {"merge", R"(usage: mechopt merge OUT STORE...

Merges shard stores into OUT/store.sqlite, checking that their configs agree
and that no sample is missing or doubled.

arguments:
  OUT                     the output directory
  STORE...                the shards' store.sqlite files

options:
  -h, --help              this help
)"},
    {"check", R"(usage: mechopt check STORE

Checks a doe store: SQLite's integrity check, every row's checksum, every
sample index once and within the run, counts by status, the config hash.
Reads only; a store that a run is writing can be checked.

arguments:
  STORE                   a store.sqlite file (or the directory holding it)

options:
  -h, --help              this help

exit codes: 0 sound, 1 damaged (what is wrong is printed), 2 bad arguments
)"},
    {"recover", R"(usage: mechopt recover STORE OUT

Copies every readable row whose checksum holds, and the readable meta, of a
damaged store into OUT/store.sqlite. Running the config with OUT as its
output directory then evaluates only the samples that were lost.

arguments:
  STORE                   the damaged store.sqlite file (or its directory)
  OUT                     a directory with no store yet

options:
  -h, --help              this help

exit codes: 0 recovered, 1 nothing could be saved (e.g. the first page is
damaged), 2 bad arguments
)"},
    {"dakota", R"(usage: mechopt dakota PARAMS RESULTS --config CONFIG

Dakota's analysis driver (a fork or system interface, docs/interfaces.md):
reads Dakota's parameters file PARAMS (standard or APREPRO format),
evaluates CONFIG's problem at its variables (by descriptor; SI values) and
writes RESULTS: each function's value (the metric its descriptor names, or
the config's objective, inequality and equality constraints in that
order), then the gradients asked for (exact, autodiff), or FAIL when the
design's status is not ok. A Hessian asked for is refused (exit 2).

options:
  --config CONFIG         the config whose problem (and objective and constraints) Dakota drives
  -h, --help              this help
)"},
    {"list", R"(usage: mechopt list [--markdown]

Lists the problems (every model key with its default, domain and source;
variables; metrics) and the drivers' algorithms.

options:
  --markdown              the config reference of docs/config.md, as Markdown
  -h, --help              this help
)"},
};

}  // namespace
