// Twin slider-crank recuperative drive (seed 000): two slider-crank mechanisms
// on one shaft, cranks shifted by dphi, each driving a forming cart of mass m.
// Kinetic energy (eqs 9-11), its cycle mean (12), least possible mean (14),
// ratios k1..k3 (15), static resistance moment (16-17), inertia moment
// (18-20) and total moment (21). All quantities at constant crank speed w.
#pragma once
#include <algorithm>
#include <cmath>
#include <numbers>
#include <type_traits>
#include <vector>

#include "mech/autodiff.hpp"
#include "mech/cycle.hpp"
#include "mech/slider_crank.hpp"

namespace mech {

// Second cart on the other side of the shaft (seed 000 eq. 2) or on the same
// side as the first (seed 001 eqs 36-38).
enum class Layout { opposed, same_side };
// Rod as a mass concentrated at its centre (seed 000 eq. 10) or with its own
// rotational inertia q*l^3/12 added.
enum class RodModel { point_masses, full };
// Cart resistance F_B as printed (eq. 16: proportional to the signed cart
// velocity) or always opposing the cart's motion (|velocity|).
enum class Resistance { signed_velocity, opposes_motion };

template <class S>
struct TwinDrive {
  S crank_radius;          // r [m], (0, inf)
  S rod_length;            // l [m], (r + |e|, inf)
  S phase_shift;           // dphi [rad], crank 2 leads crank 1 by dphi
  S offset;                // e [m], slider-axis offset of both mechanisms
  S crank_speed;           // w [rad/s], (0, inf)
  S cart_mass;             // m [kg], [0, inf)
  S rod_mass_per_length;   // q [kg/m], [0, inf)
  S efficiency;            // eta, (0, 1]
  S cart_resistance;       // F_B [N], [0, inf)
  Layout layout = Layout::opposed;
  Kinematics kinematics = Kinematics::exact;
  RodModel rod = RodModel::point_masses;
  Resistance resistance = Resistance::signed_velocity;

