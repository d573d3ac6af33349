// A linkage's joint reactions at one crank angle by the classical
// kinetostatic analysis: d'Alembert's inertia forces and every applied
// force (gravity, loads, springs: the ones dynamics.hpp's virtual power
// counts) on each link, then Newton-Euler group by group from the last
// group back to the crank, six equations of a group's two links in its six
// reaction components, closed form per type; the reactions a group takes
// at its known points go, reversed, onto the links that carry them. The
// crank's moment equation gives the driving torque, equal to the virtual
// power's to round-off (the tests' check). docs/design/linkage.md,
// section 3.
//
// Joints: a pin is a link turning on a point that another body carries
// (its owner: the link that defines it, or the ground), its reaction the
// force on the link from the owner; a slide is a slider on its line (RRP)
// or a block on its guide (RPR), or in a slider's slot and the slider on
// its line (RPP: two slides), or each of two pinned sliders on its own
// line (PRP: two slides), its reaction a force N along the line's normal
// rot90(u) and a couple C on the slider (block) from the body of the line
// (the guide, the slotted slider).
#pragma once
#include <vector>

#include "mech/linkage/dynamics.hpp"

namespace mech::linkage {

struct Pin {
  int point, link, owner;  // owner kNone: the ground
};

// A chain's joints in the order of solution: the crank's pivot, then per
// group RRR (first, p), (second, q), (second, joint); RRP (rod, p), (rod,
// joint); RPR (block, p), (guide, q); RPP (block, p); PRP (second, joint),
// the first slider owning the joint as an RRR group's first link does; one
// slide per RRP and RPR group, two per RPP (the block in the slot, the
// slider on its line) and PRP (the first slider, then the second).
struct Joints {
  std::vector<Pin> pins;
  std::vector<int> slides;      // the slider (block) link
  std::vector<int> first_pin;   // per group
  std::vector<int> owner;       // per point: the link that carries it (kNone: the ground)

  explicit Joints(const Chain& c) {
    owner.assign(c.point_names().size(), kNone);
    for (size_t k = 0; k < c.links().size(); ++k)
      for (const LocalPoint& lp : c.links()[k].points) owner[static_cast<size_t>(lp.point)] = static_cast<int>(k);
    const Crank& k = c.crank();
    owner[static_cast<size_t>(k.joint)] = k.link;
    add(k.pivot, k.link);
    for (const Group& g : c.groups()) {
      first_pin.push_back(static_cast<int>(pins.size()));
      switch (g.type) {
        case GroupType::RRR:
          owner[static_cast<size_t>(g.joint)] = g.first;
          add(g.p, g.first), add(g.q, g.second), add(g.joint, g.second);
          break;
        case GroupType::RRP:
          owner[static_cast<size_t>(g.joint)] = g.second;
          add(g.p, g.first), add(g.joint, g.first);
          slides.push_back(g.second);
          break;
        case GroupType::RPR:
          add(g.p, g.first), add(g.q, g.second);
          slides.push_back(g.first);
          break;
        case GroupType::RPP:
          owner[static_cast<size_t>(g.joint)] = g.second;
          add(g.p, g.first);
          slides.push_back(g.first), slides.push_back(g.second);
          break;
        case GroupType::PRP:
          owner[static_cast<size_t>(g.joint)] = g.first;
          add(g.joint, g.second);
          slides.push_back(g.first), slides.push_back(g.second);
          break;
      }
    }
  }

 private:
  void add(int point, int link) { pins.push_back({point, link, owner[static_cast<size_t>(point)]}); }
};

// A force and its moment about the origin.
template <class S>
struct Wrench {
  S fx, fy, m;
  // Its moment about point (x, y).
  S about(const S& x, const S& y) const { return S(m - (x * fy - y * fx)); }
};

template <class S>
struct Reactions {
  std::vector<S> x, y;            // per pin: the force on its link from its owner
  std::vector<S> normal, couple;  // per slide: on the slider (block) from its line's body (the guide)
  S torque = S(0.0);              // the driving torque in the crank's sense of rotation
  // The shaking force and moment: the inertia forces' resultant -sum m a_G
  // and their moment about the origin -sum (J alpha + G x m a_G), what the
  // frame passes to its foundation beyond the weights when the process
  // loads close through the frame.
  S shaking_x = S(0.0), shaking_y = S(0.0), shaking_m = S(0.0);
  std::vector<Wrench<S>> applied;  // per link: what acts on it but its reactions yet to solve (scratch)

