// The words of a problem file: the base classes (opt/model_problem.hpp), the
// registration (opt/registry.hpp) and the rows of a parameter table.
#pragma once
#include "opt/model_problem.hpp"
#include "opt/parameters.hpp"
#include "opt/registry.hpp"

namespace problems {

using opt::choice;
using opt::Dimension;
using opt::kAnyValue;
using opt::kNonNegative;
using opt::kPositive;
using opt::MetricSink;
using opt::MetricSpec;
using opt::ModelProblem;
using opt::quantity;
using opt::TabledProblem;
using opt::variable;
using opt::whole;

}  // namespace problems
