// Reads a linkage description (docs/design/linkage.md, section 1) into a
// chain and its table, in this order: ground points; links with their
// numbers and local points; the crank; the groups (each slider's line is
// placed where its group is read, when its points are known); the branches
// given by `near:`; the loads and springs; the outputs. Every number is
// read with its unit and becomes a row named by its address.
#include "problems/linkage/description.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <map>
#include <stdexcept>
#include <tuple>

#include "mech/linkage/kinematics.hpp"
#include "problems/linkage/kinks.hpp"

namespace problems::linkage {
namespace {

using mech::linkage::kNone;
using mech::linkage::Slot;
using opt::ConfigNode;
using opt::Dimension;

// The model of a config without one: a slider-crank (seed 000's design).
constexpr const char* kDefaultModel = R"(
problem: linkage
model:
  ground: {O: [0 m, 0 m], S0: [0 m, 0 m]}
  crank: {link: crank, pivot: O, joint: A, phase: 0 deg, speed: 100 rev/min, sense: ccw}
  links:
    crank: {length: 0.2 m}
    rod: {length: 0.8 m}
    ram: {mass: 1 kg, line: {fixed_to: ground, through: S0, angle: 0 deg}}
  groups:
    - {type: RRP, links: [rod, ram], from: A, joint: B, branch: 1}
  outputs: [ram]
)";

bool identifier(const std::string& s) {
  if (s.empty() || !(std::isalpha(static_cast<unsigned char>(s[0])) || s[0] == '_')) return false;
  for (char ch : s)
    if (!(std::isalnum(static_cast<unsigned char>(ch)) || ch == '_')) return false;
  return true;
}

class Reader {
 public:
  explicit Reader(const ConfigNode& model) : model_(model) {}

  Description read() {
    model_.allow_only(
        {"gravity", "cycle_points", "speed_fluctuation", "ground", "crank", "links", "groups", "loads", "springs",
         "outputs"});
    if (model_.has("gravity")) {  // on (standard gravity), off, or an acceleration (a paper's 9.81 m/s^2)
      const ConfigNode g = model_.at("gravity");
      const std::string t = g.text();
      if (t == "on" || t == "off" || t == "true" || t == "false")
        d_.chain.set_gravity(t == "on" || t == "true" ? 9.80665 : 0.0);
      else
        d_.chain.set_gravity(g.quantity(Dimension::acceleration, opt::kNonNegative));
    }
    if (model_.has("cycle_points")) {
      const ConfigNode points = model_.at("cycle_points");
      const std::string t = points.text();
      if (t != "auto") {
        char* end = nullptr;
        std::strtod(t.c_str(), &end);
        if (t.empty() || *end != '\0') points.fail("expected auto or a whole number from 8 to 100000, got '" + t + "'");
        d_.cycle_points = points.integer(8, 100000);
      }
    }
    if (model_.has("speed_fluctuation"))
      d_.speed_fluctuation = number(model_.at("speed_fluctuation"), "speed_fluctuation", Dimension::dimensionless,
                                    {0, 1, true, false}, "the coefficient of speed fluctuation a flywheel keeps");
    const ConfigNode ground = model_.at("ground");
    for (const auto& name : ground.keys()) {
      const ConfigNode p = ground.at(name);
      check_name(p, name);
      const auto [x, y] = pair(p, "ground." + name, "a ground point");
      d_.chain.ground(name, x, y);
    }
    const ConfigNode links = model_.at("links");
    for (const auto& name : links.keys()) read_link(links.at(name), name);
    read_crank(model_.at("crank"));
    const ConfigNode groups = model_.at("groups");
    for (const auto& g : groups.items()) read_group(g);
    for (size_t k = 0; k < d_.chain.links().size(); ++k)
      if (d_.chain.links()[k].origin == kNone)
        links.at(d_.chain.links()[k].name).fail("no group or crank solves this link");
    choose_branches();
    if (model_.has("loads")) {
      const ConfigNode loads = model_.at("loads");
      for (const auto& name : loads.keys()) read_load(loads.at(name), name);
    }
    if (model_.has("springs")) {
      const ConfigNode springs = model_.at("springs");
      for (const auto& name : springs.keys()) read_spring(springs.at(name), name);
    }
    place_defaults();
    if (model_.has("outputs"))
      for (const auto& o : model_.at("outputs").items()) {
        const int k = link(o);
        const auto& l = d_.chain.links()[static_cast<size_t>(k)];
        d_.outputs.push_back({k, l.length == kNone, l.name});
      }
    return std::move(d_);
  }