  void resize(const Joints& j, const Chain& c) {
    x.resize(j.pins.size());
    y.resize(j.pins.size());
    normal.resize(j.slides.size());
    couple.resize(j.slides.size());
    applied.resize(c.links().size());
  }
};

// The reactions of the state st (solved at crank angle st.phi with values v).
template <class S>
void reactions(const Chain& c, const Joints& j, const S* v, const State<S>& st, Reactions<S>& r) {
  const S& w = v[c.crank().speed];
  const S w2 = w * w;
  const auto& links = c.links();
  for (auto& a : r.applied) a = {S(0.0), S(0.0), S(0.0)};
  auto force = [&](int link, const S& fx, const S& fy, const Vec<S>& at) {
    if (link == kNone) return;
    Wrench<S>& a = r.applied[static_cast<size_t>(link)];
    a.fx += fx, a.fy += fy, a.m += at.x.v * fy - at.y.v * fx;
  };
  auto couple = [&](int link, const S& m) {
    if (link != kNone) r.applied[static_cast<size_t>(link)].m += m;
  };
  // Inertia and weight.
  r.shaking_x = r.shaking_y = r.shaking_m = S(0.0);
  Inertial<S> b;
  for (size_t k = 0; k < links.size(); ++k) {
    if (!inertial(links[k], v, st, static_cast<int>(k), b)) continue;
    const S ix = -(b.m * w2 * b.G->x.dd), iy = -(b.m * w2 * b.G->y.dd), ia = -(b.J * w2 * st.rates(static_cast<int>(k)).dd);
    r.shaking_x += ix, r.shaking_y += iy, r.shaking_m += ia + (b.G->x.v * iy - b.G->y.v * ix);
    force(static_cast<int>(k), ix, S(iy - b.m * c.gravity()), *b.G);
    couple(static_cast<int>(k), ia);
  }
  // Loads and springs.
  S size(0.0), rate(0.0);
  for (const Load& l : c.loads()) {
    if (!load_action(c, l, v, st, st.phi, size, rate)) continue;
    if (l.kind == Load::Kind::force) {
      const size_t k = static_cast<size_t>(l.link);
      const Vec<S>& u = st.axis[k];
      force(l.link, S(size * u.x.v), S(size * u.y.v), st.point[static_cast<size_t>(links[k].origin)]);
    } else {
      couple(l.link, size);
      couple(l.other, S(-size));
    }
  }
  for (const Spring& sp : c.springs()) {
    const Tension<S> t = tension(sp, v, st);
    const S fx = t.tension * t.ux, fy = t.tension * t.uy;  // on q; minus on p
    force(j.owner[static_cast<size_t>(sp.p)], S(-fx), S(-fy), st.point[static_cast<size_t>(sp.p)]);
    force(j.owner[static_cast<size_t>(sp.q)], fx, fy, st.point[static_cast<size_t>(sp.q)]);
  }
  // The groups, last first: each one's reactions, and their opposites on
  // the bodies that carry its known points (and its line).
  auto pin = [&](int i, const S& fx, const S& fy) {
    const Pin& p = j.pins[static_cast<size_t>(i)];
    r.x[static_cast<size_t>(i)] = fx, r.y[static_cast<size_t>(i)] = fy;
    force(p.owner, S(-fx), S(-fy), st.point[static_cast<size_t>(p.point)]);
  };
  const auto& groups = c.groups();
  int slide = static_cast<int>(j.slides.size());
  // A slide's reaction (the slides are solved last first) and its opposite
  // on the body that carries the slider's line, at `at`.
  auto slide_reaction = [&](const S& N, const S& C) {
    --slide;
    r.normal[static_cast<size_t>(slide)] = N, r.couple[static_cast<size_t>(slide)] = C;
  };
  auto on_line = [&](int slider, const S& N, const S& C, const S& ux, const S& uy, const Vec<S>& at) {
    const int on = links[static_cast<size_t>(slider)].line_on;
    force(on, S(N * uy), S(-(N * ux)), at);
    couple(on, S(-C));
  };
  for (size_t g = groups.size(); g-- > 0;) {
    const Group& gr = groups[g];
    const int i = j.first_pin[g];
    const Wrench<S>& a1 = r.applied[static_cast<size_t>(gr.first)];
    const Wrench<S>& a2 = r.applied[static_cast<size_t>(gr.second)];
    const Vec<S>& e1 = st.axis[static_cast<size_t>(gr.first)];
    const S e1x = e1.x.v, e1y = e1.y.v;
    switch (gr.type) {
      case GroupType::RRR: {
        // Each link's moment about the joint B gives its pin force's normal
        // part at p (q); the two links' forces together the axial parts.
        const Vec<S>& e2 = st.axis[static_cast<size_t>(gr.second)];
        const S e2x = e2.x.v, e2y = e2.y.v;
        const Vec<S>& B = st.point[static_cast<size_t>(gr.joint)];
        const S n1 = a1.about(B.x.v, B.y.v) / v[links[static_cast<size_t>(gr.first)].length];
        const S n2 = a2.about(B.x.v, B.y.v) / v[links[static_cast<size_t>(gr.second)].length];
        const S rx = -(a1.fx + a2.fx) + n1 * e1y + n2 * e2y, ry = -(a1.fy + a2.fy) - n1 * e1x - n2 * e2x;
        const S det = e1x * e2y - e1y * e2x;
        const S t1 = (rx * e2y - ry * e2x) / det, t2 = (e1x * ry - e1y * rx) / det;
        const S r2x = t2 * e2x - n2 * e2y, r2y = t2 * e2y + n2 * e2x;
        const S fx = -a2.fx - r2x, fy = -a2.fy - r2y;  // on second from first, at B
        pin(i, S(t1 * e1x - n1 * e1y), S(t1 * e1y + n1 * e1x));
        pin(i + 1, r2x, r2y);
        r.x[static_cast<size_t>(i + 2)] = fx, r.y[static_cast<size_t>(i + 2)] = fy;
        break;
      }
      case GroupType::RRP: {
        // The slider's moment about its pin is the line's couple; the rod's
        // gives its pin force's normal part; the two links' forces along
        // the line its axial part.
        const Vec<S>& u = st.axis[static_cast<size_t>(gr.second)];
        const S ux = u.x.v, uy = u.y.v;
        const Vec<S>& B = st.point[static_cast<size_t>(gr.joint)];
        const S n1 = a1.about(B.x.v, B.y.v) / v[links[static_cast<size_t>(gr.first)].length];
        const S t1 = -((a1.fx + a2.fx) * ux + (a1.fy + a2.fy) * uy + n1 * (e1x * uy - e1y * ux)) /
                     (e1x * ux + e1y * uy);
        const S r1x = t1 * e1x - n1 * e1y, r1y = t1 * e1y + n1 * e1x;
        const S fx = -a1.fx - r1x, fy = -a1.fy - r1y;  // on the rod from the slider, at B
        const S N = (fx - a2.fx) * -uy + (fy - a2.fy) * ux, C = -a2.about(B.x.v, B.y.v);
        pin(i, r1x, r1y);
        r.x[static_cast<size_t>(i + 1)] = fx, r.y[static_cast<size_t>(i + 1)] = fy;
        slide_reaction(N, C);
        on_line(gr.second, N, C, ux, uy, B);
        break;
      }
      case GroupType::RPR: {
        // The block's moment about its pin is the guide's couple; the
        // guide's about its pivot gives the normal force (s: the block's
        // distance along the guide).
        const Vec<S>& P = st.point[static_cast<size_t>(gr.p)];
        const Vec<S>& Q = st.point[static_cast<size_t>(gr.q)];
        const S C = -a1.about(P.x.v, P.y.v);
        const S N = (a2.about(Q.x.v, Q.y.v) - C) / st.slide[static_cast<size_t>(gr.first)].v;
        const S nx = -e1y, ny = e1x;
        pin(i, S(-a1.fx - N * nx), S(-a1.fy - N * ny));
        pin(i + 1, S(-a2.fx + N * nx), S(-a2.fy + N * ny));
        slide_reaction(N, C);
        break;
      }
      case GroupType::RPP: {
        // The block's moment about its pin P is the slot's couple; the
        // slider's forces along its line the slot's normal force N1 (along
        // m = rot90(w), w the slot, the block's axis e1); across it, and its
        // moment about its point J on the line, the line's N2 and C2.
        const Vec<S>& u = st.axis[static_cast<size_t>(gr.second)];
        const S ux = u.x.v, uy = u.y.v, mx = -e1y, my = e1x;
        const Vec<S>& P = st.point[static_cast<size_t>(gr.p)];
        const Vec<S>& J = st.point[static_cast<size_t>(gr.joint)];
        const S C1 = -a1.about(P.x.v, P.y.v);
        const S N1 = (a2.fx * ux + a2.fy * uy) / (mx * ux + my * uy);
        const S N2 = N1 * (mx * -uy + my * ux) - (a2.fx * -uy + a2.fy * ux);
        const S arm = (P.x.v - J.x.v) * (N1 * my) - (P.y.v - J.y.v) * (N1 * mx);  // N1 m at P about J
        const S C2 = -a2.about(J.x.v, J.y.v) + arm + C1;
        pin(i, S(-a1.fx - N1 * mx), S(-a1.fy - N1 * my));
        slide_reaction(N2, C2);
        slide_reaction(N1, C1);
        on_line(gr.second, N2, C2, ux, uy, J);
        break;
      }
      case GroupType::PRP: {
        // Each slider's moment about the pin B is its line's couple; the two
        // sliders' forces together the lines' normal forces, N1 n1 + N2 n2 =
        // -(a1 + a2) (Cramer, over u1 x u2); the second's alone the pin's.
        const Vec<S>& u2 = st.axis[static_cast<size_t>(gr.second)];
        const S u2x = u2.x.v, u2y = u2.y.v;
        const Vec<S>& B = st.point[static_cast<size_t>(gr.joint)];
        const S C1 = -a1.about(B.x.v, B.y.v), C2 = -a2.about(B.x.v, B.y.v);
        const S rx = -(a1.fx + a2.fx), ry = -(a1.fy + a2.fy), det = e1x * u2y - e1y * u2x;
        // n1 = rot90(u1), n2 = rot90(u2): N1 = (r x n2) / det, N2 = (n1 x r) / det.
        const S N1 = (rx * u2x + ry * u2y) / det, N2 = -(e1x * rx + e1y * ry) / det;
        r.x[static_cast<size_t>(i)] = -a2.fx + N2 * u2y, r.y[static_cast<size_t>(i)] = -a2.fy - N2 * u2x;
        slide_reaction(N2, C2);
        slide_reaction(N1, C1);
        on_line(gr.second, N2, C2, u2x, u2y, B);
        on_line(gr.first, N1, C1, e1x, e1y, B);
        break;
      }
    }
  }
  // The crank: its pivot's force and the torque that holds its moment.
  const Crank& k = c.crank();
  const Wrench<S>& a = r.applied[static_cast<size_t>(k.link)];
  const Vec<S>& O = st.point[static_cast<size_t>(k.pivot)];
  r.x[0] = -a.fx, r.y[0] = -a.fy;
  r.torque = S(-a.about(O.x.v, O.y.v) * double(k.sense));
}

}  // namespace mech::linkage
