// The metrics a linkage description offers, and the check that a torque
// or energy metric a config asks for has the masses or loads it needs.
#include "problems/linkage/metrics.hpp"

#include "mech/linkage/reactions.hpp"

namespace problems::linkage {

using mech::linkage::GroupType;
using mech::linkage::kNone;
using opt::MetricSpec;

std::vector<int> moving_masses(const Description& d) {
  const auto& c = d.chain;
  std::vector<int> out;
  for (size_t o = 0; o < d.outputs.size(); ++o) {
    const auto& l = c.links()[static_cast<size_t>(d.outputs[o].link)];
    bool pivoted = false;  // turning about a ground point
    for (const auto& gp : c.ground_points()) pivoted = pivoted || gp.first == l.origin;
    const bool slider = l.length == kNone && l.line_through != kNone && l.line_on == kNone;
    const bool rocker = l.length != kNone && pivoted && d.outputs[o].link != c.crank().link;
    if ((slider && l.mass != kNone) || (rocker && (l.mass != kNone || l.mass_per_length != kNone)))
      out.push_back(static_cast<int>(o));
  }
  return out;
}

std::vector<Metric> metrics_of(const Description& d) {
  std::vector<Metric> out;
  auto add = [&](const std::string& name, const std::string& unit, Form f, Quantity q,
                 Quantity q2 = {Kind::margin, kNone}) {
    out.push_back({MetricSpec(static_cast<int>(out.size()), name, unit), f, q, q2});
  };
  for (size_t o = 0; o < d.outputs.size(); ++o) {
    const auto& out_o = d.outputs[o];
    const int i = static_cast<int>(o);
    const std::string u = out_o.slides ? "m" : "rad";
    add(out_o.name + "_stroke", u, Form::range, {Kind::coordinate, i}, {Kind::neg_coordinate, i});
    add(out_o.name + "_max", u, Form::peak, {Kind::coordinate, i});
    add(out_o.name + "_min", u, Form::peak, {Kind::neg_coordinate, i});
    add(out_o.name + "_peak_velocity", u + "/s", Form::peak, {Kind::speed, i});
    add(out_o.name + "_peak_acceleration", u + "/s^2", Form::peak, {Kind::acceleration, i});
    add(out_o.name + "_time_ratio", "", Form::ratio, {Kind::coordinate, i}, {Kind::neg_coordinate, i});
  }
  const auto& groups = d.chain.groups();
  auto each_group = [&](Kind k, const std::string& name) {
    // one metric over the groups k measures: the largest of their maxima
    bool any = false;
    for (const auto& g : groups) any = any || measures(k, g.type);
    if (any) add(name, "rad", Form::peak, {k, kNone});
  };
  // A four-bar loop: an RRR group on the crank's joint and a ground point.
  const auto& c = d.chain;
  for (size_t g = 0; g < groups.size(); ++g) {
    const auto& gr = groups[g];
    const bool on_crank = gr.p == c.crank().joint || gr.q == c.crank().joint;
    bool on_ground = false;
    for (const auto& gp : c.ground_points()) on_ground = on_ground || gp.first == gr.p || gp.first == gr.q;
    if (gr.type == GroupType::RRR && on_crank && on_ground)
      add(c.links()[static_cast<size_t>(gr.first)].name + "_" + c.links()[static_cast<size_t>(gr.second)].name +
              "_grashof_margin",
          "m", Form::grashof, {Kind::margin, static_cast<int>(g)});
  }
  each_group(Kind::pressure, "max_pressure_angle");
  each_group(Kind::transmission, "min_transmission_angle");
  if (d.has_dynamics()) {
    add("peak_drive_torque", "N m", Form::peak, {Kind::torque, kNone});
    add("mean_drive_torque", "N m", Form::mean, {Kind::torque, kNone});
    add("mean_abs_drive_torque", "N m", Form::mean_abs, {Kind::torque, kNone});
    add("rms_drive_torque", "N m", Form::rms, {Kind::torque, kNone});
    add("energy_swing", "J", Form::swing, {Kind::torque, kNone});
  }
  if (d.has_dynamics()) {  // the joints' reactions: per pin POINT_LINK (reactions.hpp), per slider
    const mech::linkage::Joints j(c);
    for (size_t i = 0; i < j.pins.size(); ++i)
      add(c.point_names()[static_cast<size_t>(j.pins[i].point)] + "_" +
              c.links()[static_cast<size_t>(j.pins[i].link)].name + "_peak_reaction",
          "N", Form::peak, {Kind::reaction, static_cast<int>(i)});
    for (size_t i = 0; i < j.slides.size(); ++i)
      add(c.links()[static_cast<size_t>(j.slides[i])].name + "_peak_guide_force", "N", Form::peak,
          {Kind::guide, static_cast<int>(i)});
  }
  if (d.has_dynamics() && d.speed_fluctuation != kNone)
    add("flywheel_inertia", "kg m^2", Form::flywheel, {Kind::torque, kNone});
  if (d.has_mass) {
    add("peak_kinetic_energy", "J", Form::peak, {Kind::energy, kNone});
    add("mean_kinetic_energy", "J", Form::mean, {Kind::energy, kNone});
    add("k1", "", Form::k1, {Kind::energy, kNone});  // seed 000 eq. (15): peak over mean energy
    add("peak_shaking_force", "N", Form::peak, {Kind::shaking_force, kNone});
    add("peak_shaking_moment", "N m", Form::peak, {Kind::shaking_moment, kNone});
  }
  if (!moving_masses(d).empty()) {  // seed 000 eqs (14), (15)
    add("least_mean_kinetic_energy", "J", Form::least, {Kind::energy, kNone});
    add("k2", "", Form::k2, {Kind::energy, kNone});
    add("k3", "", Form::k3, {Kind::energy, kNone});
  }
  return out;
}

std::vector<MetricSpec> specs_of(const std::vector<Metric>& ms) {
  std::vector<MetricSpec> out;
  for (const auto& m : ms) out.push_back(m.spec);
  return out;
}

void check_dynamics_asked(const opt::ConfigNode& root, const std::vector<Metric>& metrics) {
  auto offered = [&](const std::string& name) {
    for (const auto& m : metrics)
      if (m.spec.name == name) return true;
    return false;
  };
  auto check = [&](const opt::ConfigNode& at, const std::string& name) {
    if (offered(name)) return;
    auto has = [&](const char* part) { return name.find(part) != std::string::npos; };
    const bool least = name == "least_mean_kinetic_energy" || name == "k2" || name == "k3";
    const bool energy = has("kinetic_energy") || has("shaking") || name == "k1";
    if (least)
      at.fail("'" + name + "' needs T_min, the energy of the outputs' strokes: an output with a mass, a slider "
              "on a ground line or a link turning about a ground point; this description has none");
    if (energy || has("drive_torque") || has("energy_swing") || has("_peak_reaction") || has("_peak_guide_force"))
      at.fail("'" + name + "' needs " +
              (energy ? std::string(kNeedsMasses)
                      : std::string("masses, loads or springs")) +
              " in the model: this description has none");
  };
  if (root.has("objective"))
    for (const char* key : {"minimize", "maximize"})
      if (root.at("objective").is_map() && root.at("objective").has(key))
        check(root.at("objective").at(key), root.at("objective").at(key).text());
  if (root.has("constraints") && root.at("constraints").is_map())
    for (const auto& name : root.at("constraints").keys()) check(root.at("constraints").at(name), name);
}

void ask(const Description& d, const std::vector<int>& masses, const Metric& m, std::vector<Quantity>& asked) {
  using mech::linkage::kNone;
  auto once = [&](Quantity q) {
    for (const Quantity& a : asked)
      if (a.kind == q.kind && a.index == q.index) return;
    asked.push_back(q);
  };
  if (m.form == Form::k1 || m.form == Form::k3) once({Kind::energy, kNone});  // the peak energy
  if (m.form >= Form::k2)  // T_min: the strokes
    for (int o : masses) once({Kind::coordinate, o}), once({Kind::neg_coordinate, o});
  if (m.form >= Form::mean) return;  // a mean asks for no maximum
  for (const Quantity& q : {m.q, m.q2}) {
    if (q.kind == Kind::margin) continue;
    if (q.index != kNone || (q.kind != Kind::pressure && q.kind != Kind::transmission)) {
      once(q);
      continue;
    }
    for (size_t g = 0; g < d.chain.groups().size(); ++g)
      if (measures(q.kind, d.chain.groups()[g].type)) once({q.kind, static_cast<int>(g)});
  }
}

}  // namespace problems::linkage