  SliderCrank<S> mechanism(int i) const {
    const int sigma = (i == 1 && layout == Layout::opposed) ? -1 : 1;
    return {crank_radius, rod_length, offset, sigma, kinematics};
  }
  // The same drive with f applied to every number.
  template <class F>
  auto map(F&& f) const -> TwinDrive<decltype(f(crank_radius))> {
    return {f(crank_radius), f(rod_length), f(phase_shift), f(offset), f(crank_speed), f(cart_mass),
            f(rod_mass_per_length), f(efficiency), f(cart_resistance), layout, kinematics, rod, resistance};
  }
  template <class T>
  TwinDrive<T> cast() const {
    return map([](const S& x) { return T(value(x)); });
  }
  // kLanes copies of the drive, derivatives kept (S must have lanes_of<S>).
  TwinDrive<lanes_of<S>> lanes() const { return map(LaneForm<S>::broadcast); }
};

// Physical domain and assembly over the whole revolution.
template <class S>
Status check(const TwinDrive<S>& d) {
  if (!(value(d.crank_radius) > 0) || !(value(d.crank_speed) > 0) ||
      !(value(d.cart_mass) >= 0) || !(value(d.rod_mass_per_length) >= 0) ||
      !(value(d.efficiency) > 0 && value(d.efficiency) <= 1) ||
      !(value(d.cart_resistance) >= 0) || !std::isfinite(value(d.phase_shift)))
    return Status::invalid_parameter;
  if (!assembles_over_cycle(d.mechanism(0))) return Status::cannot_assemble;
  return Status::ok;
}

template <class S>
struct DrivePoint {
  S kinetic_energy;   // T, eq. (11) [J]
  S inertia_moment;   // M_i = dT/dphi, eqs (18)-(20) [N m]
  S static_moment;    // M_on, eqs (16)-(17) [N m]
  S total_moment() const { return inertia_moment + static_moment; }  // eq. (21)
};

// Whether the rods carry their own rotation (RodModel::full), as the kernels
// below ask it: of the drive (RodOf), or fixed at compile time (FixedRod:
// cycle_metrics's loops, where the test at every crank angle cost a
// recuperative DOE design 3.5%; the same operations either way).
struct RodOf {
  template <class S>
  static bool full(const TwinDrive<S>& d) { return d.rod == RodModel::full; }
};
template <RodModel R>
struct FixedRod {
  template <class S>
  static constexpr bool full(const TwinDrive<S>&) { return R == RodModel::full; }
};

// Sum of mass * (velocity / w)^2 over both carts (eq. 9) and rods (eq. 10,
// plus the rods' rotation for RodModel::full): T = w^2/2 times this.
template <class Rod = RodOf, class S>
MECH_INLINE S mass_velocity_squared(const TwinDrive<S>& d, const SliderCrankVelocity<S>& p1,
                        const SliderCrankVelocity<S>& p2) {
  const S rod_mass = d.rod_mass_per_length * d.rod_length;
  S mv2 = d.cart_mass * (p1.dx * p1.dx + p2.dx * p2.dx) +
          rod_mass * (p1.dxs * p1.dxs + p1.dys * p1.dys + p2.dxs * p2.dxs + p2.dys * p2.dys);
  if (Rod::full(d))
    mv2 += rod_mass * d.rod_length * d.rod_length / 12.0 * (p1.dbeta * p1.dbeta + p2.dbeta * p2.dbeta);
  return mv2;
}

// ... and the angle slope of the total moment, dM/dphi (a cart's |dx/dphi|
// taken one-sided, as abs of a dual number takes it, at its dead centre).
template <class S>
struct DrivePointSlope : DrivePoint<S> {
  S moment_slope;
};

// u where v >= 0, -u where v < 0 (the slope of |v| given v's slope u).
inline double flip_where_negative(double u, double v) { return v < 0 ? -u : u; }
MECH_INLINE Lanes flip_where_negative(const Lanes& u, const Lanes& v) {
  Lanes r;
  for (int j = 0; j < kLanes; ++j) r[j] = v[j] < 0 ? -u[j] : u[j];
  return r;
}

// Energy and moments at crank angle phi given c = cos(phi), s = sin(phi) and
// the cos/sin of the phase shift (cd, sd), with the moment's slope when
// kSlope (drive_point_slope: third-order transfer functions, S double or
// Lanes). check(d) must be ok.
template <class Rod = RodOf, bool kSlope = false, class S, class A>
MECH_INLINE std::conditional_t<kSlope, DrivePointSlope<S>, DrivePoint<S>> drive_point(
    const TwinDrive<S>& d, const A& c, const A& s, const S& cd, const S& sd) {
  using std::abs;
  using P = std::conditional_t<kSlope, DrivePointSlope<S>, DrivePoint<S>>;
  using K = std::conditional_t<kSlope, SliderCrankPoint3<S>, SliderCrankPoint<S>>;
  const auto p1 = slider_crank_point<S, K>(d.mechanism(0), S(c), S(s));
  const auto p2 = slider_crank_point<S, K>(d.mechanism(1), S(c * cd - s * sd), S(s * cd + c * sd));
  const S w2 = d.crank_speed * d.crank_speed;
  const S rod_mass = d.rod_mass_per_length * d.rod_length;
  // Half the angle derivative of mass_velocity_squared.
  S mva = d.cart_mass * (p1.dx * p1.ddx + p2.dx * p2.ddx) +
          rod_mass * (p1.dxs * p1.ddxs + p1.dys * p1.ddys + p2.dxs * p2.ddxs + p2.dys * p2.ddys);
  if (Rod::full(d))
    mva += rod_mass * d.rod_length * d.rod_length / 12.0 * (p1.dbeta * p1.ddbeta + p2.dbeta * p2.ddbeta);
  const S force = d.cart_resistance / d.efficiency;
  P out;
  out.kinetic_energy = 0.5 * w2 * mass_velocity_squared<Rod>(d, p1, p2);
  out.inertia_moment = w2 * mva;
  out.static_moment = d.resistance == Resistance::signed_velocity
                          ? S(force * (p1.dx + p2.dx))
                          : S(force * (abs(p1.dx) + abs(p2.dx)));
  if constexpr (kSlope) {  // the angle derivatives of mva and of the static moment
    S dmva = d.cart_mass * (p1.ddx * p1.ddx + p1.dx * p1.dddx + p2.ddx * p2.ddx + p2.dx * p2.dddx) +
             rod_mass * (p1.ddxs * p1.ddxs + p1.dxs * p1.dddxs + p1.ddys * p1.ddys + p1.dys * p1.dddys +
                         p2.ddxs * p2.ddxs + p2.dxs * p2.dddxs + p2.ddys * p2.ddys + p2.dys * p2.dddys);
    if (Rod::full(d))
      dmva += rod_mass * d.rod_length * d.rod_length / 12.0 *
              (p1.ddbeta * p1.ddbeta + p1.dbeta * p1.dddbeta + p2.ddbeta * p2.ddbeta + p2.dbeta * p2.dddbeta);
    out.moment_slope = w2 * dmva + (d.resistance == Resistance::signed_velocity
                                        ? S(force * (p1.ddx + p2.ddx))
                                        : S(force * (flip_where_negative(p1.ddx, p1.dx) +
                                                     flip_where_negative(p2.ddx, p2.dx))));
  }
  return out;
}
template <class Rod = RodOf, class S>
MECH_INLINE DrivePointSlope<S> drive_point_slope(const TwinDrive<S>& d, const S& c, const S& s, const S& cd,
                                                 const S& sd) {
  return drive_point<Rod, true>(d, c, s, cd, sd);
}

template <class S>
DrivePoint<S> drive_point(const TwinDrive<S>& d, const S& phi) {
  using std::cos;
  using std::sin;
  return drive_point(d, S(cos(phi)), S(sin(phi)), S(cos(d.phase_shift)), S(sin(d.phase_shift)));
}

// Least possible mean kinetic energy of both carts, eq. (14): 4 m r^2 w^2 / pi^2.
template <class S>
S least_mean_kinetic_energy(const TwinDrive<S>& d) {
  return 4.0 * d.cart_mass * d.crank_radius * d.crank_radius * d.crank_speed * d.crank_speed /
         (std::numbers::pi * std::numbers::pi);
}

// Grid points per revolution for ~1e-13 relative error in cycle means. The
// integrands are analytic in the strip |Im phi| < a, a = acosh(l / (r + |e|)),
// where the rod's horizontal extent vanishes, so the periodic trapezoidal rule
// errs by ~exp(-a n): n = 45 / a (measured: n a = 31..43 reaches 1e-13 for
// r/l from 0.95 to 0.13), rounded up to a multiple of 4, at least 16.
template <class S>
int auto_cycle_points(const TwinDrive<S>& d) {
  using std::abs;
  const double ratio = value(d.rod_length) / (value(d.crank_radius) + abs(value(d.offset)));
  if (!(ratio > 1)) return 16;  // cannot assemble: check() reports it
  const double n = 45.0 / std::acosh(ratio);
  return std::clamp(4 * static_cast<int>(std::ceil(n / 4)), 16, 4096);
}

// Cycle mean of T, eq. (12), by the n-point periodic trapezoidal rule. check(d) must be ok.
template <class S>
S mean_kinetic_energy(const TwinDrive<S>& d, int n) {
  using std::cos;
  using std::sin;
  const S cd = cos(d.phase_shift), sd = sin(d.phase_shift);
  S sum(0.0);
  if constexpr (has_lanes<S>) {  // kLanes angles at a time
    using L = lanes_of<S>;
    const auto dl = d.lanes();
    const auto m1 = dl.mechanism(0), m2 = dl.mechanism(1);
    const L cdl = LaneForm<S>::broadcast(cd), sdl = LaneForm<S>::broadcast(sd);
    L sums(0.0);
    for_each_grid_block(n, [&](int, int m, const Lanes& c, const Lanes& s) {
      sums += first_lanes(mass_velocity_squared(dl, slider_crank_velocity(m1, L(c), L(s)),
                                                slider_crank_velocity(m2, c * cdl - s * sdl, s * cdl + c * sdl)),
                          m);
    });
    sum = LaneForm<S>::sum(sums);
  } else {
    const auto m1 = d.mechanism(0), m2 = d.mechanism(1);
    for_each_grid_angle(n, [&](int, double c, double s) {
      sum += mass_velocity_squared(d, slider_crank_velocity(m1, S(c), S(s)),
                                   slider_crank_velocity(m2, S(c * cd - s * sd), S(s * cd + c * sd)));
    });
  }
  return 0.5 * d.crank_speed * d.crank_speed * sum / double(n);
}

// Which cycle quantities to compute: the means are cheap, each refined maximum
// costs a root search.
struct CycleNeeds {
  bool peak_energy = true;
  bool moments = true;
};

template <class S>
struct CycleMetrics {
  S mean_kinetic_energy, peak_kinetic_energy, least_mean_kinetic_energy;
  S k1, k2, k3;                   // eq. (15)
  S peak_total_moment;            // max over the cycle of |M| [N m]
  S mean_total_moment, rms_total_moment;
  double phi_peak_energy = 0, phi_peak_moment = 0;  // maximising angles [rad]
};

// Crank angles phi in [0, 2 pi) of the dead centres of both sliders (where
// a cart stops and its resistance flips). check(d) must be ok. Exact
// kinematics: in closed form, where crank and rod are collinear (crank angle
// psi with sin psi = -e/(l + r), stretched, or e/(l - r), folded; the cosine's
// sign from the slider's side sigma; both mechanisms have the same r, l and
// e, so slider 2's psi are slider 1's, or pi minus them when mirrored). The
// binomial series: the sign changes of the slider velocity on the n-point
// grid, refined by Brent. Into `out` (its storage reused):
template <class S>
void dead_centres(const TwinDrive<S>& d, int n, std::vector<double>& out) {
  const TwinDrive<double> dv = d.template cast<double>();
  out.clear();
  double first[2];  // slider 1's crank angles, stretched and folded
  for (int i = 0; i < 2; ++i) {
    const auto m = dv.mechanism(i);
    const double shift = i == 0 ? 0.0 : dv.phase_shift;
    if (m.kinematics == Kinematics::exact) {
      int k = 0;
      for (const auto& [sn, side] : {std::pair{-m.e / (m.l + m.r), 1.0}, std::pair{m.e / (m.l - m.r), -1.0}}) {
        if (i == 0) first[k] = std::atan2(sn, side * m.sigma * std::sqrt(1 - sn * sn));
        const double psi = i == 0 || m.sigma == dv.mechanism(0).sigma ? first[k] : std::numbers::pi - first[k];
        out.push_back(wrap_angle(psi - shift));
        ++k;
      }
      continue;
    }
    auto dx = [&](double phi) {
      return slider_crank_velocity(m, std::cos(phi + shift), std::sin(phi + shift)).dx;
    };
    std::vector<double> v(n);
    for (int k = 0; k < n; ++k) v[k] = dx(kTwoPi * k / n);
    for (double r : periodic_roots(v, dx)) out.push_back(r);
  }
}
template <class S>
std::vector<double> dead_centres(const TwinDrive<S>& d, int n) {
  std::vector<double> out;
  dead_centres(d, n, out);
  return out;
}

// Cycle means of M and M^2, eq. (21), by Gauss-Legendre on each arc between
// dead centres (`centres`: dead_centres(d, n)), where M is smooth:
// exponential convergence again.
template <class Rod = RodOf, class S>
std::pair<S, S> piecewise_moment_means(const TwinDrive<S>& d, int n, const std::vector<double>& centres,
                                       CycleScratch& scratch) {
  using std::cos;
  using std::sin;
  const S cd = cos(d.phase_shift), sd = sin(d.phase_shift);
  auto means = [&](auto&& M) {
    const auto r = piecewise_means<S>(M, centres, 2 * n, scratch);
    return std::pair<S, S>{r.mean, r.mean_square};
  };
  if constexpr (has_lanes<S>) {  // kLanes nodes at a time
    const auto dl = d.lanes();
    const auto cdl = LaneForm<S>::broadcast(cd), sdl = LaneForm<S>::broadcast(sd);
    return means([&](const Lanes&, const Lanes& c, const Lanes& s) {
      return drive_point<Rod>(dl, c, s, cdl, sdl).total_moment();
    });
  } else {
    return means([&](double, double c, double s) { return drive_point<Rod>(d, c, s, cd, sd).total_moment(); });
  }
}

// All cycle quantities with n grid points. A maximum over the cycle is
// nonsmooth in the design; its derivative is taken at the maximising angle
// (Danskin's theorem), which is exact wherever the maximiser is unique.
// check(d) must be ok. Rod: the rod model, fixed for the loops (cycle_metrics
// below). `scratch`: the grids', kinks' and searches' storage.
template <class Rod, class S>
CycleMetrics<S> cycle_metrics_with(const TwinDrive<S>& d, int n, CycleNeeds needs, CycleScratch& scratch) {
  using std::abs;
  using std::cos;
  using std::sin;
  using std::sqrt;
  const S cd = cos(d.phase_shift), sd = sin(d.phase_shift);
  CycleMetrics<S> m;
  S sumT(0.0), sumM(0.0), sumM2(0.0);
  std::vector<double>& grids = scratch.grids;  // for the maxima: no allocation per design once warm
  grids.resize(3 * static_cast<std::size_t>(n));
  const std::span<double> gridT(grids.data(), n), gridDT(grids.data() + n, n),
      gridM(grids.data() + 2 * n, needs.moments ? n : 0);
  if constexpr (has_lanes<S>) {  // kLanes angles at a time
    using L = lanes_of<S>;
    const auto dl = d.lanes();
    const L cdl = LaneForm<S>::broadcast(cd), sdl = LaneForm<S>::broadcast(sd);
    L sT(0.0), sM(0.0), sM2(0.0);
    for_each_grid_block(n, [&](int k, int lanes, const Lanes& c, const Lanes& s) {
      const auto p = drive_point<Rod>(dl, c, s, cdl, sdl);
      const L T = first_lanes(p.kinetic_energy, lanes), M = first_lanes(p.total_moment(), lanes);
      sT += T;
      sM += M;
      sM2 += M * M;
      store_lanes(&gridT[k], lane_values(T), lanes);
      store_lanes(&gridDT[k], lane_values(p.inertia_moment), lanes);
      if (needs.moments) store_lanes(&gridM[k], abs(lane_values(M)), lanes);
    });
    sumT = LaneForm<S>::sum(sT), sumM = LaneForm<S>::sum(sM), sumM2 = LaneForm<S>::sum(sM2);
  } else {
    for_each_grid_angle(n, [&](int k, double c, double s) {
      const auto p = drive_point<Rod>(d, c, s, cd, sd);
      sumT += p.kinetic_energy;
      gridT[k] = value(p.kinetic_energy);
      gridDT[k] = value(p.inertia_moment);
      if (needs.moments) {
        const S M = p.total_moment();
        sumM += M;
        sumM2 += M * M;
        gridM[k] = abs(value(M));
      }
    });
  }
  m.mean_kinetic_energy = sumT / double(n);
  m.least_mean_kinetic_energy = least_mean_kinetic_energy(d);
  m.k2 = m.mean_kinetic_energy / m.least_mean_kinetic_energy;
  std::vector<double>& kinks = scratch.kinks;  // of M: where a cart stops and its resistance flips
  kinks.clear();
  if (needs.moments) {
    if (d.resistance == Resistance::opposes_motion) {
      // |dx/dphi| has kinks at the dead centres, where the trapezoidal rule
      // drops to O(h^2): integrate piecewise between them instead.
      dead_centres(d, n, kinks);
      const auto [mean, mean2] = piecewise_moment_means<Rod>(d, n, kinks, scratch);
      sumM = mean * double(n);
      sumM2 = mean2 * double(n);
    }
    m.mean_total_moment = sumM / double(n);
    m.rms_total_moment = sqrt(sumM2 / double(n));
  }
  // The peaks of T and |M|, searched together (find_cycle_maxima), kLanes
  // angles an evaluation: dT/dphi is the inertia moment (eqs 18-20, constant
  // speed; the grid has it), d|M|/dphi from third-order transfer functions.
  CycleMaxSearch* searches = scratch.searches;  // kept: no allocation per design
  int count = 0, energy = -1, moment = -1;
  if (needs.peak_energy) energy = count, searches[count++].reset(gridT, {}, gridDT);
  if (needs.moments) moment = count, searches[count++].reset(gridM, kinks);
  if (count == 0) return m;
  const TwinDrive<Lanes> dl = d.template cast<double>().lanes();
  const Lanes cdl(value(cd)), sdl(value(sd));
  find_cycle_maxima(std::span(searches, count), [&](std::span<AngleQuery> qs) {
    for_query_blocks(qs, [&](AngleQuery* q, int lanes, const Lanes& c, const Lanes& s) {
      // Each query's answer picked from the four by its kind, without a
      // branch: T, dT/dphi, |M|, d|M|/dphi; M's slope (third-order transfer
      // functions) only for a block that asks for it.
      auto answer = [&](const DrivePoint<Lanes>& p, const Lanes& slope) {
        const Lanes M = p.total_moment();
        const Lanes four[4] = {p.kinetic_energy, p.inertia_moment, abs(M), flip_where_negative(slope, M)};
        for (int j = 0; j < lanes; ++j) q[j].out = four[2 * (q[j].fn != energy) + q[j].slope][j];
      };
      bool slope = false;
      for (int j = 0; j < lanes; ++j) slope |= q[j].fn == moment && q[j].slope;
      if (slope) {
        const auto p = drive_point_slope<Rod>(dl, c, s, cdl, sdl);
        answer(p, p.moment_slope);
      } else {
        answer(drive_point<Rod>(dl, c, s, cdl, sdl), Lanes(0.0));
      }
    });
  }, scratch);
  // The peaks' values: as the search found them (the lanes' sincos and
  // arithmetic, the scalar ones' bits), or at the same cosines with
  // derivatives in the design (Danskin).
  auto at = [&](double phi) {
    double c, s;
    sincos(phi, s, c);
    return drive_point<Rod>(d, S(c), S(s), cd, sd);
  };
  if (needs.peak_energy) {
    m.phi_peak_energy = searches[energy].phi;
    if constexpr (std::is_same_v<S, double>) m.peak_kinetic_energy = searches[energy].value;
    else m.peak_kinetic_energy = at(m.phi_peak_energy).kinetic_energy;
    m.k1 = m.peak_kinetic_energy / m.mean_kinetic_energy;
    m.k3 = m.peak_kinetic_energy / m.least_mean_kinetic_energy;
  }
  if (needs.moments) {
    m.phi_peak_moment = searches[moment].phi;
    if constexpr (std::is_same_v<S, double>) m.peak_total_moment = searches[moment].value;
    else m.peak_total_moment = abs(at(m.phi_peak_moment).total_moment());
  }
  return m;
}
template <class S>
CycleMetrics<S> cycle_metrics(const TwinDrive<S>& d, int n, CycleScratch& scratch, CycleNeeds needs = {}) {
  return d.rod == RodModel::full ? cycle_metrics_with<FixedRod<RodModel::full>>(d, n, needs, scratch)
                                 : cycle_metrics_with<FixedRod<RodModel::point_masses>>(d, n, needs, scratch);
}
// The same with scratch of its own (tests, benchmarks).
template <class S>
CycleMetrics<S> cycle_metrics(const TwinDrive<S>& d, int n, CycleNeeds needs = {}) {
  CycleScratch scratch;
  return cycle_metrics(d, n, scratch, needs);
}

}  // namespace mech
