#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iomanip>
#include <stdexcept>

#include "opt/record.hpp"

namespace opt {
namespace fs = std::filesystem;

CsvRecorder::CsvRecorder(std::string file, const RecordLayout& layout)
    : file_(std::move(file)), out_(file_ + ".partial") {
  if (!out_) throw std::runtime_error("cannot write " + file_ + ".partial");
  out_ << layout.index;
  for (const auto& v : layout.variables) out_ << "," << v;
  out_ << ",status";
  for (const auto& v : layout.values) out_ << "," << v;
  out_ << "\n" << std::setprecision(17);
}

CsvRecorder::~CsvRecorder() { out_.flush(); }

void CsvRecorder::record(const Record& r) {
  out_ << r.index;
  for (int i = 0; i < r.x.size(); ++i) out_ << "," << r.x[i];
  out_ << "," << r.status;
  for (double v : r.values) {
    out_ << ",";
    if (std::isfinite(v)) out_ << v;
  }
  out_ << std::endl;  // flushed: an interrupted run keeps its rows
}

void CsvRecorder::close(bool) {
  if (!open_) return;
  open_ = false;
  out_.close();
  fs::rename(file_ + ".partial", file_);
}

void write_file_atomically(const std::string& file, const std::string& text) {
  {
    std::ofstream out(file + ".partial");
    out << text;
    if (!out.flush()) throw std::runtime_error("cannot write " + file + ".partial");
  }
  fs::rename(file + ".partial", file);
}

void remove_previous_outputs(const std::string& dir) {
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    const bool ours = name == "result.json" || name == "sweep.csv" || name == "history.csv" ||
                      name == "pareto.csv" || name == "generations.csv" || name == "cycle.csv" || name == "cycle.svg" || name == "mechanism.svg" ||
                      name == "pareto.svg" || ((name.rfind("chart", 0) == 0 || name.rfind("main_effects_", 0) == 0) && e.path().extension() == ".svg") ||
                      e.path().extension() == ".partial";
    if (ours && e.is_regular_file()) fs::remove(e.path(), ec);
  }
}

}  // namespace opt