 private:
  // A number read with its unit: a row named `address`, and its slot.
  Slot number(const ConfigNode& n, const std::string& address, Dimension dim, const opt::Domain& domain,
              const std::string& doc) {
    return add(address, dim, domain, doc, n.quantity(dim, domain));
  }
  Slot add(const std::string& address, Dimension dim, const opt::Domain& domain, const std::string& doc,
           double value) {
    opt::Parameter p = opt::variable(address, dim, domain, doc, "");
    p.value = value;
    d_.table.push_back(p);
    return d_.chain.value(address, value);
  }
  Slot number_at(const ConfigNode& n, const std::string& key, const std::string& address, Dimension dim,
                 const opt::Domain& domain, const std::string& doc) {
    return number(n.at(key), address + "." + key, dim, domain, doc);
  }
  // [x, y] with units, or {x: .., y: ..} (as a config over a base writes one).
  std::pair<Slot, Slot> pair(const ConfigNode& n, const std::string& address, const std::string& what) {
    if (n.is_map()) {
      n.allow_only({"x", "y"});
      return {number_at(n, "x", address, Dimension::length, opt::kAnyValue, what + ", x"),
              number_at(n, "y", address, Dimension::length, opt::kAnyValue, what + ", y")};
    }
    const auto items = n.items();
    if (items.size() != 2) n.fail("expected a point [x, y] with units, e.g. [0.8 m, 0 m]");
    return {number(items[0], address + ".x", Dimension::length, opt::kAnyValue, what + ", x"),
            number(items[1], address + ".y", Dimension::length, opt::kAnyValue, what + ", y")};
  }
  void check_name(const ConfigNode& n, const std::string& name) {
    if (!identifier(name)) n.fail("a name is letters, digits and _ (not starting with a digit); got '" + name + "'");
    if (d_.chain.find_point(name) != kNone) n.fail("point '" + name + "' is defined twice");
  }
  int point(const ConfigNode& n) {
    const std::string name = n.text();
    const int p = d_.chain.find_point(name);
    if (p == kNone) {
      std::string known;
      for (const auto& q : d_.chain.point_names()) known += (known.empty() ? "" : ", ") + q;
      n.fail("unknown point '" + name + "'; the points are: " + known);
    }
    return p;
  }
  int link(const ConfigNode& n) {
    const std::string name = n.text();
    const int k = d_.chain.find_link(name);
    if (k == kNone) {
      std::string known;
      for (const auto& l : d_.chain.links()) known += (known.empty() ? "" : ", ") + l.name;
      n.fail("unknown link '" + name + "'; the links are: " + known);
    }
    return k;
  }

  void read_link(const ConfigNode& n, const std::string& name) {
    if (!identifier(name)) n.fail("a name is letters, digits and _ (not starting with a digit); got '" + name + "'");
    n.allow_only({"length", "points", "mass", "cg", "inertia", "mass_per_length", "line", "offset", "slot"});
    const std::string at = "links." + name;
    auto& c = d_.chain;
    const int k = c.link(name);
    if (n.has("length"))
      c.set_length(k, number_at(n, "length", at, Dimension::length, opt::kPositive, "link length"));
    if (n.has("points")) {
      const ConfigNode pts = n.at("points");
      for (const auto& p : pts.keys()) {
        check_name(pts.at(p), p);
        const auto [u, v] = pair(pts.at(p), at + ".points." + p, "a point on " + name + " in its frame");
        c.local_point(k, p, u, v);
      }
    }
    if (n.has("mass_per_length")) {
      if (n.has("mass")) n.at("mass").fail("give mass (with cg and inertia) or mass_per_length, not both");
      if (!n.has("length")) n.at("mass_per_length").fail("a uniform bar needs the link's length");
      c.set_bar(k, number_at(n, "mass_per_length", at, Dimension::linear_density, opt::kNonNegative,
                             "a uniform bar's mass per length"));
      d_.has_mass = true;
    } else if (n.has("mass")) {
      const Slot m = number_at(n, "mass", at, Dimension::mass, opt::kNonNegative, "mass");
      Slot u = kNone, v = kNone;
      if (n.has("cg")) std::tie(u, v) = pair(n.at("cg"), at + ".cg", "centre of mass in " + name + "'s frame");
      const Slot J = n.has("inertia") ? number_at(n, "inertia", at, Dimension::inertia, opt::kNonNegative,
                                                  "moment of inertia about the centre of mass")
                                      : kNone;
      c.set_body(k, m, u, v, J);
      d_.has_mass = true;
    } else {
      for (const char* key : {"cg", "inertia"})
        if (n.has(key)) n.at(key).fail("a centre of mass and an inertia need the link's mass");
    }
    if (n.has("slot"))
      c.set_slot(k, number_at(n, "slot", at, Dimension::angle, opt::kAnyValue,
                              "the slider's slot, from its line (an RPP group's block slides in it)"));
    if (n.has("offset"))
      c.set_guide_offset(k, number_at(n, "offset", at, Dimension::length, opt::kAnyValue,
                                      "the guide's slide line left of its x axis"));
    if (n.has("line")) {
      const ConfigNode line = n.at("line");
      line.allow_only({"fixed_to", "through", "angle", "offset"});
      line.at("through");  // required; placed with its group
      const Slot angle = number_at(line, "angle", at + ".line", Dimension::angle, opt::kAnyValue,
                                   "the slider's line, in the frame of the link it is fixed to");
      const Slot offset = line.has("offset") ? number_at(line, "offset", at + ".line", Dimension::length,
                                                         opt::kAnyValue, "the pin left of the slider's line")
                                             : kNone;
      lines_.emplace(k, Line{line, angle, offset});
    }
  }

