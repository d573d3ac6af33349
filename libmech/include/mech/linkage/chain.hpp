// A single-degree-of-freedom planar linkage as data: a driving crank and a
// chain of class II Assur groups in the order of solution, points and links
// as indices into flat arrays, every number a slot of one values vector (the
// problem's parameter table: docs/design/linkage.md, section 2). The chain
// holds no number itself, so one chain serves every scalar and every design;
// mech/linkage/kinematics.hpp solves it. Built by its add_* functions, which
// check the topology (a problem's reader checks the same first, to name the
// file and line).
#pragma once
#include <initializer_list>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace mech::linkage {

// A row of the values vector; kNone: absent (a ground line, no offset).
using Slot = int;
inline constexpr int kNone = -1;

enum class GroupType {
  RRR,  // two links from two known points to a new joint
  RRP,  // a rod from a known point to a slider's pin on a line
  RPR,  // a block pinned at a known point sliding along a guide that turns about another
  RPP,  // a block pinned at a known point sliding in a slot across a slider on a line (a scotch yoke)
  PRP,  // two sliders, each on its own line, pinned together at a new joint (a wedge)
};
inline const char* to_string(GroupType t) {
  switch (t) {
    case GroupType::RRR: return "RRR";
    case GroupType::RRP: return "RRP";
    case GroupType::RPR: return "RPR";
    case GroupType::RPP: return "RPP";
    case GroupType::PRP: return "PRP";
  }
  return "?";
}

// A point fixed on a link at local coordinates (u, v) in its frame.
struct LocalPoint {
  int point;
  Slot u, v;
};

struct Link {
  std::string name;
  int origin = kNone;    // the point at its frame's origin, set by the group that solves it
  Slot length = kNone;   // none for a slider and a block
  std::vector<LocalPoint> points;
  // A slider's line (RRP, RPP, PRP): through a known point, at an angle in the frame
  // of link `on` (kNone: the ground), the pin `offset` to its left.
  int line_on = kNone, line_through = kNone;
  Slot line_angle = kNone, line_offset = kNone;
  // A guide's slide line (RPR): its x axis shifted `offset` to its left.
  Slot guide_offset = kNone;
  // A slider's slot (RPP): its angle from the slider's line.
  Slot slot = kNone;
  // Its body: a mass with its centre (u, v) and inertia about it; or a
  // uniform bar of mass_per_length (centre [L/2, 0], inertia m L^2 / 12).
  // A slider's mass sits at its pin. None: massless.
  Slot mass = kNone, cg_u = kNone, cg_v = kNone, inertia = kNone, mass_per_length = kNone;
};

struct Group {
  GroupType type;
  int first, second;  // links: RRR the two from p and q; RRP rod, slider; RPR block, guide; RPP block,
                      // slider; PRP the two sliders
  int p, q;           // known points: RRR from p and q; RRP, RPP p (q none); RPR the block's pin p, the pivot q;
                      // PRP none (its known points are its lines')
  int joint = kNone;  // the new point (RRR, RRP; RPP the slider's point on its line where the slot crosses it;
                      // PRP the sliders' pin)
  int branch = 1;     // RRR: +1 joint left of p -> q; RRP: +1 ahead of p's foot along the line
};

// A load on the mechanism: a force on a slider along its line, a torque
// on a link, or a friction torque between two links (kNone: the ground)
// against their relative rotation. Its size: a value slot, or a table over
// the slider's coordinate or the crank angle (linear between rows,
// constant outside), or seed 003's pressure law on a slider: -area a
// e^(b d) over the depth d = s - contact while d >= 0, none before (a
// pressure over the area resisting the depth; every parameter a slot).
// `when`: +1 only while the coordinate (the slider's s, the link's angle)
// grows (ds/dphi > 0), -1 only while it falls, 0 always; `opposing`: the
// size against the motion, whatever its sign.
struct Load {
  enum class Kind { force, torque, friction } kind = Kind::force;
  int link = kNone, other = kNone;  // other: a friction's second link
  Slot value = kNone;
  enum class Over { none, position, crank_angle } over = Over::none;
  std::vector<double> xs, ys;  // the table, SI, xs increasing
  Slot law_a = kNone, law_b = kNone, law_area = kNone, law_contact = kNone;  // the pressure law, when law_a is set
  // A law given by its depth at the end of the stroke instead: its contact
  // follows the design, the slider's largest coordinate less this (the
  // problem writes it into the contact's slot).
  Slot law_depth = kNone;
  int when = 0;
  bool opposing = false;
  Slot efficiency = kNone;  // the drive supplies the load's power over it (seed 000's eta)
};

