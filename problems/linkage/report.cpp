// `mechopt kinematics`: a linkage's state at chosen crank angles as JSON,
// for checking a description against a drawing or a hand calculation.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "mech/linkage/reactions.hpp"
#include "problems/linkage/description.hpp"
#include "problems/linkage/quantity.hpp"

namespace problems::linkage {

std::vector<double> crank_angles(const std::string& list) {
  std::vector<std::string> items;
  for (size_t from = 0, comma; from <= list.size(); from = comma + 1) {
    comma = std::min(list.find(',', from), list.size());
    items.push_back(list.substr(from, comma - from));
  }
  const char* number = "0123456789.+-eE ";
  const std::string& last = items.back();
  const size_t cut = last.find_first_not_of(number, last.find_first_not_of(' '));
  const std::string unit = cut == std::string::npos ? "" : last.substr(cut);
  std::vector<double> out;
  for (const auto& item : items) {
    const bool bare = item.find_first_not_of(number) == std::string::npos;
    const auto q = opt::parse_quantity(bare ? item + " " + unit : item, opt::Dimension::angle);
    if (!q.error.empty()) throw std::invalid_argument("'" + item + "': " + q.error);
    out.push_back(q.value);
  }
  return out;
}

nlohmann::json kinematics_report(const opt::ConfigNode& root, const std::vector<double>& angles) {
  const Description d = read_description(root);
  const auto& c = d.chain;
  const double* v = c.defaults().data();
  const double w = v[static_cast<size_t>(c.crank().speed)], w2 = w * w;
  mech::linkage::State<double> st;
  st.resize(c);
  nlohmann::json out = {{"problem", "linkage"},
                        {"units", "SI: m, m/s, m/s^2, rad, rad/s, rad/s^2, N, N m, J"},
                        {"reactions", "POINT_LINK: the force on LINK from the body that carries POINT; slides: on "
                                      "the slider (block) from its line's body (guide), normal along the line "
                                      "turned +90 deg, and a couple"},
                        {"crank_speed", w},
                        {"angles", nlohmann::json::array()}};
  const bool dynamics = d.has_dynamics();
  const mech::linkage::Joints joints(c);
  mech::linkage::Reactions<double> r;
  r.resize(joints, c);
  for (double phi : angles) {
    nlohmann::json a = {{"crank_angle", phi}, {"crank_angle_deg", phi * 180 / std::numbers::pi}};
    if (!mech::linkage::solve(c, v, phi, st)) {
      a["status"] = "cannot_assemble";
      a["group"] = c.group_name(st.failed);
      out["angles"].push_back(a);
      continue;
    }
    a["status"] = "ok";
    for (size_t p = 0; p < c.point_names().size(); ++p) {
      const auto& q = st.point[p];
      a["points"][c.point_names()[p]] = {{"x", q.x.v}, {"y", q.y.v}, {"vx", q.x.d * w}, {"vy", q.y.d * w},
                                         {"ax", q.x.dd * w2}, {"ay", q.y.dd * w2}};
    }
    for (size_t k = 0; k < c.links().size(); ++k) {
      const auto t = st.angle(static_cast<int>(k));
      a["links"][c.links()[k].name] = {{"angle", t.v}, {"rate", t.d * w}, {"acceleration", t.dd * w2}};
      if (c.links()[k].length == mech::linkage::kNone) {
        const auto& s = st.slide[k];
        a["sliders"][c.links()[k].name] = {{"position", s.v}, {"velocity", s.d * w}, {"acceleration", s.dd * w2}};
      }
    }
    for (int g = 0; g < static_cast<int>(c.groups().size()); ++g) {
      const auto& gr = c.groups()[static_cast<size_t>(g)];
      const auto &e1 = st.axis[static_cast<size_t>(gr.first)], &e2 = st.axis[static_cast<size_t>(gr.second)];
      if (measures(Kind::transmission, gr.type))
        a["transmission_angles"][c.group_name(g)] = std::asin(std::abs(e1.x.v * e2.y.v - e1.y.v * e2.x.v));
      if (measures(Kind::pressure, gr.type))
        a["pressure_angles"][c.group_name(g)] = std::asin(std::abs(pressure_sine(c, g, st).v));
    }
    if (dynamics) {
      const auto p = mech::linkage::drive_point(c, v, st);
      a["drive_torque"] = p.torque;
      a["load_torque"] = -mech::linkage::load_power(c, v, st, phi);
      a["kinetic_energy"] = p.energy * w2;
      mech::linkage::reactions(c, joints, v, st, r);
      a["drive_torque_newton_euler"] = r.torque;
      for (size_t i = 0; i < joints.pins.size(); ++i) {
        const auto& pin = joints.pins[i];
        a["reactions"][c.point_names()[static_cast<size_t>(pin.point)] + "_" +
                       c.links()[static_cast<size_t>(pin.link)].name] = {{"x", r.x[i]}, {"y", r.y[i]}};
      }
      for (size_t i = 0; i < joints.slides.size(); ++i)
        a["slides"][c.links()[static_cast<size_t>(joints.slides[i])].name] = {{"normal", r.normal[i]},
                                                                              {"couple", r.couple[i]}};
      a["shaking_force"] = {{"x", r.shaking_x}, {"y", r.shaking_y}};
      a["shaking_moment"] = r.shaking_m;
    }
    out["angles"].push_back(a);
  }
  return out;
}

opt::CycleCurves cycle_curves(const Description& d, const std::vector<double>& v, int n) {
  const auto& c = d.chain;
  mech::linkage::State<double> st;
  st.resize(c);
  if (!mech::linkage::solve(c, v.data(), 0.0, st)) return {};
  const bool dynamics = d.has_dynamics();
  const mech::linkage::Joints joints(c);
  mech::linkage::Reactions<double> r;
  r.resize(joints, c);
  opt::CycleCurves out;
  out.names = {"crank_angle"};
  out.units = {"rad"};
  if (dynamics) {
    out.names.insert(out.names.end(), {"drive_torque", "load_torque", "inertia_gravity_torque", "kinetic_energy"});
    out.units.insert(out.units.end(), {"N m", "N m", "N m", "J"});
  }
  std::vector<double> ref;  // each rocker's angle unwrapped from phi = 0
  for (const auto& o : d.outputs) {
    out.names.push_back(o.name + (o.slides ? "_position" : "_angle"));
    out.units.push_back(o.slides ? "m" : "rad");
    ref.push_back(st.angle(o.link).v);
  }
  const double w = v[static_cast<size_t>(c.crank().speed)];
  out.columns.resize(out.names.size());
  for (int i = 0; i <= n; ++i) {
    const double phi = mech::kTwoPi * i / n;
    if (!mech::linkage::solve(c, v.data(), phi, st)) return {};
    std::vector<double> row = {phi};
    if (dynamics) {
      const auto p = mech::linkage::drive_point(c, v.data(), st);
      const double loads = -mech::linkage::load_power(c, v.data(), st, phi);
      row.insert(row.end(), {p.torque, loads, p.torque - loads, p.energy * w * w});
    }
    for (size_t o = 0; o < d.outputs.size(); ++o) {
      const auto& out_o = d.outputs[o];
      row.push_back(out_o.slides ? st.slide[static_cast<size_t>(out_o.link)].v
                                 : ref[o] + std::remainder(st.angle(out_o.link).v - ref[o], mech::kTwoPi));
    }
    for (size_t k = 0; k < row.size(); ++k) out.columns[k].push_back(row[k]);
  }
  return out;
}

}  // namespace problems::linkage
