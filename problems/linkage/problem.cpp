// linkage: any single-degree-of-freedom planar linkage a config describes
// (a crank and class II groups: docs/design/linkage.md), sized for its
// outputs' motion, transmission and pressure angles and, with masses or
// loads, its driving torque, energy and joint forces at constant crank
// speed. Every number is a row of the table (variables and DOE factors by
// address); metrics are named by the description's outputs and joints.
//
// At a design: the chain on an n-point grid (a group that cannot assemble
// is cannot_assemble, named); each group's distance from a singular
// position refined to its cycle minimum (below 1e-6: singular_position);
// then every wanted maximum by the hand-written problems' cycle machinery,
// its slope from the jets (the torque's from the third derivatives,
// third.hpp, or the chain on a Dual in phi where a group has none), its
// design gradient (Danskin) from the chain at its angle on the lane form
// of the evaluation's scalar (solve_maxima).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "mech/cycle.hpp"
#include "mech/linkage/dynamics.hpp"
#include "mech/linkage/third.hpp"
#include "problems/linkage/description.hpp"
#include "problems/linkage/drawing.hpp"
#include "problems/linkage/kinks.hpp"
#include "problems/linkage/means.hpp"
#include "problems/linkage/metrics.hpp"
#include "problems/linkage/quantity.hpp"
#include "problems/model_problem.hpp"

namespace problems::linkage {
namespace {

using mech::Dual;
using mech::linkage::Chain;
using mech::linkage::Jet;
using mech::linkage::kNone;
using mech::linkage::State;

// A group closer than this to a singular position (the sine measure of
// kinematics.hpp) is singular_position.
constexpr double kSingular = 1e-6;

// The grid of `cycle_points: auto` (grid_points): kAutoFirst points, or
// kAutoLast where the poles are near.
constexpr int kAutoFirst = 32, kAutoLast = 64;

class LinkageProblem : public ModelProblem<LinkageProblem> {
 public:
  LinkageProblem(Description d, std::vector<Metric> metrics, opt::Values<double> values,
                 std::vector<opt::Variable> vars)
      : ModelProblem("linkage", specs_of(metrics), d.table, std::move(values), std::move(vars)),
        d_(std::move(d)), metrics_(std::move(metrics)), masses_(moving_masses(d_)) {
    for (const auto& l : d_.chain.loads()) has_law_ = has_law_ || l.law_a != kNone;
  }

  nlohmann::json settings() const override {
    nlohmann::json groups = nlohmann::json::array();
    for (size_t g = 0; g < d_.chain.groups().size(); ++g)
      groups.push_back({{"group", d_.chain.group_name(static_cast<int>(g))},
                        {"branch", d_.chain.groups()[g].branch}});
    return {{"model", model_json()},
            {"groups", groups},
            {"numerics",
             {{"cycle_points", d_.cycle_points ? nlohmann::json(d_.cycle_points) : nlohmann::json("auto")},
              {"kinematics", "closed form per class II group on second-order jets in the crank angle"},
              {"maximum",
               "grid bracket + root of the angle derivative (jets; the torque's from third derivatives or the "
               "chain on a Dual in phi); Danskin gradients"},
              {"singular", "each group's sine measure refined to its cycle minimum; below 1e-6: singular_position"}}},
            {"units", "SI (m, rad, rad/s, kg, N, N m, J)"}};
  }

  // The driving torque and its loads' share, the kinetic energy and the
  // outputs' coordinates over a revolution (cycle.svg draws the torques).
  opt::CycleCurves cycle_curves(const Eigen::VectorXd& x, int n) const override {
    std::vector<double> v = values_at(x), plain, grid;
    State<double> sd;
    sd.resize(d_.chain);
    if (!d_.derived.empty()) placed(d_.chain, d_.mean_points(), v, plain, grid, sd);
    return linkage::cycle_curves(d_, v, n);
  }
  // mechanism.svg: the design at six crank angles with its points' paths.
  std::string mechanism_svg(const Eigen::VectorXd& x, const std::string& label) const override {
    return linkage::mechanism_svg(d_, values_at(x), drawn_angles(), "linkage: the mechanism at " + label);
  }