// A linear spring between two points: force rate * (|PQ| - free length),
// pulling them together when stretched.
struct Spring {
  int p, q;
  Slot rate, free_length;
};

struct Crank {
  int link = kNone, pivot = kNone, joint = kNone;
  Slot phase = kNone, speed = kNone;
  int sense = 1;  // +1 counter-clockwise, -1 clockwise
};

class Chain {
 public:
  // A new number (its default), by the name a problem's table gives it.
  Slot value(std::string name, double v) {
    names_.push_back(std::move(name));
    defaults_.push_back(v);
    return static_cast<Slot>(defaults_.size() - 1);
  }
  int ground(std::string name, Slot x, Slot y) {
    const int p = new_point(std::move(name));
    ground_.push_back({p, {x, y}});
    return p;
  }
  int link(std::string name) {
    for (const auto& l : links_)
      if (l.name == name) throw std::invalid_argument("link '" + name + "' defined twice");
    Link l;
    l.name = std::move(name);
    links_.push_back(std::move(l));
    return static_cast<int>(links_.size() - 1);
  }
  void set_length(int link, Slot length) { links_.at(link).length = length; }
  // A point fixed on `link`, solved when the link is.
  int local_point(int link, std::string name, Slot u, Slot v) {
    const int p = new_point(std::move(name));
    links_.at(link).points.push_back({p, u, v});
    return p;
  }
  void set_line(int slider, int on, int through, Slot angle, Slot offset) {
    Link& l = links_.at(slider);
    l.line_on = on, l.line_through = through, l.line_angle = angle, l.line_offset = offset;
  }
  void set_guide_offset(int guide, Slot offset) { links_.at(guide).guide_offset = offset; }
  void set_body(int link, Slot mass, Slot cg_u, Slot cg_v, Slot inertia) {
    Link& l = links_.at(link);
    l.mass = mass, l.cg_u = cg_u, l.cg_v = cg_v, l.inertia = inertia;
  }
  void set_bar(int link, Slot mass_per_length) {
    need(links_.at(link).length != kNone, "a uniform bar needs a length");
    links_[link].mass_per_length = mass_per_length;
  }
  void add_load(Load l) { loads_.push_back(std::move(l)); }
  void add_spring(Spring s) { springs_.push_back(s); }
  const std::vector<Spring>& springs() const { return springs_; }
  const std::vector<Load>& loads() const { return loads_; }
  // Gravity's acceleration along -y (0: off).
  void set_gravity(double g) { gravity_ = g; }
  double gravity() const { return gravity_; }

  // The crank turning `link` about ground point `pivot`; adds its joint.
  int crank(int link, int pivot, std::string joint, Slot phase, Slot speed, int sense) {
    need(links_.at(link).length != kNone, "the crank '" + links_[link].name + "' needs a length");
    need(groups_.empty() && crank_.link == kNone, "the crank comes first, once");
    need(is_ground(pivot), "the crank's pivot '" + points_.at(pivot) + "' is not a ground point");
    crank_ = {link, pivot, new_point(std::move(joint)), phase, speed, sense};
    solved_link(link, pivot);
    return crank_.joint;
  }
  // An RRR group: `first` from known point p and `second` from q to a new joint.
  int rrr(int first, int second, int p, int q, std::string joint, int branch) {
    need(links_.at(first).length != kNone && links_.at(second).length != kNone,
         "an RRR group's links need lengths");
    need_known({p, q});
    const int j = new_point(std::move(joint));
    groups_.push_back({GroupType::RRR, first, second, p, q, j, branch});
    solved_link(first, p);
    solved_link(second, q);
    return j;
  }
  // An RRP group: rod from known point p to the pin of `slider` on its line.
  int rrp(int rod, int slider, int p, std::string joint, int branch) {
    need(links_.at(rod).length != kNone, "an RRP group's rod needs a length");
    need_line(slider, "an RRP group's slider needs a line");
    need_known({p, links_[slider].line_through});
    const int j = new_point(std::move(joint));
    groups_.push_back({GroupType::RRP, rod, slider, p, kNone, j, branch});
    solved_link(rod, p);
    solved_link(slider, j);
    return j;
  }
  // An RPP group: `block` pinned at known point p slides in the slot of
  // `slider` (at the slider's slot angle from its line), the slider along
  // its line; the new joint is where the slot crosses the line.
  int rpp(int block, int slider, int p, std::string joint) {
    need_line(slider, "an RPP group's slider needs a line and a slot", links_.at(slider).slot != kNone);
    need_known({p, links_[slider].line_through});
    const int j = new_point(std::move(joint));
    groups_.push_back({GroupType::RPP, block, slider, p, kNone, j, 1});
    solved_link(block, p);
    solved_link(slider, j);
    return j;
  }
  // A PRP group: `first` and `second` slide each on its own line (known
  // before this group) and are pinned together at the new joint, where the
  // lines cross.
  int prp(int first, int second, std::string joint) {
    need(first != second, "a PRP group's two sliders are two links");
    for (int k : {first, second}) need_line(k, "a PRP group's sliders need lines");
    need_known({links_[first].line_through, links_[second].line_through});
    const int j = new_point(std::move(joint));
    groups_.push_back({GroupType::PRP, first, second, kNone, kNone, j, 1});
    solved_link(first, j);
    solved_link(second, j);
    return j;
  }
  void set_slot(int slider, Slot angle) { links_.at(slider).slot = angle; }
  // An RPR group: `block` pinned at known point a slides along `guide`,
  // which turns about known point pivot.
  void set_branch(int group, int branch) { groups_.at(group).branch = branch; }
  void rpr(int block, int guide, int a, int pivot) {
    need_known({a, pivot});
    groups_.push_back({GroupType::RPR, block, guide, a, pivot, kNone, 1});
    solved_link(block, a);
    solved_link(guide, pivot);
  }

