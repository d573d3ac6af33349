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

// Transfer functions of one slider-crank at one crank angle.
template <class S>
struct SliderCrankPoint {
  S x, dx, ddx;        // slider position and d/dpsi, d2/dpsi2 (eqs 1-2, 5-6)
  S dxs, ddxs;         // rod-centre x transfer functions (eqs 3-4, 7-8)
  S dys, ddys;         // rod-centre y transfer functions (eqs 3-4, 7-8)
  S dbeta, ddbeta;     // rod angle transfer functions
};

// True when the rod reaches the slider axis at every crank angle.
template <class S>
bool assembles_over_cycle(const SliderCrank<S>& m) {
  using std::abs;
  return m.r > 0.0 && m.r + abs(m.e) < m.l;
}

// Evaluates the transfer functions at crank angle psi given c = cos psi and
// s = sin psi (passed in so a uniform grid can rotate them without trig calls).
// The caller guarantees assembly (assembles_over_cycle).
template <class S>
SliderCrankPoint<S> slider_crank_point(const SliderCrank<S>& m, const S& c, const S& s) {
  using std::sqrt;
  const double sg = m.sigma;
  const S h = m.r * s + m.e;  // vertical extent of the rod
  const S dh = m.r * c;
  const S ddh = -m.r * s;
  SliderCrankPoint<S> p;
  if (m.kinematics == Kinematics::exact) {
    const S D = sqrt(m.l * m.l - h * h);  // horizontal extent of the rod
    const S invD = 1.0 / D;
    const S g = h * dh * invD;                                    // d(D)/dpsi = -g
    const S dg = (dh * dh + h * ddh) * invD + g * g * invD;       // dg/dpsi
    p.x = m.r * c + sg * D;
    p.dx = -m.r * s - sg * g;
    p.ddx = -m.r * c - sg * dg;
    p.dbeta = -sg * dh * invD;
    p.ddbeta = -sg * (ddh + dh * g * invD) * invD;
  } else {  // binomial: sqrt(l^2 - h^2) ~ l - h^2/(2l), seed 001 eqs (36)-(39)
    const S invl = 1.0 / m.l;
    const S g = h * dh * invl;
    const S dg = (dh * dh + h * ddh) * invl;
    p.x = m.r * c + sg * (m.l - 0.5 * h * h * invl);
    p.dx = -m.r * s - sg * g;
    p.ddx = -m.r * c - sg * dg;
    p.dbeta = -sg * dh * invl;
    p.ddbeta = -sg * ddh * invl;
  }
  // Rod centre: midpoint of pin (r c, r s) and slider (x, -e).
  p.dxs = 0.5 * (-m.r * s + p.dx);
  p.ddxs = 0.5 * (-m.r * c + p.ddx);
  p.dys = 0.5 * dh;
  p.ddys = 0.5 * ddh;
  return p;
}

template <class S>
SliderCrankPoint<S> slider_crank_point(const SliderCrank<S>& m, const S& psi) {
  using std::cos;
  using std::sin;
  return slider_crank_point(m, S(cos(psi)), S(sin(psi)));
}

}  // namespace mech