  void read_crank(const ConfigNode& n) {
    n.allow_only({"link", "pivot", "joint", "phase", "speed", "sense"});
    const int k = link(n.at("link"));
    const int pivot = point(n.at("pivot"));
    const std::string joint = n.at("joint").text();
    check_name(n.at("joint"), joint);
    const char* phase_doc = "the crank's angle at crank angle 0";
    const Slot phase = n.has("phase") ? number_at(n, "phase", "crank", Dimension::angle, opt::kAnyValue, phase_doc)
                                      : add("crank.phase", Dimension::angle, opt::kAnyValue, phase_doc, 0.0);
    const Slot speed = number_at(n, "speed", "crank", Dimension::angular_speed, opt::kPositive,
                                 "the crank's constant speed");
    const int sense = n.has("sense") ? (n.at("sense").choice({"ccw", "cw"}) == "ccw" ? 1 : -1) : 1;
    try {
      d_.chain.crank(k, pivot, joint, phase, speed, sense);
    } catch (const std::invalid_argument& e) {
      n.fail(e.what());
    }
  }

  void read_group(const ConfigNode& g) {
    const std::string type = g.at("type").choice({"RRR", "RRP", "RPR", "RPP", "PRP"});
    auto& c = d_.chain;
    const auto ls = g.at("links").items();
    if (ls.size() != 2) g.at("links").fail("expected the group's two links [first, second]");
    const int first = link(ls[0]), second = link(ls[1]);
    const int index = static_cast<int>(c.groups().size());
    try {
      if (type == "RRR") {
        g.allow_only({"type", "links", "from", "joint", "branch", "near"});
        const auto from = g.at("from").items();
        if (from.size() != 2) g.at("from").fail("expected the two known points [P, Q] the links start from");
        c.rrr(first, second, point(from[0]), point(from[1]), new_joint(g), branch(g, index));
      } else if (type == "RRP" || type == "RPP") {
        if (type == "RRP") g.allow_only({"type", "links", "from", "joint", "branch", "near"});
        else g.allow_only({"type", "links", "from", "joint"});
        place_line(ls[1], second);
        if (type == "RRP") c.rrp(first, second, point(g.at("from")), new_joint(g), branch(g, index));
        else c.rpp(first, second, point(g.at("from")), new_joint(g));
      } else if (type == "PRP") {
        g.allow_only({"type", "links", "joint"});
        place_line(ls[0], first);
        place_line(ls[1], second);
        c.prp(first, second, new_joint(g));
      } else {
        g.allow_only({"type", "links", "from", "pivot"});
        c.rpr(first, second, point(g.at("from")), point(g.at("pivot")));
      }
    } catch (const std::invalid_argument& e) {
      g.fail(e.what());
    }
    nodes_.push_back(g);
  }
  // Slider k's line (its link named at `at` in the group's links), placed
  // now that the points before its group are known.
  void place_line(const ConfigNode& at, int k) {
    const auto line = lines_.find(k);
    if (line == lines_.end()) at.fail("the slider '" + at.text() + "' has no line: {fixed_to, through, angle}");
    const ConfigNode& ln = line->second.node;
    const int on = ln.has("fixed_to") && ln.at("fixed_to").text() != "ground" ? link(ln.at("fixed_to")) : kNone;
    const int through = point(ln.at("through"));
    if (!fixed_on(through, on)) {
      std::string what = "the line is fixed to ";
      what += on == kNone ? std::string("the ground") : "link " + ln.at("fixed_to").text();
      what += "; its point '" + ln.at("through").text() + "' must be fixed there too";
      ln.at("through").fail(what);
    }
    d_.chain.set_line(k, on, through, line->second.angle, line->second.offset);
  }
  // Whether point p is fixed on link k (kNone: the ground): a ground point;
  // the link's origin, one of its points, or the joint its group or the
  // crank gives it.
  bool fixed_on(int p, int k) const {
    const auto& c = d_.chain;
    if (k == kNone) {
      for (const auto& g : c.ground_points())
        if (g.first == p) return true;
      return false;
    }
    const auto& l = c.links()[static_cast<size_t>(k)];
    if (l.origin == p || (c.crank().link == k && c.crank().joint == p)) return true;
    for (const auto& lp : l.points)
      if (lp.point == p) return true;
    for (const auto& g : c.groups())
      if ((g.first == k || g.second == k) && g.joint == p) return true;
    return false;
  }
  std::string new_joint(const ConfigNode& g) {
    const std::string name = g.at("joint").text();
    check_name(g.at("joint"), name);
    return name;
  }
  int branch(const ConfigNode& g, int index) {
    if (g.has("near")) {
      if (g.has("branch")) g.at("near").fail("give branch or near, not both");
      const auto items = g.at("near").items();
      if (items.size() != 2) g.at("near").fail("expected a point [x, y] with units near the joint at crank angle 0");
      near_.push_back({index, items[0].quantity(Dimension::length), items[1].quantity(Dimension::length)});
      return 1;
    }
    return g.at("branch").choice({"1", "+1", "-1"}) == "-1" ? -1 : 1;
  }

