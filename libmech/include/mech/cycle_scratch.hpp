// The scratch of the cycle computations: what find_cycle_maxima,
// piecewise_means, swing_metrics and cycle_metrics reuse from one design to
// the next (a batch evaluates millions of designs; an allocation a search
// cost a DOE design 3%), with the search's inputs and outputs
// (CycleMaxSearch, AngleQuery). Whoever evaluates owns one (a problem's
// workspace, opt/model_problem.hpp) and passes it down; two computations
// under way at once need two.
#pragma once
#include <cmath>
#include <span>
#include <vector>

#include "mech/grow.hpp"
#include "mech/roots.hpp"

namespace mech {

// One evaluation a batched search asks for: f of search `fn` at the angle
// phi, or its angle derivative (slope); the evaluator writes `out`.
struct AngleQuery {
  double phi;
  int fn;
  bool slope;
  double out = 0;
};

// The maxima over the cycle of a periodic f sampled as v[k] = f(2 pi k / n),
// found by find_cycle_maxima (mech/cycle_maxima.hpp). `kinks`: the angles
// where f has kinks (a slider's dead centres for |M|); `slopes`: df on the
// grid, where the caller has it (its evaluations saved).
struct CycleMaxSearch {
  std::span<const double> v, kinks = {}, slopes = {};
  // A global search's: angles that hold every local maximum of f (a
  // closed form's: where f stands still), or empty (find_cycle_maxima).
  std::span<const double> known = {};
  bool global = true;        // the global maximum; else every local one within `margin`
  double margin = HUGE_VAL;  // local ones: no lower than max(v) - margin
  std::vector<double> maxima;  // out: the refined local maxima, sorted by angle
  double phi = 0;              // out (global): the angle of the largest value
  double value = 0;            // out (global): f there, as eval answered it (or the grid's)

  // A global search of these inputs, the maxima's storage kept: a model
  // that searches every design keeps its searches in a CycleScratch.
  void reset(std::span<const double> values, std::span<const double> kinks_of_f = {},
             std::span<const double> slopes_of_f = {}) {
    v = values, kinks = kinks_of_f, slopes = slopes_of_f, known = {};
    global = true, margin = HUGE_VAL;
    maxima.clear();
    phi = value = 0;
  }
};

struct CycleScratch {
  // find_cycle_maxima's lists: its queries, the points around each grid
  // maximum, the candidates, the roots (and their searches), the cells
  // beside kinks.
  struct Point {
    double x, g;
    int query = -1;     // g comes from this query
    bool kink = false;  // eps beside a kink (f's pieces part between two such points)
  };
  struct Candidate {
    int fn;
    double phi_k;
    int first, count;  // its points: phi_k -+ h, phi_k, and kink -+ eps
    int quarter = -1;  // the 4-part search's first query
  };
  struct Root {  // a maximum: known, or where a root search ends
    int fn;
    double phi;
    int search = -1;  // its root search, if any
  };
  struct Bracket {  // a cell beside a kink
    int fn;
    Point a, b;
  };
  struct Known {  // a global search's known maximum, its value asked with the first batch
    int fn;
    double phi;
    int query;
    double f = 0;
  };
  Grow<AngleQuery> batch;
  Grow<Point> points;
  Grow<Candidate> cands;
  Grow<Root> roots, beside_roots;
  Grow<Bracket> beside;
  Grow<Known> known;
  Grow<int> kink_queries, root_fn, tops;
  Grow<double> kink_f;
  Grow<LaneRootSearch> roots_searched;

  // piecewise_means: the arcs' ends, sorted.
  std::vector<double> ends;
  // swing_metrics and cycle_metrics: the grids of the searched functions,
  // the kinks of M, and the two searches.
  std::vector<double> grids, kinks;
  CycleMaxSearch searches[2];
};

}  // namespace mech
