// The one way studies write evaluated designs. A Recorder takes one row per
// evaluated design (its index, variables, status and values in a fixed
// column order) and is closed once at the end; sweeps, driver histories and
// Pareto fronts all write through it (CSV here; a results store is one more
// Recorder). Files appear whole or not at all: rows go to FILE.partial and
// become FILE when closed, so a killed run leaves FILE.partial, never a
// truncated FILE.
#pragma once
#include <Eigen/Core>
#include <fstream>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace opt {

struct RecordLayout {
  std::string index;                   // the index column ("point", "evaluation")
  std::vector<std::string> variables;  // columns of x
  std::vector<std::string> values;     // columns of the values
};

struct Record {
  long index = 0;
  const Eigen::VectorXd& x;
  std::string_view status;
  std::span<const double> values;  // in the layout's order; NaN: not computed
};

class Recorder {
 public:
  virtual ~Recorder() = default;
  virtual void record(const Record& r) = 0;
  // Once, at the end: `complete`, or stopped early with the rows so far.
  virtual void close(bool complete) = 0;
};

// A CSV file with a header row; every row is flushed as it is written.
// Values print with 17 significant digits; NaN as an empty cell.
class CsvRecorder final : public Recorder {
 public:
  CsvRecorder(std::string file, const RecordLayout& layout);
  ~CsvRecorder() override;  // a recorder not closed keeps FILE.partial
  void record(const Record& r) override;
  void close(bool complete) override;

 private:
  std::string file_;
  std::ofstream out_;
  bool open_ = true;
};

// Writes `text` to FILE.partial, then renames it to FILE.
void write_file_atomically(const std::string& file, const std::string& text);

// Removes what an earlier mechopt run wrote into dir (result.json, its CSV
// and SVG files, partial files), and nothing else, so that a new run's output
// never sits beside a stale result.
void remove_previous_outputs(const std::string& dir);

}  // namespace opt