  // A load (docs/design/linkage.md, "Loads"): on a slider a force, on a
  // link a torque, at a point a friction torque between the two bodies
  // that meet there.
  void read_load(const ConfigNode& n, const std::string& name) {
    if (!identifier(name)) n.fail("a name is letters, digits and _ (not starting with a digit); got '" + name + "'");
    const std::string at = "loads." + name;
    mech::linkage::Load l;
    if (n.has("at")) {
      n.allow_only({"at", "friction_torque"});
      l.kind = mech::linkage::Load::Kind::friction;
      std::tie(l.link, l.other) = bodies_at(n.at("at"));
      l.value = number_at(n, "friction_torque", at, Dimension::torque, opt::kNonNegative,
                          "a friction torque against the relative rotation");
      d_.chain.add_load(std::move(l));
      return;
    }
    n.allow_only({"link", "force", "torque", "table", "law", "a", "b", "area", "contact", "depth", "when",
                  "opposing", "efficiency"});
    l.link = link(n.at("link"));
    const bool slider = d_.chain.links()[static_cast<size_t>(l.link)].length == kNone;
    l.kind = slider ? mech::linkage::Load::Kind::force : mech::linkage::Load::Kind::torque;
    const char* size_key = slider ? "force" : "torque";
    const Dimension size_dim = slider ? Dimension::force : Dimension::torque;
    for (const char* wrong : {"force", "torque"})
      if (n.has(wrong) && std::string(wrong) != size_key)
        n.at(wrong).fail(std::string("'") + n.at("link").text() + "' is " +
                         (slider ? "a slider: a force along its line" : "a link: a torque on it"));
    for (const char* key : {"law", "a", "b", "area", "contact", "depth"})
      if (n.has(key) && (!slider || !n.has("law")))
        n.at(key).fail(slider ? "a pressure law's key: it goes with law: exponential"
                              : "a pressure law acts on a slider; '" + n.at("link").text() + "' is a link");
    if (n.has("table") + n.has(size_key) + n.has("law") != 1)
      n.fail(std::string("give ") + size_key + (slider ? ", table or law" : " or table") + ", one of them");
    if (n.has("law")) {
      read_law(n, at, l);
    } else if (n.has(size_key)) {
      l.value = number_at(n, size_key, at, size_dim, opt::kAnyValue, std::string("a ") + size_key + " load");
    } else {
      const ConfigNode t = n.at("table");
      t.allow_only({"over", "unit", "rows"});
      const bool position = t.at("over").choice({"position", "crank_angle"}) == "position";
      l.over = position ? mech::linkage::Load::Over::position : mech::linkage::Load::Over::crank_angle;
      const auto units = t.at("unit").items();
      if (units.size() != 2) t.at("unit").fail("expected the two columns' units, e.g. [m, kN]");
      const Dimension x_dim = position ? (slider ? Dimension::length : Dimension::angle) : Dimension::angle;
      const double xs = scale(units[0], x_dim), ys = scale(units[1], size_dim);
      for (const auto& row : t.at("rows").items()) {
        const auto xy = row.items();
        if (xy.size() != 2) row.fail("expected a row [x, value]");
        l.xs.push_back(xy[0].number() * xs);
        l.ys.push_back(xy[1].number() * ys);
        if (l.xs.size() > 1 && !(l.xs.back() > l.xs[l.xs.size() - 2])) row.fail("the rows' x must increase");
      }
      if (l.xs.empty()) t.at("rows").fail("expected at least one row");
    }
    if (n.has("when")) {
      const std::string w = n.at("when").choice({"forward", "return", "always"});
      l.when = w == "forward" ? 1 : w == "return" ? -1 : 0;
    }
    if (n.has("opposing")) l.opposing = n.at("opposing").boolean();
    if (n.has("efficiency"))
      l.efficiency = number_at(n, "efficiency", at, Dimension::dimensionless, {0, 1, true, false},
                               "the drive supplies the load's power over this");
    d_.chain.add_load(std::move(l));
  }
  // Seed 003's pressure law p = a e^(b d) over the depth d = s - contact
  // of the slider's coordinate s, its force -p area along the line.
  void read_law(const ConfigNode& n, const std::string& at, mech::linkage::Load& l) {
    n.at("law").choice({"exponential"});
    l.law_a = number_at(n, "a", at, Dimension::pressure, opt::kAnyValue, "the pressure at zero depth, a of a e^(b d)");
    l.law_b = number_at(n, "b", at, Dimension::inverse_length, opt::kAnyValue, "the exponent's rate, b of a e^(b d)");
    l.law_area = number_at(n, "area", at, Dimension::area, opt::kNonNegative, "the area the pressure acts on");
    if (n.has("contact") == n.has("depth"))
      n.fail("give contact (the coordinate where the depth starts) or depth (the depth at the stroke's end), one");
    if (n.has("contact")) {
      l.law_contact = number_at(n, "contact", at, Dimension::length, opt::kAnyValue,
                                "the slider's coordinate where the depth starts");
      return;
    }
    l.law_depth = number_at(n, "depth", at, Dimension::length, opt::kAnyValue,
                            "the depth at the end of the stroke: the contact follows the design");
    l.law_contact = add(at + ".contact", Dimension::length, opt::kAnyValue,
                        "the slider's largest coordinate less the depth (follows the design)", 0.0);
    d_.derived.push_back(l.law_contact);
  }
  // The derived contacts at the description's own values.
  void place_defaults() {
    if (d_.derived.empty()) return;
    std::vector<double> v = d_.chain.defaults(), plain, grid;
    mech::linkage::State<double> sd;
    sd.resize(d_.chain);
    placed(d_.chain, d_.mean_points(), v, plain, grid, sd);
    for (const auto s : d_.derived) {
      d_.chain.set_default(s, v[static_cast<size_t>(s)]);
      d_.table[static_cast<size_t>(s)].value = v[static_cast<size_t>(s)];
    }
  }
  // A spring between two points (each a ground point or fixed on a link).
  void read_spring(const ConfigNode& n, const std::string& name) {
    if (!identifier(name)) n.fail("a name is letters, digits and _ (not starting with a digit); got '" + name + "'");
    n.allow_only({"between", "rate", "free_length"});
    const auto ends = n.at("between").items();
    if (ends.size() != 2) n.at("between").fail("expected the spring's two points [P, Q]");
    const std::string at = "springs." + name;
    d_.chain.add_spring({point(ends[0]), point(ends[1]),
                         number_at(n, "rate", at, Dimension::linear_stiffness, opt::kNonNegative, "a spring's rate"),
                         number_at(n, "free_length", at, Dimension::length, opt::kNonNegative,
                                   "a spring's free length")});
  }

