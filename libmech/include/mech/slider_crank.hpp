// Slider-crank kinematics: slider position and its first and second transfer
// functions (derivatives with respect to the crank angle), rod angle and the
// rod-centre velocity components. Seed 000 eqs (1)-(8); seed 001 eqs (36)-(39).
//
// Frame: crank axis at the origin, crank pin at (r cos psi, r sin psi), slider
// axis along x at y = -e (e is the offset, or eccentricity). The rod (length l)
// runs from the pin to the slider with vertical extent h = r sin psi + e and
// horizontal extent sigma*sqrt(l^2 - h^2): sigma = +1 puts the slider on the +x
// side ("normal"), sigma = -1 on the -x side ("mirrored", seed 000 eq. 2).
// Units: metres and radians; transfer functions are per radian of crank angle.
#pragma once
#include <cmath>
#include <type_traits>

#include "mech/inline.hpp"
#include "mech/status.hpp"

namespace mech {

enum class Kinematics { exact, binomial };

template <class S>
struct SliderCrank {
  S r;       // crank radius [m], domain (0, inf)
  S l;       // rod length [m], domain (r + |e|, inf) for a full revolution
  S e;       // slider-axis offset [m]
  int sigma; // +1 normal, -1 mirrored
  Kinematics kinematics = Kinematics::exact;
};

// First-order transfer functions: all that velocities and kinetic energy need.
template <class S>
struct SliderCrankVelocity {
  S dx;          // slider d/dpsi (eqs 1-2)
  S dxs, dys;    // rod-centre d/dpsi (eqs 3-4)
  S dbeta;       // rod angle d/dpsi
};

// Transfer functions up to second order at one crank angle.
template <class S>
struct SliderCrankPoint : SliderCrankVelocity<S> {
  S x;             // slider position
  S ddx;           // eqs 5-6
  S ddxs, ddys;    // eqs 7-8
  S ddbeta;
};

// ... and the third-order ones: what the angle slope of the inertia moment
// (the derivative of eqs 18-20) needs.
template <class S>
struct SliderCrankPoint3 : SliderCrankPoint<S> {
  S dddx, dddxs, dddys, dddbeta;
};

// True when the rod reaches the slider axis at every crank angle.
template <class S>
bool assembles_over_cycle(const SliderCrank<S>& m) {
  using std::abs;
  return m.r > 0.0 && m.r + abs(m.e) < m.l;
}

namespace detail {
// Rod extent at one angle: vertical h and its derivatives, horizontal D, the
// inverse extent k used in derivatives (1/D exact, 1/l binomial) and
// g = -dD/dpsi.
template <class S>
struct Extent {
  S h, dh, ddh, D, k, g;
};

template <class S>
MECH_INLINE Extent<S> extent(const SliderCrank<S>& m, const S& c, const S& s) {
  using std::sqrt;
  Extent<S> x;
  x.h = m.r * s + m.e;
  x.dh = m.r * c;
  x.ddh = -m.r * s;
  if (m.kinematics == Kinematics::exact) {
    x.D = sqrt(m.l * m.l - x.h * x.h);
    x.k = 1.0 / x.D;
  } else {  // binomial: sqrt(l^2 - h^2) ~ l - h^2/(2l), seed 001 eqs (36)-(39)
    x.k = 1.0 / m.l;
    x.D = m.l - 0.5 * x.h * x.h * x.k;
  }
  x.g = x.h * x.dh * x.k;
  return x;
}

template <class S>
MECH_INLINE void first_order(const SliderCrank<S>& m, const Extent<S>& x, const S& s,
                 SliderCrankVelocity<S>& v) {
  const double sg = m.sigma;
  v.dx = -m.r * s - sg * x.g;
  v.dxs = 0.5 * (-m.r * s + v.dx);  // rod centre: midpoint of pin and slider
  v.dys = 0.5 * x.dh;
  v.dbeta = -sg * x.dh * x.k;
}
}  // namespace detail

// Velocity-level transfer functions at crank angle psi given c = cos psi and
// s = sin psi (passed in so a uniform grid can rotate them without trig
// calls). The caller guarantees assembly (assembles_over_cycle).
template <class S>
MECH_INLINE SliderCrankVelocity<S> slider_crank_velocity(const SliderCrank<S>& m, const S& c, const S& s) {
  SliderCrankVelocity<S> v;
  detail::first_order(m, detail::extent(m, c, s), s, v);
  return v;
}

// All transfer functions up to second order (see slider_crank_velocity), or
// up to third (P = SliderCrankPoint3). With k = 1/D and dk/dpsi = g k^2
// (exact extent): dg = (dh^2 + h ddh + g^2) k, ddg = (3 dh ddh + h dddh +
// 3 g dg) k, dddh = -dh; the binomial extent (k = 1/l) drops the g terms.
template <class S, class P = SliderCrankPoint<S>>
MECH_INLINE P slider_crank_point(const SliderCrank<S>& m, const S& c, const S& s) {
  const double sg = m.sigma;
  const bool exact = m.kinematics == Kinematics::exact;
  const auto x = detail::extent(m, c, s);
  P p;
  detail::first_order(m, x, s, p);
  // dg/dpsi; the exact extent adds g^2/D from the derivative of 1/D.
  S dg = (x.dh * x.dh + x.h * x.ddh) * x.k;
  S ddbeta_inner = x.ddh;
  if (exact) {
    dg += x.g * x.g * x.k;
    ddbeta_inner += x.dh * x.g * x.k;
  }
  p.x = m.r * c + sg * x.D;
  p.ddx = -m.r * c - sg * dg;
  p.ddxs = 0.5 * (-m.r * c + p.ddx);
  p.ddys = 0.5 * x.ddh;
  p.ddbeta = -sg * ddbeta_inner * x.k;
  if constexpr (std::is_same_v<P, SliderCrankPoint3<S>>) {
    const S dddh = -x.dh;
    S ddg = 3.0 * x.dh * x.ddh + x.h * dddh, dddbeta_inner = dddh;
    if (exact) {
      ddg += 3.0 * x.g * dg;
      dddbeta_inner += (2.0 * x.ddh * x.g + x.dh * dg + 2.0 * x.dh * x.g * x.g * x.k) * x.k;
    }
    p.dddx = m.r * s - sg * ddg * x.k;
    p.dddxs = 0.5 * (m.r * s + p.dddx);
    p.dddys = 0.5 * dddh;
    p.dddbeta = -sg * dddbeta_inner * x.k;
  }
  return p;
}

template <class S>
SliderCrankPoint<S> slider_crank_point(const SliderCrank<S>& m, const S& psi) {
  using std::cos;
  using std::sin;
  return slider_crank_point(m, S(cos(psi)), S(sin(psi)));
}

}  // namespace mech