  struct Workspace : opt::ModelWorkspace {
    State<double> sd;
    std::vector<State<double>> grid;  // the chain at the grid's angles (GridStates)
    State<Dual> sdual;
    std::vector<double> plain;  // the values as doubles
    std::vector<Dual> vdual;    // ... as Duals (their slope: the crank angle's)
    std::vector<double> grids;
    std::vector<double> slopes;  // their slopes, where solve_grid gives them (grid_slopes)
    ZeroScratch zeros;  // the kinks' roots' (kinks.hpp), output_stops' for this design
    std::vector<std::pair<int, int>> held;  // per search: the load and side of a maximum at a switch (hold_switches)
    std::vector<std::pair<double, int>> switches;  // the loads' switches: angle, load (find_kinks)
    bool switches_found = false;                   // ... found in this evaluation
    std::vector<double> kinks;  // the torque's and the forces' kinks: contacts, tables' rows, switches
    std::vector<MovingKink> moving;         // the contacts and rows crossed, which move with the design
    std::vector<double> ref;  // each output's direction at phi = 0 (x, y, its angle)
    std::vector<Contact> contacts;     // the pressure laws' contacts
    std::vector<double> contact_grid;  // scratch
    std::vector<mech::CycleMaxSearch> searches;
    std::vector<mech::NearPole> near;  // the poles (poles(); grid_points' where it keeps its grid)
    bool near_known = false;           // ... found for this evaluation's grid
    std::vector<size_t> wanted;  // the metrics wanted, by index (evaluate_model's plan)
    uint64_t wanted_bits = 0;    // ... as bits
    bool planned = false;
    std::vector<Quantity> asked;  // ... the quantities they ask
    mech::CycleScratch cycle;
    std::optional<mech::linkage::LaneSolver<double>> lanes;  // the grid's chain, kLanes angles at a time
    std::optional<mech::linkage::LaneSolver<Dual>> dual_lanes;  // ... on Duals (in phi), once asked
    bool dual_set = false;                                       // ... at this evaluation's values
    std::vector<mech::AngleQuery*> lane_queries, dual_queries;  // run_searches' blocks
    std::vector<double> lane_angles;  // ... the lane queries' angles, each once
    std::vector<size_t> lane_of;      // ... each lane query's in lane_angles
    std::vector<size_t> by_block, block_end;  // ... the queries block by block (run_searches)
    // ... their blocks of this evaluation, kept on a value where loads
    // switch: the loads' arc ends take the chain from them (work.hpp).
    SolvedBlocks<mech::Lanes> searched;
    bool keep_searched = false;
    mech::linkage::Thirds<mech::Lanes> thirds;                  // ... the third derivatives
    ScalarScratches scalar;
    std::vector<size_t> mirror;   // the row of each asked coordinate's other sign (other_signs)
    std::vector<double> known;    // the outputs' stops (known_extremes)
    // The grid's angles, block by block, with the crank's cosines and sines
    // there (crank_cos_sin), kept while the phase and the grid are.
    std::vector<std::array<mech::Lanes, 3>> grid_cs;
    double grid_phase = 0;
    int grid_n = 0;
    std::vector<State<mech::Lanes>> blocks;  // the grid's chain, kLanes angles a block (solve_grid)
    std::vector<char> scattered;             // ... block b's states in `grid` already
    // The grid's states as scalars, each block's lanes scattered into
    // `grid` when first asked (a pass that reads none costs none).
    GridStates states() {
      for (size_t b = 0; b < scattered.size(); ++b) scatter(b);
      return grid;
    }
    void scatter(size_t b) {
      if (scattered[b]) return;
      const size_t k = b * mech::kLanes, m = std::min<size_t>(mech::kLanes, grid.size() - k);
      for (size_t j = 0; j < m; ++j) mech::linkage::lane_state(blocks[b], static_cast<int>(j), grid[k + j]);
      scattered[b] = 1;
    }
  };