  // The SI value of one `unit` (a table column's), of dimension d.
  static double scale(const ConfigNode& unit, Dimension d) {
    const opt::ParsedQuantity q = opt::parse_quantity("1 " + unit.text(), d);
    if (!q.error.empty()) unit.fail("expected a unit of " + opt::to_string(d) + ": " + q.error);
    return q.value;
  }
  // The two bodies (links, kNone for the ground) that meet at a point.
  std::pair<int, int> bodies_at(const ConfigNode& n) {
    const int p = point(n);
    const auto& c = d_.chain;
    std::vector<int> bodies;
    auto add = [&](int b) {
      if (std::find(bodies.begin(), bodies.end(), b) == bodies.end()) bodies.push_back(b);
    };
    for (const auto& g : c.ground_points())
      if (g.first == p) add(kNone);
    if (c.crank().joint == p) add(c.crank().link);
    for (size_t k = 0; k < c.links().size(); ++k) {
      if (c.links()[k].origin == p) add(static_cast<int>(k));
      for (const auto& lp : c.links()[k].points)
        if (lp.point == p) add(static_cast<int>(k));
    }
    for (const auto& g : c.groups())
      if (g.joint == p) add(g.first), add(g.second);
    if (bodies.size() != 2)
      n.fail(std::to_string(bodies.size()) + " bodies meet at '" + n.text() +
             "'; a joint's friction needs exactly two (a pin between two links, or a link and the ground)");
    if (bodies[0] == kNone) std::swap(bodies[0], bodies[1]);  // the ground second
    return {bodies[0], bodies[1]};
  }