  const std::vector<std::string>& value_names() const { return names_; }
  const std::vector<double>& defaults() const { return defaults_; }
  void set_default(Slot s, double v) { defaults_.at(static_cast<size_t>(s)) = v; }
  const std::vector<std::string>& point_names() const { return points_; }
  const std::vector<std::pair<int, std::pair<Slot, Slot>>>& ground_points() const { return ground_; }
  const std::vector<Link>& links() const { return links_; }
  const std::vector<Group>& groups() const { return groups_; }
  const Crank& crank() const { return crank_; }
  // "RRR (coupler, rocker)": a group as messages name it.
  std::string group_name(int g) const {
    const Group& gr = groups_.at(g);
    return std::string(to_string(gr.type)) + " (" + links_[gr.first].name + ", " + links_[gr.second].name + ")";
  }
  int find_point(const std::string& name) const {
    for (size_t i = 0; i < points_.size(); ++i)
      if (points_[i] == name) return static_cast<int>(i);
    return kNone;
  }
  int find_link(const std::string& name) const {
    for (size_t i = 0; i < links_.size(); ++i)
      if (links_[i].name == name) return static_cast<int>(i);
    return kNone;
  }

 private:
  static void need(bool ok, const std::string& what) {
    if (!ok) throw std::invalid_argument(what);
  }
  int new_point(std::string name) {
    need(find_point(name) == kNone, "point '" + name + "' defined twice");
    points_.push_back(std::move(name));
    return static_cast<int>(points_.size() - 1);
  }
  // A slider's line, on the ground or on a link solved before its group.
  void need_line(int slider, const std::string& what, bool more = true) const {
    const Link& s = links_.at(slider);
    need(s.line_through != kNone && more, what);
    need(s.line_on == kNone || links_.at(s.line_on).origin != kNone,
         "the line of '" + s.name + "' is on a link not solved before it");
  }
  bool is_ground(int p) const {
    for (const auto& g : ground_)
      if (g.first == p) return true;
    return false;
  }
  // Known: a ground point, the crank's joint, an earlier group's joint, a
  // point of a link already solved.
  bool known(int p) const {
    if (p < 0 || p >= static_cast<int>(points_.size())) return false;
    if (is_ground(p) || p == crank_.joint) return true;
    for (const auto& g : groups_)
      if (g.joint == p) return true;
    for (const auto& l : links_)
      for (const auto& lp : l.points)
        if (lp.point == p) return l.origin != kNone;
    return false;
  }
  void need_known(std::initializer_list<int> ps) {
    need(crank_.link != kNone, "a group comes after the crank");
    for (int p : ps)
      need(known(p), "point '" + (p >= 0 && p < static_cast<int>(points_.size()) ? points_[p] : std::string("?")) +
                         "' is not known before this group");
  }
  void solved_link(int link, int origin) {
    need(links_.at(link).origin == kNone, "link '" + links_[link].name + "' is solved by two groups");
    links_[link].origin = origin;
  }

  std::vector<std::string> names_;
  std::vector<double> defaults_;
  std::vector<std::string> points_;
  std::vector<std::pair<int, std::pair<Slot, Slot>>> ground_;  // point, its x and y slots
  std::vector<Link> links_;
  std::vector<Group> groups_;
  Crank crank_;
  std::vector<Load> loads_;
  std::vector<Spring> springs_;
  double gravity_ = 0;
};

}  // namespace mech::linkage