  template <class S>
  void evaluate_model(const opt::Values<S>& given, MetricSink<S>& out, Workspace& ws) const {
    const Chain& c = d_.chain;
    int n = d_.cycle_points ? d_.cycle_points : kAutoFirst;
    if (ws.sd.point.size() != c.point_names().size()) {
      ws.sd.resize(c);
      ws.sdual.resize(c);
      ws.thirds.resize(c);
    }
    // The wanted metrics (ws.wanted), every quantity they ask on the grid
    // (ws.asked: the groups' margins, then the metrics') and each asked
    // coordinate's other sign (ws.mirror), kept while the same are wanted.
    const size_t n_margins = c.groups().size();
    uint64_t wanted = 0;  // bit m: metric m (at most opt::MetricSet::kMax of them)
    for (size_t m = 0; m < metrics_.size(); ++m) wanted |= uint64_t{out.want(static_cast<int>(m))} << m;
    if (!ws.planned || wanted != ws.wanted_bits) {
      ws.wanted.clear(), ws.asked.clear();
      for (size_t g = 0; g < n_margins; ++g) ws.asked.push_back({Kind::margin, static_cast<int>(g)});
      for (size_t m = 0; m < metrics_.size(); ++m) {
        if (!out.want(static_cast<int>(m))) continue;
        ws.wanted.push_back(m);
        ask(d_, masses_, metrics_[m], ws.asked);
      }
      other_signs(ws.asked, ws.mirror);
      ws.wanted_bits = wanted, ws.planned = true;
    }
    const size_t nq = ws.asked.size();
    opt::Values<S> placed;  // with the contacts of the laws given by their depth
    const opt::Values<S>& v =
        d_.derived.empty() ? given
                           : linkage::placed(c, d_.mean_points(), placed = given, ws.plain, ws.contact_grid, ws.sd);
    for (size_t m : ws.wanted)  // defined for every design: a driver's constraint
      if (metrics_[m].form == Form::grashof) out.put(static_cast<int>(m), grashof_margin(c, metrics_[m].q.index, v.data()));
    ws.plain.resize(v.size());
    ws.vdual.resize(v.size());
    ws.zeros.stops.clear();  // (another design's)
    ws.keep_searched = std::is_same_v<S, double> && switches_;
    std::get<ScalarScratch<S>>(ws.scalar).lanes_set = false;
    for (size_t i = 0; i < v.size(); ++i) ws.vdual[i] = Dual(ws.plain[i] = mech::value(v[i]));
    const double* vd = ws.plain.data();
    // The rockers' reference directions, at phi = 0 (a slider needs none;
    // where the chain cannot assemble there, the grid's first angle says
    // so as this would).
    ws.ref.assign(3 * d_.outputs.size(), 0.0);
    if (has_rocker_) {
      if (!solve_at(vd, 0.0, ws.sd, out)) return;
      for (size_t o = 0; o < d_.outputs.size(); ++o) {
        const auto& e = ws.sd.axis[static_cast<size_t>(d_.outputs[o].link)];
        ws.ref[3 * o] = e.x.v, ws.ref[3 * o + 1] = e.y.v, ws.ref[3 * o + 2] = std::atan2(e.y.v, e.x.v);
      }
    }
    size_t un;
    ws.near_known = false;
    while (true) {  // under auto, a second grid where the first's poles ask for more points
      un = static_cast<size_t>(n);
      ws.grids.resize(nq * un);
      ws.slopes.resize(nq * un);
      if (!solve_grid(vd, n, out, ws)) return;
      const int more = d_.cycle_points || n != kAutoFirst ? n : grid_points(ws, n_margins);
      if (more == n) break;
      n = more;
    }
    // Maxima, their slopes from the chain on a Dual in phi: first the
    // margins (a singular design stops there), then the metrics' (those
    // whose slopes the jets give take the grid's: solve_grid).
    ws.searches.resize(nq);
    for (size_t q = 0; q < nq; ++q)
      ws.searches[q].reset(std::span<const double>(ws.grids.data() + q * un, un), {},
                           grid_slopes(ws.asked[q].kind) ? std::span<const double>(ws.slopes.data() + q * un, un)
                                                         : std::span<const double>{});
    known_extremes(vd, n, ws);
    find_kinks(ws, n_margins);
    auto search = [&](size_t from, size_t to) { run_searches(ws, from, to); };
    // A group whose grid keeps it clear of a singular position by more than
    // twice what the margin can dip between grid points (h^2 |f''| / 8,
    // f'' from the largest second difference, as find_cycle_maxima bounds
    // a peak) needs no refined search.
    bool near_singular = false;
    for (size_t g = 0; g < n_margins; ++g) {
      const auto [top, bend] = mech::max_and_curvature(ws.searches[g].v);
      ws.searches[g].value = top + bend / 4;  // an upper bound of the refined maximum
      near_singular = near_singular || ws.searches[g].value > -kSingular * kSingular;
    }
    if (near_singular) search(0, n_margins);
    for (size_t g = 0; g < n_margins; ++g) {
      const auto& s = ws.searches[g];
      if (s.value <= -kSingular * kSingular) continue;
      const bool assembles = mech::linkage::solve(c, vd, s.phi, ws.sd);
      out.result.status = assembles ? mech::Status::singular_position : mech::Status::cannot_assemble;
      out.result.message = c.group_name(assembles ? static_cast<int>(g) : ws.sd.failed) +
                           (assembles ? " passes a singular position" : " cannot assemble") + " at crank angle " +
                           degrees(s.phi) + " deg";
      return;
    }
    search(n_margins, nq);
    hold_switches(ws, n_margins);
    // The metrics: each maximum as the search found it (double), or the
    // quantity at the maximising angle on S (Danskin), the chain there on
    // lanes where S has them (solve_maxima).
    auto& kept = std::get<ScalarScratch<S>>(ws.scalar);
    if constexpr (mech::is_dual<S>) {
      kept.tops.assign(nq, std::nullopt);
      kept.angles.assign(nq, std::nullopt);
      kept.solved.assign(nq, 0);
      if constexpr (mech::has_lanes<S>) solve_maxima(v, n_margins, ws, kept);
    }
    State<S> ss;
    auto solved_at = [&](size_t q) -> const State<S>& {  // the chain on S at search q's angle
      if constexpr (mech::is_dual<S>)
        if (kept.solved[q]) return kept.maxima[q];
      if (ss.point.size() != c.point_names().size()) ss.resize(c);
      mech::linkage::solve(c, v.data(), S(ws.searches[q].phi), ss);
      return ss;
    };
    auto at_max = [&](size_t q) -> S {
      if constexpr (!mech::is_dual<S>) {
        return ws.searches[q].value;
      } else {
        if (!kept.tops[q]) kept.tops[q] = dual_max(q, v, ws, solved_at, ss);
        return *kept.tops[q];
      }
    };
    // The angle of search q's maximum; on S, moved with the design: phi -
    // f'/f'' at it (f' ~ 0 there: its design derivatives alone, so the
    // value is the search's, with or without a gradient).
    auto at_angle = [&](size_t q) -> S {
      if constexpr (!mech::is_dual<S>) {
        return ws.searches[q].phi;
      } else {
        if (kept.angles[q]) return *kept.angles[q];
        const Jet<S> f = coordinate_jet(ws.asked[q], solved_at(q), ws);
        return S(ws.searches[q].phi - (f.d - mech::value(f.d)) / mech::value(f.dd));
      }
    };
    auto find = [&](Quantity q) { return search_of(ws, n_margins, q); };
    bool means = false;
    for (size_t m : ws.wanted) {
      const Metric& mt = metrics_[m];
      switch (mt.form) {
        case Form::peak: {
          // (the angles' searches run on their sines: the same maxima, no asin)
          using std::asin;
          const S top = at_max(find(mt.q));
          if (mt.q.kind == Kind::pressure) out.put(static_cast<int>(m), S(asin(top)));
          else if (mt.q.kind == Kind::transmission) out.put(static_cast<int>(m), S(asin(S(-top))));
          else out.put(static_cast<int>(m), mt.q.kind == Kind::neg_coordinate ? S(-top) : top);
          break;
        }
        case Form::range: out.put(static_cast<int>(m), S(at_max(find(mt.q)) + at_max(find(mt.q2)))); break;
        case Form::ratio: {
          // The forward stroke, from the minimum to the maximum in phi,
          // over the return; each angle moves with the design by the
          // implicit function theorem on f'(phi) = 0.
          const S forward = S(at_angle(find(mt.q)) - at_angle(find(mt.q2)));
          const double wrapped = mech::wrap_angle(mech::value(forward));
          const S fwd = S(forward + (wrapped - mech::value(forward)));
          out.put(static_cast<int>(m), S(fwd / (mech::kTwoPi - fwd)));
          break;
        }
        case Form::grashof: break;  // put first
        case Form::k3:
        case Form::least: break;  // from maxima alone: below
        default: means = true;
      }
    }
    // The energy's ratios, seed 000 eq. (15), over T_min from the outputs' strokes.
    const S mean_energy = means ? put_means(d_, metrics_, has_law_, poles(ws), v, out, ws) : S(0.0);
    bool least_wanted = false;
    for (size_t m : ws.wanted) least_wanted = least_wanted || metrics_[m].form >= Form::k2;
    const S least = !least_wanted ? S(0.0) : least_mean_energy(d_, v.data(), masses_, [&](int o) {
      return S(at_max(find({Kind::coordinate, o})) + at_max(find({Kind::neg_coordinate, o})));
    });
    for (size_t m : ws.wanted) {
      const Form f = metrics_[m].form;
      if (f < Form::k1) continue;
      const S top = f == Form::k2 || f == Form::least ? S(0.0) : at_max(find({Kind::energy, kNone}));
      out.put(static_cast<int>(m), f == Form::k1   ? S(top / mean_energy)
                                   : f == Form::k2 ? S(mean_energy / least)
                                   : f == Form::k3 ? S(top / least)
                                                   : least);
    }
  }