  // Each `near:` group takes the branch whose joint lies nearer the given
  // point at crank angle 0 (the groups before it settled first).
  void choose_branches() {
    mech::linkage::State<double> st;
    st.resize(d_.chain);
    auto& c = d_.chain;
    for (const Near& n : near_) {
      const int joint = c.groups()[static_cast<size_t>(n.group)].joint;
      double dist[2];
      for (int b : {0, 1}) {
        c.set_branch(n.group, b == 0 ? 1 : -1);
        mech::linkage::solve(c, c.defaults().data(), 0.0, st);
        const bool reached = st.failed == kNone || st.failed > n.group;
        const auto& p = st.point[static_cast<size_t>(joint)];
        dist[b] = reached ? std::hypot(p.x.v - n.x, p.y.v - n.y) : HUGE_VAL;
      }
      if (!std::isfinite(dist[0]) && !std::isfinite(dist[1]))
        nodes_[static_cast<size_t>(n.group)].fail("the group cannot assemble at crank angle 0");
      c.set_branch(n.group, dist[0] <= dist[1] ? 1 : -1);
    }
    // A PRP group fails only where its lines are parallel; all but
    // parallel (its margin below the evaluation's singular threshold) it
    // would stop every evaluation: both are said so.
    auto prp = [&](int g) {
      return c.groups()[static_cast<size_t>(g)].type == mech::linkage::GroupType::PRP;
    };
    auto fail = [&](int g) {
      nodes_[static_cast<size_t>(g)].fail(
          c.group_name(g) + (prp(g) ? ": its sliders' lines are parallel at crank angle 0 (the pin has no place)"
                                         : " cannot assemble at crank angle 0 with these values"));
    };
    if (!mech::linkage::solve(c, c.defaults().data(), 0.0, st)) fail(st.failed);
    for (int g = 0; g < static_cast<int>(c.groups().size()); ++g)
      if (prp(g) && st.margin[static_cast<size_t>(g)] < 1e-6) fail(g);
  }

  struct Line {
    ConfigNode node;
    Slot angle, offset;
  };
  struct Near {
    int group;
    double x, y;
  };
  const ConfigNode& model_;
  Description d_;
  std::map<int, Line> lines_;  // by slider link
  std::vector<Near> near_;
  std::vector<ConfigNode> nodes_;  // each group's, for errors
};

}  // namespace

Description read_description(const ConfigNode& root) {
  if (!root.has("model")) return read_description(ConfigNode::parse(kDefaultModel, "<linkage default>"));
  return read_model(root.at("model"));
}

Description read_model(const ConfigNode& model) { return Reader(model).read(); }

void check_derived_not_free(const Description& d, const ConfigNode& root, const std::vector<opt::Variable>& vars,
                            const std::string& prefix) {
  for (const auto& var : vars)
    for (const auto s : d.derived)
      if (var.name == prefix + d.table[static_cast<size_t>(s)].name)
        root.at("variables").at(var.name).fail("the contact follows the law's depth: free the depth instead");
}

}  // namespace problems::linkage
