// Swing mechanism of a radial-rotary conveyor (seed 002): a crank-rocker
// four-bar whose rocker is the platform carrying the conveyor. The balancing
// (reduced) moment on the crank at constant crank speed, eqs (6)-(11), by
// power balance over the links, plus the thrust-bearing friction moment (7).
//
// The swing plane is horizontal (a thrust bearing carries the platform's
// weight G, eq. 7), so gravity does no work and only inertia and friction
// load the crank. The crank turns uniformly: its inertia costs no moment.
#pragma once
#include <algorithm>
#include <cmath>
#include <vector>

#include "mech/cycle.hpp"
#include "mech/four_bar.hpp"

namespace mech {

template <class S>
struct SwingMechanism {
  FourBar<S> linkage;
  S crank_speed;          // w1 [rad/s], > 0
  S rod_mass_per_length;  // m_n of crank and coupler [kg/m], eq. (10)
  S platform_mass;        // m3 [kg]
  S platform_inertia;     // J_s3 about the platform's centre of mass [kg m^2], eq. (11)
  S platform_cg_radius;   // |O1 S3| [m]
  S friction_moment;      // M_c = f G D / 2 [N m], eq. (7), opposing the swing

  // Moment of inertia of the platform about its pivot O1 (parallel axes).
  S platform_pivot_inertia() const {
    return platform_inertia + platform_mass * platform_cg_radius * platform_cg_radius;
  }
  template <class F>
  auto map(F&& f) const -> SwingMechanism<decltype(f(crank_speed))> {
    return {linkage.map(f), f(crank_speed), f(rod_mass_per_length), f(platform_mass), f(platform_inertia),
            f(platform_cg_radius), f(friction_moment)};
  }
  template <class T>
  SwingMechanism<T> cast() const {
    return map([](const S& x) { return T(value(x)); });
  }
  SwingMechanism<lanes_of<S>> lanes() const { return map(LaneForm<S>::broadcast); }
};

// Whether the crank turns fully: the typed reason if not.
template <class S>
Status check(const SwingMechanism<S>& m) {
  const auto& k = m.linkage;
  if (!(value(k.crank) > 0 && value(k.coupler) > 0 && value(k.rocker) > 0 &&
        value(m.crank_speed) > 0 && value(m.platform_mass) >= 0 &&
        value(m.rod_mass_per_length) >= 0 && value(m.friction_moment) >= 0))
    return Status::invalid_parameter;
  const double l1 = value(k.crank), l2 = value(k.coupler), l3 = value(k.rocker);
  const double l4 = value(k.frame());
  // |O1A| spans [|l4 - l1|, l4 + l1]; the loop closes for [|l2 - l3|, l2 + l3].
  if (l4 + l1 < std::abs(l2 - l3) || std::abs(l4 - l1) > l2 + l3) return Status::cannot_assemble;
  if (grashof(l1, l2, l3, l4) == GrashofClass::non_grashof) return Status::not_grashof;
  if (!(value(rotation_margin(k)) > 0)) return Status::toggle_in_cycle;
  return Status::ok;
}

// Kinetic energy of the moving links over w1^2 at crank angle phi, from
// positions and first transfer functions only (the independent check of
// the balancing moment: M_inertia = dT/dphi at constant crank speed).
template <class S>
S swing_energy_per_w2(const SwingMechanism<S>& m, const FourBarPoint<S>& p) {
  const auto& k = m.linkage;
  const S m1 = m.rod_mass_per_length * k.crank, m2 = m.rod_mass_per_length * k.coupler;
  // Crank: rotation about O (eq. 10 inertia about its centre + m (l/2)^2).
  const S crank = m1 * k.crank * k.crank / 3.0;
  // Coupler centre: v = v_A + w2 (l2/2) e2_perp, per unit crank speed.
  const S vx = -k.crank * p.e1.y - p.w2 * 0.5 * k.coupler * p.e2.y;
  const S vy = k.crank * p.e1.x + p.w2 * 0.5 * k.coupler * p.e2.x;
  const S coupler = m2 * (vx * vx + vy * vy) + m2 * k.coupler * k.coupler / 12.0 * p.w2 * p.w2;
  return 0.5 * (crank + coupler + m.platform_pivot_inertia() * p.w3 * p.w3);
}

// Balancing moment on the crank and its parts at one crank angle.
template <class S>
struct SwingPoint {
  S inertia;   // from inertia forces and moments, eqs (8)-(11), by power balance
  S friction;  // thrust-bearing friction reduced to the crank: M_c |w3|
  S moment() const { return inertia + friction; }  // eq. (6): positive resists the drive
  FourBarPoint<S> kinematics;
};

// Power balance at constant crank speed: M w1 = sum(m a_s . v_s + J eps w)
// + M_c |w_3|, with a = w1^2 a', v = w1 v' from the transfer functions.
// check(m) must be ok.
// From c = cos(phi) and s = sin(phi).
template <class S>
SwingPoint<S> swing_point(const SwingMechanism<S>& m, const S& c, const S& s) {
  using std::abs;
  SwingPoint<S> out;
  auto& p = out.kinematics;
  four_bar_point(m.linkage, c, s, p);
  const auto& k = m.linkage;
  const S m2 = m.rod_mass_per_length * k.coupler, h = 0.5 * k.coupler;
  const S c1 = p.e1.x, s1 = p.e1.y, c2 = p.e2.x, s2 = p.e2.y;
  // Coupler centre velocity and acceleration per unit crank speed.
  const S vx = -k.crank * s1 - p.w2 * h * s2, vy = k.crank * c1 + p.w2 * h * c2;
  const S ax = -k.crank * c1 - p.alpha2 * h * s2 - p.w2 * p.w2 * h * c2;
  const S ay = -k.crank * s1 + p.alpha2 * h * c2 - p.w2 * p.w2 * h * s2;
  const S power = m2 * (ax * vx + ay * vy) + m2 * k.coupler * k.coupler / 12.0 * p.alpha2 * p.w2 +
                  m.platform_pivot_inertia() * p.alpha3 * p.w3;
  out.inertia = m.crank_speed * m.crank_speed * power;
  out.friction = m.friction_moment * abs(p.w3);
  return out;
}

template <class S>
SwingPoint<S> swing_point(const SwingMechanism<S>& m, const S& phi) {
  using std::cos;
  using std::sin;
  return swing_point(m, S(cos(phi)), S(sin(phi)));
}

// Grid points a revolution for the maxima and sign changes of the swing
// moment: n, or, near a toggle, where |M| spikes over a crank angle of
// about the poles' width (toggle_poles), four points a width (spread over
// the cycle; at most 2^17).
inline int swing_grid_points(const std::array<NearPole, 2>& poles, int n) {
  const double width = std::min(poles[0].width, poles[1].width);
  return std::max(n, static_cast<int>(std::min(std::ceil(4 * kTwoPi / width), double(1 << 17))));
}

template <class S>
struct SwingMetrics {
  S peak_moment;      // max over the cycle of |M| [N m]
  S mean_abs_moment;  // cycle mean of |M| [N m]
  S rms_moment;       // [N m]
  S max_pressure_angle;  // [rad]
  S swing_angle;      // rocker swing between the dead centres [rad]
  S time_ratio;       // K, eq. (5)
  double phi_peak_moment = 0, phi_max_pressure = 0;
};

// Cycle metrics with n grid points (the means only if `means`). Maxima over
// the cycle take their design
// derivative at the maximising angle (Danskin); |M| and the friction term have
// kinks (zeros of M, rocker reversals), so means integrate piecewise between
// them. check(m) must be ok. `scratch`: the grids' and searches' storage.
template <class S>
SwingMetrics<S> swing_metrics(const SwingMechanism<S>& m, int n, CycleScratch& scratch, bool means = true) {
  using std::abs;
  using std::sqrt;
  SwingMetrics<S> out;
  const SwingMechanism<double> md = m.template cast<double>();
  // The means' Gauss rule: 2n nodes a revolution, or more where the poles
  // ask (piecewise_means); the grid: swing_grid_points.
  const auto poles = toggle_poles(md.linkage);
  const int means_points = 2 * n;
  n = swing_grid_points(poles, n);
  std::vector<double>& grids = scratch.grids;  // no allocation per design once warm
  grids.resize(3 * static_cast<std::size_t>(n));
  const std::span<double> gridM(grids.data(), n), gridP(grids.data() + n, n), M(grids.data() + 2 * n, n);
  const SwingMechanism<Lanes> ml = md.lanes();
  for_each_grid_block(n, [&](int k, int lanes, const Lanes& c, const Lanes& s) {  // kLanes angles at a time
    const auto p = swing_point(ml, c, s);
    const Lanes moment = p.moment(), cosine = dot(p.kinematics.e2, p.kinematics.e3);
    for (int j = 0; j < lanes; ++j) {
      M[k + j] = moment[j];
      gridM[k + j] = std::abs(moment[j]);
      gridP[k + j] = std::asin(std::abs(cosine[j]));  // pressure_angle
    }
  });
  const auto dc = dead_centres(m.linkage);
  // Kinks: rocker reversals (w3 = 0, the friction term: the dead centres, in
  // closed form) and sign changes of M (for |M|, by root searches side by
  // side); M is smooth between them.
  if (means) {
    const std::span<const double> grid[1] = {M};
    std::vector<double> kinks = periodic_roots_together(std::span(grid), [&](std::span<AngleQuery> qs) {
      for_query_blocks(qs, [&](AngleQuery* q, int lanes, const Lanes& c, const Lanes& s) {
        const Lanes moment = swing_point(ml, c, s).moment();
        for (int j = 0; j < lanes; ++j) q[j].out = moment[j];
      });
    });
    for (double phi : {value(dc.phi_extended), value(dc.phi_folded)})
      kinks.push_back(wrap_angle(phi));
    ArcMeans<S> arcs;
    if constexpr (has_lanes<S>) {  // kLanes nodes at a time
      using L = lanes_of<S>;
      const SwingMechanism<L> mlanes = m.lanes();
      auto moment = [&](const Lanes&, const Lanes& c, const Lanes& s) { return swing_point(mlanes, L(c), L(s)).moment(); };
      arcs = piecewise_means<S>(moment, kinks, means_points, scratch, poles);
    } else {
      auto moment = [&](double, double c, double s) -> S { return swing_point(m, S(c), S(s)).moment(); };
      arcs = piecewise_means<S>(moment, kinks, means_points, scratch, poles);
    }
    out.mean_abs_moment = arcs.mean_abs;
    out.rms_moment = sqrt(arcs.mean_square);
  }
  // Maxima of |M| and of the pressure angle asin|e2 . e3|, searched together;
  // slopes in phi by a dual number.
  using LD = LaneDual<1>;
  const SwingMechanism<LD> mdual = md.map([](double x) { return LD(x); });
  CycleMaxSearch* searches = scratch.searches;  // kept: no allocation per design
  searches[0].reset(gridM), searches[1].reset(gridP);
  find_cycle_maxima(std::span(searches, 2), [&](std::span<AngleQuery> qs) {
    for_query_blocks(qs, [&](AngleQuery* q, int lanes, const Lanes& c, const Lanes& s) {
      LD cl(c), sl(s);  // slopes -sin, cos
      cl.d[0] = -s, sl.d[0] = c;
      const auto p = swing_point(mdual, cl, sl);
      const LD moment = p.moment(), u = dot(p.kinematics.e2, p.kinematics.e3);
      for (int j = 0; j < lanes; ++j) {
        AngleQuery& a = q[j];
        const double sign = a.fn == 0 ? (moment.v[j] >= 0 ? 1.0 : -1.0) : (u.v[j] < 0 ? -1.0 : 1.0);
        if (a.fn == 0) a.out = a.slope ? sign * moment.d[0][j] : std::abs(moment.v[j]);
        else  // d asin|u| / dphi = sign(u) u' / sqrt(1 - u^2)
          a.out = a.slope ? sign * u.d[0][j] / std::sqrt(1 - std::abs(u.v[j]) * std::abs(u.v[j]))
                          : std::asin(std::abs(u.v[j]));
      }
    });
  }, scratch);
  // The peaks' values: as the search found them (the lanes' sincos and
  // arithmetic, the scalar ones' bits), or at the same cosines with
  // derivatives in the design (Danskin).
  out.phi_peak_moment = searches[0].phi;
  out.phi_max_pressure = searches[1].phi;
  if constexpr (std::is_same_v<S, double>) {
    out.peak_moment = searches[0].value;
    out.max_pressure_angle = searches[1].value;
  } else {
    double c, s;
    sincos(out.phi_peak_moment, s, c);
    out.peak_moment = abs(swing_point(m, S(c), S(s)).moment());
    sincos(out.phi_max_pressure, s, c);
    FourBarPoint<S> pp;
    four_bar_point(m.linkage, S(c), S(s), pp);
    out.max_pressure_angle = pressure_angle(pp);
  }
  out.swing_angle = abs(dc.theta3_folded - dc.theta3_extended);
  out.time_ratio = time_ratio(dc);
  return out;
}

// The same with scratch of its own (tests, benchmarks).
template <class S>
SwingMetrics<S> swing_metrics(const SwingMechanism<S>& m, int n, bool means = true) {
  CycleScratch scratch;
  return swing_metrics(m, n, scratch, means);
}

}  // namespace mech