 private:
  // The search of q among ws's [from, end): over all groups of its kind
  // where q names none, the largest.
  static size_t search_of(const Workspace& ws, size_t from, Quantity q) {
    const size_t nq = ws.asked.size();
    size_t best = nq;
    for (size_t i = from; i < nq; ++i)
      if (ws.asked[i].kind == q.kind && (q.index == kNone || ws.asked[i].index == q.index) &&
          (best == nq || ws.searches[i].value > ws.searches[best].value))
        best = i;
    return best;
  }
  // The contact or table row (which move with the design) at search q's
  // maximum, if a load-bearing quantity's maximum is at one.
  static const MovingKink* moving_kink(const Workspace& ws, size_t q) {
    if (!bears_loads(ws.asked[q].kind)) return nullptr;
    const double at_phi = ws.searches[q].phi;
    for (const MovingKink& k : ws.moving)
      if (std::abs(std::remainder(k.phi - at_phi, mech::kTwoPi)) < 1e-9) return &k;
    return nullptr;
  }

  // Search q's maximum on a dual S (Danskin): the quantity at its angle
  // (solved_at(q): the chain there), or where that angle moves with the
  // design, at it on S.
  template <class S, class At>
  S dual_max(size_t q, const opt::Values<S>& v, const Workspace& ws, At&& solved_at, State<S>& ss) const {
    const Chain& c = d_.chain;
    const auto [load, side] = ws.held[q];
    const double at_phi = ws.searches[q].phi;
    if (ss.point.size() != c.point_names().size()) ss.resize(c);
    // At a contact or a table's row: at_phi and its shift on S (kink_shift).
    if (const MovingKink* kink = load == kNone ? moving_kink(ws, q) : nullptr) {
      mech::linkage::solve(c, v.data(), S(at_phi + kink_shift(c, v.data(), kink->fn, at_phi, ss)), ss);
      return quantity(ws.asked[q], v.data(), ss, ws);
    }
    if (load == kNone) return quantity(ws.asked[q], v.data(), solved_at(q), ws);
    // At a switch: phi - r / r' on S (r the load's switching rate, zero
    // there: its value's residual left out, so phi's value is the
    // search's, the same bits as without a gradient), the load held.
    const Jet<S> r = mech::linkage::switch_rate(c.loads()[static_cast<size_t>(load)], solved_at(q));
    const S phi = S(at_phi - (r.v - mech::value(r.v)) / mech::value(r.d));
    mech::linkage::solve(c, v.data(), phi, ss);
    ss.held_load = load, ss.held_side = side;
    const S f = quantity(ws.asked[q], v.data(), ss, ws);
    ss.held_load = kNone;
    return f;
  }

  // On a dual S, the maxima of searches [from, end) that the metrics take
  // at their angle, the chain there on lanes kLanes maxima a call (lane by
  // lane solve's values): a lane quantity's value into kept.tops[q] (a
  // coordinate's angle, at_angle's, into kept.angles[q]), else the chain
  // on S into kept.maxima[q] (kept.solved[q]) for dual_max. Not those at
  // a moving kink (at_max solves where it moves) nor a group kind's other
  // than its largest (no metric takes them). Where no metric asks a
  // coordinate's angle (a time ratio), the coordinates' maxima take the
  // full block's spare lanes, then the chain on position lanes (their
  // values' design derivatives alone, the same bits); the rest full jets.
  template <class S>
  void solve_maxima(const opt::Values<S>& v, size_t from, Workspace& ws, ScalarScratch<S>& kept) const {
    using L = mech::lanes_of<S>;
    using P = mech::linkage::position_lanes<L>;
    const Chain& c = d_.chain;
    const size_t nq = ws.asked.size();
    if (kept.maxima.size() < nq) {
      kept.maxima.resize(nq);
      for (auto& st : kept.maxima) st.resize(c);
    }
    auto& lanes = kept.lanes_at(c, v.data());
    kept.at_maxima.clear(), kept.at_positions.clear();
    bool angles = false;
    for (size_t w : ws.wanted) angles = angles || metrics_[w].form == Form::ratio;
    std::array<size_t, mech::kLanes> block, coords;
    int m = 0, k = 0;
    auto angles_of = [&](const std::array<size_t, mech::kLanes>& qs, int used) {
      mech::Lanes phi;
      for (int j = 0; j < mech::kLanes; ++j) phi[j] = ws.searches[qs[static_cast<size_t>(std::min(j, used - 1))]].phi;
      return phi;
    };
    auto run = [&] {
      const mech::Lanes phi = angles_of(block, m);
      auto& st = kept.at_maxima.next(c);
      mech::linkage::solve_lanes_at<L, false>(c, lanes.v.data(), L(phi), st);
      kept.at_maxima.keep(phi, m);
      std::optional<mech::linkage::DrivePoint<L>> dp;  // the torque's and the energy's, once
      for (int j = 0; j < m; ++j) {
        const size_t q = block[static_cast<size_t>(j)];
        const Quantity& a = ws.asked[q];
        if (ws.held[q].first != kNone || !lane_kind(a.kind)) {
          mech::linkage::lane_state(st, j, kept.maxima[q]);
          kept.solved[q] = 1;
          continue;
        }
        L f;
        if (a.kind == Kind::torque || a.kind == Kind::energy) {
          if (!dp) dp = mech::linkage::drive_point(c, lanes.v.data(), st);
          f = drive_quantity(a.kind, *dp, lanes.v[static_cast<size_t>(c.crank().speed)]);
        } else if (a.kind == Kind::coordinate || a.kind == Kind::neg_coordinate) {
          const Jet<L> x = coordinate_jet(a, st, ws);
          f = x.v;
          kept.angles[q] = S(phi[j] - (mech::LaneForm<S>::lane(x.d, j) - x.d.v[j]) / x.dd.v[j]);
        } else {
          f = quantity(a, lanes.v.data(), st, ws);
        }
        kept.tops[q] = mech::LaneForm<S>::lane(f, j);
      }
      m = 0;
    };
    auto run_positions = [&] {
      auto& pv = kept.position_values;
      if (pv.empty()) pv.assign(lanes.v.begin(), lanes.v.end());
      const mech::Lanes phi = angles_of(coords, k);
      auto& st = kept.at_positions.next(c);
      mech::linkage::solve_lanes_at<P, false>(c, pv.data(), P(L(phi)), st);
      kept.at_positions.keep(phi, k);
      for (int j = 0; j < k; ++j) {
        const size_t q = coords[static_cast<size_t>(j)];
        kept.tops[q] = mech::LaneForm<S>::lane(coordinate_jet(ws.asked[q], st, ws).v, j);
      }
      k = 0;
    };
    kept.position_values.clear();
    for (size_t q = from; q < nq; ++q) {
      const Kind kind = ws.asked[q].kind;
      const bool grouped = kind == Kind::pressure || kind == Kind::transmission;
      if ((ws.held[q].first == kNone && moving_kink(ws, q)) || (grouped && search_of(ws, from, {kind, kNone}) != q))
        continue;
      if ((kind == Kind::coordinate || kind == Kind::neg_coordinate) && !angles && ws.held[q].first == kNone) {
        coords[static_cast<size_t>(k++)] = q;
        if (k == mech::kLanes) run_positions();
        continue;
      }
      block[static_cast<size_t>(m++)] = q;
      if (m == mech::kLanes) run();
    }
    while (m && m < mech::kLanes && k) block[static_cast<size_t>(m++)] = coords[static_cast<size_t>(--k)];
    if (m) run();
    if (k) run_positions();
  }

  // Runs searches [from, to) of ws (their quantities ws.asked[from, to)).
  // Values, the jets' slopes and, on a chain of RRR and RRP groups, the
  // torque's slope from the third derivatives (third.hpp) go kLanes queries
  // at a time through the grid's lanes (each lane solve's bits; a block
  // with a lane that cannot assemble goes query by query); other slopes
  // on the chain on a LaneDual in phi.
  void run_searches(Workspace& ws, size_t from, size_t to) const {
    const Chain& c = d_.chain;
    auto& lanes = *ws.lanes;
    auto& block = ws.lane_queries;
    mech::find_cycle_maxima(std::span(ws.searches.data() + from, to - from), [&](std::span<mech::AngleQuery> qs) {
      auto one = [&](mech::AngleQuery& a) {
        const Quantity& q = ws.asked[from + static_cast<size_t>(a.fn)];
        // A value, or a slope the jets give, on doubles; else on a Dual in phi.
        const bool dual = a.slope && !has_jet_slope(q.kind);
        const bool ok = dual ? mech::linkage::solve(c, ws.vdual.data(), Dual(a.phi, 1.0), ws.sdual)
                             : mech::linkage::solve(c, ws.plain.data(), a.phi, ws.sd);
        if (!ok && (q.kind != Kind::margin || (dual ? ws.sdual.failed : ws.sd.failed) <= q.index)) {
          a.out = a.slope ? 0.0 : 1.0;  // past a failure: above every margin
          return;
        }
        if (dual) a.out = quantity(q, ws.vdual.data(), ws.sdual, ws).d;
        else if (a.slope) a.out = jet_slope(d_, q, ws.plain.data(), ws.sd);
        else a.out = quantity(q, ws.plain.data(), ws.sd, ws);
      };
      // Slopes beyond the jets: on a LaneDual in phi, kLanes at a time.
      auto run_dual_block = [&] {
        auto& duals = ws.dual_queries;
        const int m = static_cast<int>(duals.size());
        using L = mech::LaneDual<1>;
        L phi;
        for (int j = 0; j < mech::kLanes; ++j) phi.v[j] = duals[static_cast<size_t>(std::min(j, m - 1))]->phi;
        phi.d[0] = mech::Lanes(1.0);
        if (!ws.dual_set) {
          if (ws.dual_lanes) ws.dual_lanes->reset(ws.vdual.data());
          else ws.dual_lanes.emplace(c, ws.vdual.data());
          ws.dual_set = true;
        }
        auto& dl = *ws.dual_lanes;
        if (!mech::linkage::solve_lanes_at(c, dl.v.data(), phi, dl.st)) {
          for (mech::AngleQuery* a : duals) one(*a);
        } else {
          L out;  // a quantity once for the lanes in a row that ask it
          for (int j = 0; j < m; ++j) {
            mech::AngleQuery& a = *duals[static_cast<size_t>(j)];
            if (j == 0 || a.fn != duals[static_cast<size_t>(j - 1)]->fn)
              out = quantity(ws.asked[from + static_cast<size_t>(a.fn)], dl.v.data(), dl.st, ws);
            a.out = out.d[0][j];
          }
        }
        duals.clear();
      };
      // Block b of lane queries, at angles [first, first + kLanes) of
      // ws.lane_angles (first = b kLanes): the chain once at those angles,
      // each query's answer from its angle's lane. Its queries: block[i]
      // for the i in ws.by_block from block b - 1's end (0 for the first)
      // to ws.block_end[b].
      const auto& angles = ws.lane_angles;
      auto run_block = [&](size_t b) {
        const size_t first = b * mech::kLanes, m = std::min<size_t>(mech::kLanes, angles.size() - first);
        const std::span<const size_t> mine(ws.by_block.data() + (b == 0 ? 0 : ws.block_end[b - 1]),
                                           ws.by_block.data() + ws.block_end[b]);
        mech::Lanes phi;
        for (size_t j = 0; j < mech::kLanes; ++j) phi[static_cast<int>(j)] = angles[first + std::min(j, m - 1)];
        State<mech::Lanes>& st = ws.keep_searched ? ws.searched.next(c) : lanes.st;
        if (!mech::linkage::solve_lanes_exact(c, lanes.v.data(), phi, st)) {
          for (size_t i : mine) one(*block[i]);
          return;
        }
        if (ws.keep_searched) ws.searched.keep(phi, static_cast<int>(m));
        // The torque's and the energy's drive point, once: with the
        // torque's slope (the third derivatives) where the block asks it.
        std::optional<mech::linkage::DrivePoint<mech::Lanes>> dp;
        mech::Lanes torque_slope;
        for (size_t i : mine) {
          if (!block[i]->slope || ws.asked[from + static_cast<size_t>(block[i]->fn)].kind != Kind::torque) continue;
          mech::linkage::third_order(c, lanes.v.data(), st, ws.thirds);
          const mech::linkage::DriveSlope ds = mech::linkage::drive_slope(c, lanes.v.data(), st, ws.thirds);
          dp = ds.point, torque_slope = ds.slope;
          break;
        }
        mech::Lanes out;  // a quantity (or slope) once for the block's queries in a row that ask it
        const mech::AngleQuery* before = nullptr;
        for (size_t i : mine) {
          mech::AngleQuery& a = *block[i];
          if (!before || a.fn != before->fn || a.slope != before->slope) {
            const Quantity& q = ws.asked[from + static_cast<size_t>(a.fn)];
            if (a.slope && q.kind == Kind::torque) {
              out = torque_slope;
            } else if (q.kind == Kind::torque || q.kind == Kind::energy) {  // (quantity's and jet_slope's)
              if (!dp) dp = mech::linkage::drive_point(c, lanes.v.data(), st);
              const mech::Lanes& w = lanes.v[static_cast<size_t>(c.crank().speed)];
              out = a.slope ? energy_slope(*dp, w) : drive_quantity(q.kind, *dp, w);
            } else {
              out = a.slope ? jet_slope(d_, q, lanes.v.data(), st) : quantity(q, lanes.v.data(), st, ws);
            }
          }
          a.out = out[static_cast<int>(ws.lane_of[i] - first)];
          before = &a;
        }
      };
      block.clear();
      for (mech::AngleQuery& a : qs) {
        const Kind k = ws.asked[from + static_cast<size_t>(a.fn)].kind;
        if (!lane_kind(k)) {
          one(a);
        } else if (a.slope && !has_jet_slope(k) && !(k == Kind::torque && third_order_)) {
          ws.dual_queries.push_back(&a);
          if (ws.dual_queries.size() == mech::kLanes) run_dual_block();
        } else {
          block.push_back(&a);
        }
      }
      // The lane queries' angles, each once (a kink's f and an output's
      // stop are often one angle).
      ws.lane_angles.clear(), ws.lane_of.clear();
      for (const mech::AngleQuery* a : block) {
        size_t i = 0;
        while (i < angles.size() && !(angles[i] == a->phi)) ++i;
        if (i == angles.size()) ws.lane_angles.push_back(a->phi);
        ws.lane_of.push_back(i);
      }
      // ... and the queries by block, in their order within each (a
      // counting sort: block_end holds the counts, then the starts, then
      // after the fill each block's end).
      const size_t nb = (angles.size() + mech::kLanes - 1) / mech::kLanes;
      std::vector<size_t>& block_end = ws.block_end;
      block_end.assign(nb + 1, 0);
      for (size_t i : ws.lane_of) ++block_end[i / mech::kLanes + 1];
      for (size_t b = 0; b < nb; ++b) block_end[b + 1] += block_end[b];
      ws.by_block.resize(block.size());
      for (size_t i = 0; i < block.size(); ++i) ws.by_block[block_end[ws.lane_of[i] / mech::kLanes]++] = i;
      for (size_t b = 0; b < nb; ++b) run_block(b);
      if (!ws.dual_queries.empty()) run_dual_block();
    }, ws.cycle);
  }

  // Where the driving torque has singularities near the real axis: each
  // local minimum m0 of a group's margin^2 (at phi_k, its second
  // derivative m2 there) is zero at about phi_k +- i sqrt(2 m0 / m2), a
  // toggle off the real line, whose transfer functions blow up there. The
  // margins' searches are ws.searches[0, groups) over their grids: a group
  // whose minima its grid resolves takes their parabolas (grid_poles), one
  // with a narrower minimum searches each to its angle and takes the
  // chain's jets there.
  const std::vector<mech::NearPole>& poles(Workspace& ws) const {
    std::vector<mech::NearPole>& out = ws.near;
    if (ws.near_known) return out;  // (grid_points': every group's from its grid)
    out.clear();
    for (size_t g = 0; g < d_.chain.groups().size(); ++g) {
      if (grid_poles(ws.searches[g].v, out)) continue;
      ws.searches[g].reset(ws.searches[g].v);
      ws.searches[g].global = false;
      run_searches(ws, g, g + 1);
      for (double phi : ws.searches[g].maxima) {
        mech::linkage::solve(d_.chain, ws.plain.data(), phi, ws.sd);
        const Jet<double> m = margin2(d_.chain, static_cast<int>(g), ws.sd);
        if (m.dd > 0) out.push_back({phi, std::sqrt(2 * m.v / m.dd)});
      }
    }
    return out;
  }

  // The grid of an `auto` evaluation, from its first of kAutoFirst points:
  // those where they give the mean energy's trapezoid rule its n asinh(w)
  // >= 2 kPoleDigits (energy_mean; seed 000's n >= 45 / acosh(l / r) on a
  // slider-crank), w the nearest pole's width from the margins' grids
  // (grid_poles), else kAutoLast. Two sizes only: a grid between them
  // would save little and leave the searches' starts on more grids than
  // the tests see.
  int grid_points(Workspace& ws, size_t n_margins) const {
    const size_t n = ws.grid.size();
    ws.near.clear();
    for (size_t g = 0; g < n_margins; ++g)
      if (!grid_poles(std::span<const double>(ws.grids.data() + g * n, n), ws.near)) return kAutoLast;
    if (static_cast<double>(n) * least_asinh_width(ws.near) < 2 * mech::kPoleDigits) return kAutoLast;
    ws.near_known = true;
    return static_cast<int>(n);
  }

  static std::string degrees(double phi) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.4g", phi * 180 / std::numbers::pi);
    return buf;
  }

  // Solves the chain at phi (a grid angle); false, with the status and the
  // failing group named in the evaluation, when it cannot assemble there.
  template <class S>
  bool solve_at(const double* vd, double phi, State<double>& st, MetricSink<S>& out) const {
    if (mech::linkage::solve(d_.chain, vd, phi, st)) return true;
    out.result.status = mech::Status::cannot_assemble;
    out.result.message = d_.chain.group_name(st.failed) + " cannot assemble at crank angle " + degrees(phi) + " deg";
    return false;
  }

  // The chain and the asked quantities at the n grid angles (ws.blocks,
  // ws.grids; ws.states() the states as scalars), kLanes at a time
  // (solve_lanes_exact: the same bits as solve at each angle); a block
  // where some lane cannot assemble goes angle by angle, to name the
  // first that fails.
  template <class S>
  bool solve_grid(const double* vd, int n, MetricSink<S>& out, Workspace& ws) const {
    const Chain& c = d_.chain;
    const size_t un = static_cast<size_t>(n), nq = ws.asked.size();
    const size_t nb = (un + mech::kLanes - 1) / mech::kLanes;
    if (ws.grid.size() != un || ws.grid[0].point.size() != c.point_names().size()) {
      ws.grid.resize(un);
      for (auto& st : ws.grid) st.resize(c);
      ws.blocks.resize(nb);
      for (auto& st : ws.blocks) st.resize(c);
    }
    ws.scattered.assign(nb, 0);
    if (ws.lanes) ws.lanes->reset(vd);
    else ws.lanes.emplace(c, vd);
    ws.dual_set = false;
    ws.searched.clear();
    auto& lanes = *ws.lanes;
    const std::vector<size_t>& mirror = ws.mirror;
    if (const double phase = vd[c.crank().phase]; ws.grid_n != n || phase != ws.grid_phase) {
      ws.grid_cs.resize(nb);
      for (int k = 0; k < n; k += mech::kLanes) {
        auto& [phi, cp, sp] = ws.grid_cs[static_cast<size_t>(k / mech::kLanes)];
        mech::Lanes i = mech::iota(k);
        for (int j = n - k; j < mech::kLanes; ++j) i[j] = n - 1;  // (a last block's spare lanes)
        phi = mech::kTwoPi * i / n;  // (solve's angles, bit for bit)
        mech::linkage::crank_cos_sin(c, phase, phi, cp, sp);
      }
      ws.grid_phase = phase, ws.grid_n = n;
    }
    for (int k = 0; k < n; k += mech::kLanes) {
      const int m = std::min(mech::kLanes, n - k);
      const size_t b = static_cast<size_t>(k / mech::kLanes);
      const auto& [phi, cp, sp] = ws.grid_cs[b];
      const State<mech::Lanes>& st = ws.blocks[b];
      const bool whole = mech::linkage::solve_lanes_exact(c, lanes.v.data(), phi, cp, sp, ws.blocks[b]);
      if (!whole) {
        for (int j = 0; j < m; ++j)
          if (!solve_at(vd, mech::kTwoPi * (k + j) / n, ws.grid[static_cast<size_t>(k + j)], out)) return false;
        ws.scattered[b] = 1;
      }
      std::optional<mech::linkage::DrivePoint<mech::Lanes>> dp;  // the torque's and the energy's, once
      const mech::Lanes& w = lanes.v[static_cast<size_t>(c.crank().speed)];
      for (size_t q = 0; q < nq; ++q) {
        const size_t at = q * un + static_cast<size_t>(k);
        double *to = ws.grids.data() + at, *slope = ws.slopes.data() + at;
        const Quantity& a = ws.asked[q];
        const bool sloped = grid_slopes(a.kind);
        if (whole && (a.kind == Kind::torque || a.kind == Kind::energy)) {
          if (!dp) dp = mech::linkage::drive_point(c, lanes.v.data(), st);
          mech::store_lanes(to, drive_quantity(a.kind, *dp, w), m);
          if (sloped) mech::store_lanes(slope, energy_slope(*dp, w), m);
        } else if (whole && mirror[q] < q) {  // a coordinate's other sign: its row's, negated
          const size_t from = mirror[q] * un + static_cast<size_t>(k);  // (an earlier row: kLanes to read)
          mech::store_lanes(to, -mech::load_lanes(ws.grids.data() + from), m);
          mech::store_lanes(slope, -mech::load_lanes(ws.slopes.data() + from), m);
        } else if (whole && lane_kind(a.kind)) {
          mech::store_lanes(to, quantity(a, lanes.v.data(), st, ws), m);
          if (sloped) mech::store_lanes(slope, jet_slope(d_, a, lanes.v.data(), st), m);
        } else {
          ws.scatter(b);
          for (int j = 0; j < m; ++j) {
            const State<double>& sj = ws.grid[static_cast<size_t>(k + j)];
            to[j] = quantity(a, vd, sj, ws);
            if (sloped) slope[j] = jet_slope(d_, a, vd, sj);
          }
        }
      }
    }
    return true;
  }

  // An output driven straight from the crank stands still where
  // kinks.hpp's output_stops says: its coordinate's searches (both signs)
  // take its extremes there (CycleMaxSearch::known) where the grid's rates
  // change sign once in each of their cells and nowhere else.
  void known_extremes(const double* vd, int n, Workspace& ws) const {
    ws.known.clear();
    ws.known.reserve(4 * ws.asked.size());  // (the spans stay put)
    for (size_t q = 0; q < ws.asked.size(); ++q) {
      const Quantity& a = ws.asked[q];
      if (a.kind != Kind::coordinate && a.kind != Kind::neg_coordinate) continue;
      if (ws.mirror[q] < q) {  // the other sign's
        ws.searches[q].known = ws.searches[ws.mirror[q]].known;
        continue;
      }
      const Output& o = d_.outputs[static_cast<size_t>(a.index)];
      double at[4];
      int m = 0;
      const size_t first = ws.known.size();
      if (ws.zeros.output_stops(d_.chain, vd, o.link, o.slides, at, m) &&
          stops_in_cells(at, m, ws.slopes.data() + q * static_cast<size_t>(n), n, ws.known))
        ws.searches[q].known = std::span<const double>(ws.known.data() + first, ws.known.size() - first);
    }
  }

  // A load that switches makes the forces it enters jump where its rate
  // changes sign (the torque does not: the load's power is zero there), so
  // the peak of a reaction can be a one-sided limit at a switch: each
  // switch's two limits join the searches of the reactions [from, end).
  // ws.held[q]: the load and side of search q's maximum when one won.
  void hold_switches(Workspace& ws, size_t from) const {
    const Chain& c = d_.chain;
    ws.held.assign(ws.asked.size(), {kNone, 0});
    bool jumps = false;
    for (size_t q = from; q < ws.asked.size(); ++q) jumps = jumps || jumps_at_switches(ws.asked[q].kind);
    if (!jumps) return;
    for (const auto& [phi, i] : ws.switches) {
      mech::linkage::solve(c, ws.plain.data(), phi, ws.sd);
      for (int side : {-1, 1}) {
        ws.sd.held_load = i, ws.sd.held_side = side;
        for (size_t q = from; q < ws.asked.size(); ++q) {
          if (!jumps_at_switches(ws.asked[q].kind)) continue;
          const double f = quantity(ws.asked[q], ws.plain.data(), ws.sd, ws);
          // A search that ended at the switch found this limit: held, its angle moves with the design.
          const bool here = std::abs(std::remainder(phi - ws.searches[q].phi, mech::kTwoPi)) < 1e-7;
          if (!(f > ws.searches[q].value) && !(here && f >= ws.searches[q].value * (1 - 1e-9))) continue;
          ws.searches[q].value = f, ws.searches[q].phi = phi;
          ws.held[q] = {i, side};
        }
      }
      ws.sd.held_load = kNone;
    }
  }
  // The kinks of the searches of [from, end) the loads enter (the torque
  // and the forces): a pressure law's contacts (jumps), the tables' rows
  // (kinks.hpp's table_rows) and the loads' switches (ws.switches: angle,
  // load; the torque bends there, the forces jump). A maximum at a kink is
  // the kink's value, one just before a jump is not mistaken for it; two
  // maxima a kink apart within a grid step are both seen. ws.moving: the
  // contacts and the rows crossed (at_max takes their motion).
  void find_kinks(Workspace& ws, size_t from) const {
    const Chain& c = d_.chain;
    const int n = static_cast<int>(ws.grid.size());
    ws.switches.clear(), ws.moving.clear(), ws.kinks.clear();
    ws.switches_found = false;
    bool loaded = false;
    for (size_t q = from; q < ws.asked.size(); ++q) loaded = loaded || bears_loads(ws.asked[q].kind);
    if (!loaded) return;
    if (has_law_) contacts(c, ws.plain.data(), n, ws.contacts, ws.zeros, ws.sd, ws.blocks);
    for (const Contact& k : ws.contacts) ws.moving.push_back({k.phi, {k.load, kDepth}});  // (none without a law)
    table_rows(c, ws.plain.data(), n, ws.moving, ws.kinks, ws.zeros, ws.sd, ws.blocks);
    for (const MovingKink& k : ws.moving) ws.kinks.push_back(k.phi);
    torque_kinks(c, ws.plain.data(), n, ws.zeros, ws.sd, ws.blocks, &ws.switches, false, &*ws.lanes);
    ws.switches_found = true;  // (put_means takes them)
    for (const auto& sw : ws.switches) ws.kinks.push_back(sw.first);
    for (size_t q = from; q < ws.asked.size(); ++q)
      if (bears_loads(ws.asked[q].kind)) ws.searches[q].kinks = ws.kinks;
  }
  static bool jumps_at_switches(Kind k) { return k == Kind::reaction || k == Kind::guide; }
  static bool bears_loads(Kind k) { return k == Kind::torque || jumps_at_switches(k); }

  template <class T>
  Jet<T> coordinate_jet(const Quantity& q, const State<T>& st, const Workspace& ws) const {
    return linkage::coordinate_jet(d_, q, st, ws.ref);
  }
  template <class T>
  T quantity(const Quantity& q, const T* v, const State<T>& st, const Workspace& ws) const {
    return linkage::quantity(d_, joints_, q, v, st, ws.ref);
  }
  Description d_;
  mech::linkage::Joints joints_{d_.chain};
  std::vector<Metric> metrics_;
  std::vector<int> masses_;  // the outputs T_min counts (moving_masses)
  bool has_law_ = false;     // a pressure law: the torque jumps at its contacts
  bool third_order_ = mech::linkage::has_third_order(d_.chain);  // the torque's slope from third.hpp
  bool switches_ = std::any_of(d_.chain.loads().begin(), d_.chain.loads().end(),
                               [](const mech::linkage::Load& l) { return mech::linkage::switching(l); });
  bool has_rocker_ = std::any_of(d_.outputs.begin(), d_.outputs.end(), [](const Output& o) { return !o.slides; });
};

std::unique_ptr<opt::Problem> make_linkage(const opt::ConfigNode& root) {
  Description d = read_description(root);
  std::vector<Metric> metrics = metrics_of(d);
  for (size_t i = 0; i < metrics.size(); ++i)
    for (size_t j = 0; j < i; ++j)
      if (metrics[i].spec.name == metrics[j].spec.name)
        root.at("model").fail("two metrics would be named '" + metrics[i].spec.name + "': rename an output");
  check_dynamics_asked(root, metrics);
  opt::Values<double> values = d.chain.defaults();
  std::vector<opt::Variable> vars = opt::parse_variables(root, opt::with_values(d.table, values));
  check_derived_not_free(d, root, vars);
  return std::make_unique<LinkageProblem>(std::move(d), std::move(metrics), std::move(values), std::move(vars));
}

const opt::Registration kRegistration{{"linkage",
                                       "any planar linkage of a crank and class II groups, described in the config "
                                       "(docs/linkage.md): its model keys are the description's numbers by address, "
                                       "its metrics named by its outputs (listed here for a slider-crank)",
                                       {},
                                       make_linkage,
                                       [](const opt::ConfigNode& root) { return read_description(root).table; }}};

}  // namespace
}  // namespace problems::linkage
