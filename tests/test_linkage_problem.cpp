// The `linkage` problem's reading and statuses: every number a table row
// named by its address (variables, DOE factors, a coordinate set over a
// base config's pair), located errors for the descriptions a designer gets
// wrong, metrics named by the outputs, and the typed statuses of a group
// that cannot assemble or passes a singular position. Reference values are
// closed forms (the centred slider-crank's stroke 2 r; its peak speed; a
// four-bar's transmission angle from the law of cosines).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "mech/linkage/dynamics.hpp"
#include "opt/registry.hpp"
#include "problems/linkage/description.hpp"
#include "paths.hpp"

namespace {

constexpr double kPi = std::numbers::pi;

// A centred slider-crank, crank r = 0.2 m, rod 0.8 m, 60 rpm; `extra`
// lines are appended under model (indented by two spaces).
std::string slider_crank(const std::string& extra = "", const std::string& after = "") {
  return "problem: linkage\nmodel:\n"
         "  ground: {O: [0 m, 0 m], S0: [0 m, 0 m]}\n"
         "  crank: {link: crank, pivot: O, joint: A, phase: 0 deg, speed: 60 rpm}\n"
         "  links:\n"
         "    crank: {length: 0.2 m}\n"
         "    rod: {length: 0.8 m}\n"
         "    ram: {mass: 10 kg, line: {fixed_to: ground, through: S0, angle: 0 deg}}\n"
         "  groups:\n"
         "    - {type: RRP, links: [rod, ram], from: A, joint: B, branch: 1}\n"
         "  outputs: [ram]\n" +
         extra + after;
}

// The same with the crank's phase at 0.1 rad: no grid angle at 90 deg.
std::string replace_phase(std::string yaml) {
  const std::string from = "phase: 0 deg";
  return yaml.replace(yaml.find(from), from.size(), "phase: 0.1 rad");
}

std::unique_ptr<opt::Problem> make(const std::string& yaml) {
  return opt::make_problem(opt::ConfigNode::parse(yaml, "<linkage>"));
}

// The error a config gives, or "" when it loads.
std::string error_of(const std::string& yaml) {
  try {
    make(yaml);
  } catch (const opt::ConfigError& e) {
    return e.what();
  }
  return "";
}

TEST(LinkageProblem, MetricsOfTheCentredSliderCrank) {
  const auto p = make(slider_crank());
  const auto e = p->evaluate(p->initial_point(), opt::MetricSet::all(), false);
  ASSERT_TRUE(e.ok()) << e.message;
  EXPECT_NEAR(e.at("ram_stroke"), 0.4, 1e-15);  // 2 r
  // Peak acceleration at phi = 0: r w^2 (1 + r / l).
  const double w = 2 * kPi;
  EXPECT_NEAR(e.at("ram_peak_acceleration"), 0.2 * w * w * 1.25, 1e-12);
  EXPECT_NEAR(e.at("max_pressure_angle"), std::asin(0.25), 1e-15);  // asin(r / l) at phi = 90 deg
  // Kinetic energy of the ram alone: m (x' w)^2 / 2 at its peak speed.
  const double v = e.at("ram_peak_velocity");
  EXPECT_NEAR(e.at("peak_kinetic_energy"), 10 * v * v / 2, 1e-12);
  // The torque is the energy's slope alone (no loads): the work swing is
  // the energy's, from 0 at the dead centres to its peak, so a flywheel
  // keeping (w_max - w_min) / w = 0.05 has J = T_max / (0.05 w^2).
  const auto f = make(slider_crank("  speed_fluctuation: 0.05\n"));
  const auto ef = f->evaluate(f->initial_point(), {"flywheel_inertia", "peak_kinetic_energy"}, true);
  ASSERT_TRUE(ef.ok()) << ef.message;
  EXPECT_NEAR(ef.at("flywheel_inertia") * 0.05 * w * w, ef.at("peak_kinetic_energy"), 1e-12 * ef.at("peak_kinetic_energy"));
}

TEST(LinkageProblem, EveryNumberIsARowByItsAddress) {
  const auto p = make(slider_crank("", "variables:\n  links.rod.length: {min: 0.5 m, max: 1 m}\n"
                                       "  ground.S0.y: {min: -0.1 m, max: 0.1 m}\n"));
  ASSERT_EQ(p->variables().size(), 2u);  // in the table's order
  EXPECT_EQ(p->variables()[0].name, "ground.S0.y");
  EXPECT_EQ(p->variables()[1].name, "links.rod.length");
  const auto root = opt::ConfigNode::parse(slider_crank(), "<linkage>");
  std::vector<std::string> names;
  for (const auto& row : opt::model_parameters(root)) names.push_back(row.name);
  for (const char* a : {"ground.O.x", "ground.S0.y", "crank.phase", "crank.speed", "links.crank.length",
                        "links.rod.length", "links.ram.mass", "links.ram.line.angle"})
    EXPECT_NE(std::find(names.begin(), names.end(), a), names.end()) << a;
  // A coordinate set over the config's pair keeps the other one: the DOE
  // rebuilds a sample this way (set_dotted writes {S0: {y: ..}}).
  YAML::Node over;
  over["model"]["ground"]["S0"]["y"] = "-0.05 m";
  const auto moved = opt::make_problem(root.with(over, "<sample>"));
  const auto e = moved->evaluate(moved->initial_point(), {"ram_stroke"}, false);
  ASSERT_TRUE(e.ok());
  EXPECT_NEAR(e.at("ram_stroke"), std::sqrt(1.0 - 0.05 * 0.05) - std::sqrt(0.36 - 0.05 * 0.05), 1e-15);
}

TEST(LinkageProblem, BadDescriptionsAreLocatedErrors) {
  struct Case {
    std::string yaml, expect;
  };
  const std::string base = slider_crank();
  auto in = [](std::string s, const std::string& from, const std::string& to) {
    return s.replace(s.find(from), from.size(), to);
  };
  auto replaced = [&](const std::string& from, const std::string& to) { return in(base, from, to); };
  const Case cases[] = {
      {replaced("from: A,", "from: Q,"), "unknown point 'Q'"},
      {in(replaced("rod: {length: 0.8 m}", "rod: {length: 0.8 m, points: {R: [0.1 m, 0 m]}}"), "from: A,",
          "from: R,"),
       "not known before this group"},  // R is on the rod, which this group solves
      {replaced("rod: {length: 0.8 m}", "rod: {length: 0 m}"), "links.rod.length"},
      {replaced("ram: {mass: 10 kg, line: {fixed_to: ground, through: S0, angle: 0 deg}}", "ram: {mass: 10 kg}"),
       "has no line"},
      {replaced("S0: [0 m, 0 m]", "S0: [0 m, 1 m]"), "cannot assemble at crank angle 0"},
      {replaced("through: S0", "through: A"), "its point 'A' must be fixed there too"},  // A moves with the crank
      {replaced("S0: [0 m, 0 m]", "S0: [0 m]"), "expected a point [x, y]"},
      {replaced("S0: [0 m, 0 m]", "S0: [0 kg, 0 m]"), "ground.S0[0]"},
      {replaced("rod: {length", "r.od: {length"), "a name is letters"},
      {replaced("branch: 1", "branch: 2"), "expected one of"},
      {replaced("{type: RRP, links: [rod, ram], from: A, joint: B, branch: 1}",
                "{type: RPP, links: [rod, ram], from: A, joint: B}"),
       "an RPP group's slider needs a line and a slot"},
      {replaced("outputs: [ram]", "outputs: [ram, rum]"), "unknown link 'rum'"},
      {replaced("    rod: {length: 0.8 m}\n", "    rod: {length: 0.8 m}\n    spare: {length: 1 m}\n"),
       "no group or crank solves this link"},
      {replaced("outputs: [ram]", "outputs: [ram, rum]"), "unknown link 'rum'"},
      {replaced("    rod: {length: 0.8 m}\n", "    rod: {length: 0.8 m}\n    spare: {length: 1 m}\n"),
       "no group or crank solves this link"},
      {in(replaced("mass: 10 kg, ", ""), "outputs: [ram]\n", "outputs: [ram]\nobjective: {minimize: peak_drive_torque}\n"),
       "'peak_drive_torque' needs masses, loads or springs in the model"},
      {in(replaced("mass: 10 kg, ", ""), "outputs: [ram]\n", "outputs: [ram]\nconstraints: {A_rod_peak_reaction: {max: 1 kN}}\n"),
       "'A_rod_peak_reaction' needs masses, loads or springs in the model"},
      {in(replaced("mass: 10 kg, ", ""), "outputs: [ram]\n", "outputs: [ram]\nobjective: {minimize: peak_shaking_force}\n"),
       "'peak_shaking_force' needs masses"},
      // T_min counts the outputs' masses: a massive rod is not an output.
      {in(in(replaced("mass: 10 kg, ", ""), "rod: {length: 0.8 m}", "rod: {length: 0.8 m, mass_per_length: 5 kg/m}"),
          "outputs: [ram]\n", "outputs: [ram]\nobjective: {minimize: k2}\n"),
       "'k2' needs T_min, the energy of the outputs' strokes"},
      {in(replaced("mass: 10 kg, ", ""), "outputs: [ram]\n", "outputs: [ram]\nconstraints: {k3: {max: 2}}\n"),
       "'k3' needs T_min"},
      {slider_crank("  loads: {p: {link: rod, law: exponential, a: 1 MPa, b: 0 1/m, area: 1 m^2, contact: 0 m}}\n"),
       "a pressure law acts on a slider; 'rod' is a link"},
      {slider_crank("  loads: {p: {link: ram, force: 1 N, a: 1 MPa}}\n"), "it goes with law: exponential"},
      {slider_crank("  loads: {p: {link: ram, force: 1 N, law: exponential}}\n"),
       "give force, table or law, one of them"},
      {slider_crank("  loads: {p: {link: ram, law: quadratic, a: 1 MPa, b: 0 1/m, area: 1 m^2, contact: 0 m}}\n"),
       "expected one of"},
      {slider_crank("  loads: {p: {link: ram, law: exponential, a: 1 MPa, b: 0 1/m, area: 1 m^2}}\n"), "contact"},
      {slider_crank("  loads: {p: {link: ram, law: exponential, a: 1 MPa, b: 2 m, area: 1 m^2, contact: 0 m}}\n"),
       "loads.p.b"},
      {slider_crank("  loads: {p: {link: ram, law: exponential, a: 1 MPa, b: 0 1/m, area: 1 m^2, contact: 0 m,"
                    " depth: 1 mm}}\n"),
       "give contact (the coordinate where the depth starts) or depth"},
      {slider_crank("  loads: {p: {link: ram, law: exponential, a: 1 MPa, b: 0 1/m, area: 1 m^2, depth: 1 mm}}\n",
                    "variables: {loads.p.contact: {min: 0 m, max: 1 m}}\n"),
       "the contact follows the law's depth"},
      {slider_crank("  cycle_points: many\n"), "key 'model.cycle_points': expected auto or a whole number from 8 to 100000, got 'many'"},
      {slider_crank("  cycle_points: 4\n"), "key 'model.cycle_points': expected a whole number from 8 to 100000, got '4'"},
  };
  for (const auto& c : cases) {
    const std::string what = error_of(c.yaml);
    EXPECT_NE(what.find(c.expect), std::string::npos) << "expected '" << c.expect << "', got: " << what;
    EXPECT_NE(what.find("<linkage>:"), std::string::npos) << what;  // located
  }
}

// A crank-rocker four-bar: the transmission angle at B from the law of
// cosines, cos(mu) = (b^2 + c^2 - |AO4|^2) / (2 b c), least where |AO4|
// is largest or smallest (the crank along the frame line).
TEST(LinkageProblem, FourBarTransmissionAngle) {
  const auto p = make(
      "problem: linkage\nmodel:\n"
      "  ground: {O2: [0 m, 0 m], O4: [1 m, 0 m]}\n"
      "  crank: {link: crank, pivot: O2, joint: A, speed: 10 rad/s}\n"
      "  links: {crank: {length: 0.3 m}, coupler: {length: 1.1 m}, rocker: {length: 0.8 m}}\n"
      "  groups: [{type: RRR, links: [coupler, rocker], from: [A, O4], joint: B, near: [1.2 m, 0.8 m]}]\n"
      "  outputs: [rocker]\n");
  const auto e = p->evaluate(p->initial_point(), opt::MetricSet::all(), false);
  ASSERT_TRUE(e.ok()) << e.message;
  const double b = 1.1, c = 0.8;
  auto mu = [&](double d) {  // the acute angle between the links for |AO4| = d
    const double m = std::acos((b * b + c * c - d * d) / (2 * b * c));
    return std::min(m, kPi - m);
  };
  EXPECT_NEAR(e.at("min_transmission_angle"), std::min(mu(0.7), mu(1.3)), 1e-13);
  // The rocker's swing between its extreme positions (A, B, O4 with the
  // crank and coupler collinear): the law of cosines at O4.
  auto rocker = [&](double ab) {  // angle at O4 of the triangle O2 O4 B with |O2 B| = ab
    return std::acos((1 + c * c - ab * ab) / (2 * c));
  };
  EXPECT_NEAR(e.at("rocker_stroke"), rocker(b + 0.3) - rocker(b - 0.3), 1e-13);
}

// Seed 000's T_min (eq. 14), the outputs' strokes at constant speed,
// sum (1/2) M (stroke w / pi)^2, against closed forms: the twin drive's
// 4 m r^2 w^2 / pi^2, which the paper prints as 1777.8 J for m = 1000 kg,
// r = 0.2 m at 100 rpm (its printed 10.5 rad/s would give 1787.3 J);
// the centred slider-crank's ram, stroke 2 r; a rocker's inertia about its
// pivot (a bar's q c^3 / 3, a body's J + m |cg|^2) with its swing from
// the law of cosines. Every output's mean energy is at least its T_min
// (mean x'^2 >= (mean |x'|)^2), so k2 >= 1.
TEST(LinkageProblem, LeastMeanKineticEnergy) {
  const auto twin = opt::make_problem(
      opt::ConfigNode::load(std::string(MECHOPT_SOURCE_DIR) + "/configs/linkage/recuperative_drive.yaml"));
  const std::vector<std::string> asked = {"least_mean_kinetic_energy", "k1", "k2", "k3", "peak_kinetic_energy",
                                          "mean_kinetic_energy"};
  auto e = twin->evaluate(twin->initial_point(), asked, false);
  ASSERT_TRUE(e.ok()) << e.message;
  const double w = 100 * kPi / 30, least = 4 * 1000 * 0.2 * 0.2 * w * w / (kPi * kPi);
  EXPECT_NEAR(least, 1777.8, 0.05);
  EXPECT_NEAR(e.at("least_mean_kinetic_energy"), least, 1e-12 * least);
  EXPECT_NEAR(e.at("k2"), e.at("mean_kinetic_energy") / least, 1e-12);
  EXPECT_NEAR(e.at("k3"), e.at("peak_kinetic_energy") / least, 1e-12);
  EXPECT_GT(e.at("k2"), 1);
  const auto ram = make(slider_crank());  // 10 kg, stroke 0.4 m, 60 rpm: (1/2) 10 (0.4 * 2 pi / pi)^2
  e = ram->evaluate(ram->initial_point(), {"least_mean_kinetic_energy", "k2"}, false);
  ASSERT_TRUE(e.ok()) << e.message;
  EXPECT_NEAR(e.at("least_mean_kinetic_energy"), 3.2, 1e-14);
  EXPECT_GT(e.at("k2"), 1);
  // The four-bar below, its rocker (c = 0.8 m, frame 1 m, crank 0.3 m,
  // coupler 1.1 m) the only mass; 10 rad/s.
  const double c = 0.8, b = 1.1;
  auto at_o4 = [&](double ab) { return std::acos((1 + c * c - ab * ab) / (2 * c)); };
  const double swing = at_o4(b + 0.3) - at_o4(b - 0.3), speed = swing * 10 / kPi;
  const struct {
    std::string body;
    double inertia;
  } rockers[] = {{"mass_per_length: 2 kg/m", 2 * c * c * c / 3},
                 {"mass: 5 kg, cg: [0.4 m, 0.1 m], inertia: 0.3 kg m^2", 0.3 + 5 * (0.4 * 0.4 + 0.1 * 0.1)}};
  for (const auto& r : rockers) {
    const auto p = make("problem: linkage\nmodel:\n"
                        "  ground: {O2: [0 m, 0 m], O4: [1 m, 0 m]}\n"
                        "  crank: {link: crank, pivot: O2, joint: A, speed: 10 rad/s}\n"
                        "  links: {crank: {length: 0.3 m}, coupler: {length: 1.1 m}, rocker: {length: 0.8 m, " +
                        r.body + "}}\n"
                        "  groups: [{type: RRR, links: [coupler, rocker], from: [A, O4], joint: B, near: [1.2 m, 0.8 m]}]\n"
                        "  outputs: [rocker]\n");
    e = p->evaluate(p->initial_point(), {"least_mean_kinetic_energy", "k2"}, false);
    ASSERT_TRUE(e.ok()) << e.message;
    EXPECT_NEAR(e.at("least_mean_kinetic_energy"), r.inertia * speed * speed / 2, 1e-13) << r.body;
    EXPECT_GT(e.at("k2"), 1) << r.body;
  }
}

// A spring between the ram's pin and a ground point, no masses: the torque
// the crank needs is the slope of the spring's potential k (L - L0)^2 / 2
// (central differences of positions), and its cycle mean is zero.
TEST(LinkageProblem, SpringTorqueIsItsPotentialsSlope) {
  const std::string yaml = slider_crank("  springs: {buffer: {between: [B, S1], rate: 20 kN/m, free_length: 0.5 m}}\n");
  std::string text = yaml;
  text.replace(text.find("S0: [0 m, 0 m]"), 14, "S0: [0 m, 0 m], S1: [1.6 m, 0.3 m]");
  text.replace(text.find("mass: 10 kg, "), 13, "");  // no masses: the spring alone
  const auto root = opt::ConfigNode::parse(text, "<linkage>");
  const auto d = problems::linkage::read_description(root);
  const auto& c = d.chain;
  mech::linkage::State<double> st;
  st.resize(c);
  auto potential = [&](double phi) {
    EXPECT_TRUE(mech::linkage::solve(c, c.defaults().data(), phi, st));
    const auto& b = st.point[static_cast<size_t>(c.find_point("B"))];
    const double stretch = std::hypot(b.x.v - 1.6, b.y.v - 0.3) - 0.5;
    return 20e3 * stretch * stretch / 2;
  };
  const double h = 1e-5;
  for (double phi : {0.3, 1.7, 2.9, 4.2, 5.5}) {
    const double slope = (potential(phi + h) - potential(phi - h)) / (2 * h);
    mech::linkage::solve(c, c.defaults().data(), phi, st);
    EXPECT_NEAR(mech::linkage::drive_point(c, c.defaults().data(), st).torque, slope, 1e-6 * std::abs(slope) + 1e-6);
  }
  const auto p = make(text);
  const auto e = p->evaluate(p->initial_point(), opt::MetricSet::all(), false);
  ASSERT_TRUE(e.ok()) << e.message;
  EXPECT_NEAR(e.at("mean_drive_torque"), 0, 1e-12);  // conservative: no work a revolution
  EXPECT_GT(e.at("peak_drive_torque"), 100);
}

// A torque on the rocker tabulated over its angle, no masses: a function
// of the angle alone, so its work a revolution is zero, and the torque
// bends where the angle crosses a row (80 and 85 deg; 70 lies below the
// swing). The means' Gauss arcs end at those crossings: the mean is zero
// to round-off and the rms is the one 16 times finer grids give.
TEST(LinkageProblem, MeansEndAtALinkAnglesTableRows) {
  auto four_bar = [](int points) {
    return make("problem: linkage\nmodel:\n"
                "  cycle_points: " + std::to_string(points) + "\n"
                "  ground: {O2: [0 m, 0 m], O4: [1 m, 0 m]}\n"
                "  crank: {link: crank, pivot: O2, joint: A, speed: 10 rad/s}\n"
                "  links: {crank: {length: 0.3 m}, coupler: {length: 1.1 m}, rocker: {length: 0.8 m}}\n"
                "  groups: [{type: RRR, links: [coupler, rocker], from: [A, O4], joint: B, near: [1.2 m, 0.8 m]}]\n"
                "  loads: {work: {link: rocker, table: {over: position, unit: [deg, N m],\n"
                "                 rows: [[70, 0], [80, 300], [85, -100]]}}}\n"
                "  outputs: [rocker]\n");
  };
  const std::vector<std::string> asked = {"mean_drive_torque", "rms_drive_torque", "peak_drive_torque"};
  const auto p = four_bar(64), fine = four_bar(1024);
  const auto e = p->evaluate(p->initial_point(), asked, false), ef = fine->evaluate(fine->initial_point(), asked, false);
  ASSERT_TRUE(e.ok() && ef.ok()) << e.message << ef.message;
  EXPECT_GT(e.at("peak_drive_torque"), 50);
  EXPECT_NEAR(e.at("mean_drive_torque"), 0, 1e-12 * e.at("peak_drive_torque"));
  EXPECT_NEAR(e.at("rms_drive_torque"), ef.at("rms_drive_torque"), 1e-12 * ef.at("rms_drive_torque"));
}

TEST(LinkageProblem, TypedStatuses) {
  // A rod shorter than crank + offset cannot reach past 90 deg: named.
  const auto p = make(slider_crank("", "variables: {links.rod.length: {min: 0.1 m, max: 1 m}}\n"));
  auto e = p->evaluate(Eigen::VectorXd::Constant(1, 0.15), opt::MetricSet::all(), false);
  EXPECT_EQ(e.status, mech::Status::cannot_assemble);
  EXPECT_NE(e.message.find("RRP (rod, ram) cannot assemble at crank angle"), std::string::npos) << e.message;
  // A rod longer than the crank by 1e-13 of it: at 90 deg it stands
  // 4.5e-7 rad off perpendicular to the line, a pressure angle within
  // 1e-6 of 90 deg: singular (its branch could flip there), though no
  // grid angle shows it (the phase puts 90 deg between grid points).
  const auto q = make(replace_phase(slider_crank("", "variables: {links.rod.length: {min: 0.1 m, max: 1 m}}\n")));
  e = q->evaluate(Eigen::VectorXd::Constant(1, 0.2 * (1 + 1e-13)), opt::MetricSet::all(), false);
  EXPECT_EQ(e.status, mech::Status::singular_position) << e.message;
  EXPECT_NE(e.message.find("RRP (rod, ram) passes a singular position"), std::string::npos) << e.message;
}

}  // namespace

namespace {

// Seed 003's pressure law on the ram (p = a e^(b d) over the depth d = s -
// contact, force -p area): by virtual work the mean driving torque is the
// law's work a stroke over 2 pi, area a (e^(b D) - 1) / b at the final
// depth D = r + l - contact (the ram's coordinate runs from l - r to l + r),
// with its gradient in closed form; acting both ways (when: always) it
// gives back on the return what it took, and the mean is zero.
std::string in_vars(std::string s, const std::string& from, const std::string& to) {
  return s.replace(s.find(from), from.size(), to);
}

TEST(LinkageProblem, PressureLawMeanIsItsWork) {
  const std::string vars =
      "variables: {links.crank.length: {min: 0.1 m, max: 0.3 m}, links.rod.length: {min: 0.5 m, max: 1 m},"
      " loads.p.a: {min: 0 Pa, max: 1 MPa}, loads.p.b: {min: 0 1/m, max: 50 1/m},"
      " loads.p.area: {min: 0 m^2, max: 1 m^2},"
      " loads.p.contact: {min: 0 m, max: 1 m}}\n";
  const std::string law = "  loads: {p: {link: ram, law: exponential, a: 0.5 MPa, b: 20 1/m, area: 0.01 m^2,"
                          " contact: 0.9 m, when: forward}}\n";
  const auto p = make(slider_crank(law, vars));
  ASSERT_EQ(p->variables()[5].name, "loads.p.contact");
  const auto e = p->evaluate(p->initial_point(), {"mean_drive_torque"}, true);
  ASSERT_TRUE(e.ok()) << e.message;
  const double a = 0.5e6, b = 20, area = 0.01, depth = 0.2 + 0.8 - 0.9, grow = std::exp(b * depth);
  const double work = area * a * (grow - 1) / b, end = area * a * grow;  // end: dW/dD
  const auto& m = e[p->metric_id("mean_drive_torque")];
  EXPECT_NEAR(m.value * 2 * kPi, work, 1e-12 * work);
  // d/d(r, l, a, b, area, contact)
  double expect[] = {end, end, work / a, area * a * (depth * grow / b - (grow - 1) / (b * b)), work / area, -end};
  for (int i = 0; i < 6; ++i) EXPECT_NEAR(m.gradient[i] * 2 * kPi, expect[i], 1e-12 * end) << p->variables()[i].name;
  std::string both = law;
  both.replace(both.find("forward"), 7, "always");
  const auto q = make(slider_crank(both, vars));
  const auto eq = q->evaluate(q->initial_point(), {"mean_drive_torque"}, false);
  ASSERT_TRUE(eq.ok()) << eq.message;
  EXPECT_NEAR(eq.at("mean_drive_torque") * 2 * kPi, 0, 1e-12 * work);
  // Given by its depth at the end of the stroke, the contact follows the
  // ram's largest coordinate r + l: the work is the same, whatever r and l.
  std::string by_depth = law;
  by_depth.replace(by_depth.find("contact: 0.9 m"), 14, "depth: 0.1 m");
  const auto d = make(slider_crank(by_depth, in_vars(vars, "loads.p.contact", "loads.p.depth")));
  ASSERT_EQ(d->variables()[5].name, "loads.p.depth");
  const auto ed = d->evaluate(d->initial_point(), {"mean_drive_torque"}, true);
  ASSERT_TRUE(ed.ok()) << ed.message;
  const auto& md = ed[d->metric_id("mean_drive_torque")];
  EXPECT_NEAR(md.value * 2 * kPi, work, 1e-12 * work);
  expect[0] = expect[1] = 0, expect[5] = end;
  for (int i = 0; i < 6; ++i) EXPECT_NEAR(md.gradient[i] * 2 * kPi, expect[i], 1e-12 * end) << d->variables()[i].name;
}

}  // namespace

// Beyond four variables the gradient comes by forward-mode chunks of four
// (ModelProblem::evaluate_model_with). Each of its columns must equal the
// derivative the same problem gives with that variable alone free (a
// single Dual: another seeding, another scalar), for every metric of the
// Stephenson six-bar at eight variables.
TEST(LinkageProblem, GradientsBeyondFourVariablesByChunks) {
  const std::string path = std::string(MECHOPT_SOURCE_DIR) + "/configs/linkage/stephenson3_sixbar.yaml";
  const char* names[] = {"links.coupler.points.E.x", "links.coupler.points.E.y", "links.rod.length",
                         "links.crank.length",       "links.rocker.length",      "links.coupler.length",
                         "ground.O4.x",              "crank.phase"};
  auto with_variables = [&](std::vector<const char*> free) {
    YAML::Node config = YAML::LoadFile(path), vars;
    for (const char* n : free)
      vars[n] = YAML::Load(std::string(n) == "crank.phase" ? "{min: -1 rad, max: 1 rad}" : "{min: 0.01 m, max: 10 m}");
    config["variables"] = vars;
    config.remove("constraints");
    return opt::make_problem(opt::ConfigNode::parse(YAML::Dump(config), path));
  };
  const auto all = with_variables(std::vector<const char*>(std::begin(names), std::end(names)));
  ASSERT_EQ(all->variables().size(), 8u);
  const auto e = all->evaluate(all->initial_point(), opt::MetricSet::all(), true);
  ASSERT_TRUE(e.ok()) << e.message;
  int checked = 0;
  for (int j = 0; j < 8; ++j) {
    const auto one = with_variables({all->variables()[static_cast<size_t>(j)].name.c_str()});
    const auto f = one->evaluate(one->initial_point(), opt::MetricSet::all(), true);
    ASSERT_TRUE(f.ok()) << f.message;
    for (size_t i = 0; i < e.values.size(); ++i) {
      const auto id = static_cast<opt::MetricId>(i);
      if (!e.has(id)) continue;
      ASSERT_TRUE(f.has(id));
      ASSERT_EQ(e[id].gradient.size(), 8);
      const double g = f[id].gradient[0];
      EXPECT_NEAR(e[id].gradient[j], g, 1e-12 * std::max(1.0, std::abs(g))) << all->metric_names()[i] << " by " << all->variables()[static_cast<size_t>(j)].name;
      ++checked;
    }
  }
  EXPECT_GT(checked, 8 * 10);
}
namespace {

// A PRP group: configs/linkage/wedge_press.yaml, its wedge on a ground
// line and its ram on another, so the block's line only translates: the
// ram's coordinate is a constant plus tan(alpha) times the wedge's less
// its offset (test_linkage_kinematics derives it), so its stroke is
// |tan alpha| times the wedge's, and the PRP group's pressure angle (the
// block's force, normal to its line, against the ram's line) is |alpha|
// at every crank angle, above the rod's here. The process force F on the
// forward stroke does F times the stroke a revolution: the mean torque.
TEST(LinkageProblem, WedgePressByClosedForms) {
  const std::string path = std::string(MECHOPT_SOURCE_DIR) + "/configs/linkage/wedge_press.yaml";
  const auto p = opt::make_problem(opt::ConfigNode::load(path));
  const auto e = p->evaluate(p->initial_point(), opt::MetricSet::all(), true);
  ASSERT_TRUE(e.ok()) << e.message;
  const double alpha = 20.5 * kPi / 180;
  EXPECT_NEAR(e.at("ram_stroke"), std::tan(alpha) * e.at("wedge_stroke"), 1e-15);
  EXPECT_NEAR(e.at("max_pressure_angle"), alpha, 1e-15);
  EXPECT_NEAR(e.at("mean_drive_torque") * 2 * kPi, 3000 * e.at("ram_stroke"), 1e-12 * 3000 * e.at("ram_stroke"));
  // d(ram stroke)/d(alpha): the wedge's stroke over cos^2 (the line's
  // angle is -alpha; the variables in the table's order: S0.y, crank,
  // rod, the line's angle).
  ASSERT_EQ(p->variables()[3].name, "links.block.line.angle");
  const auto& g = e[p->metric_id("ram_stroke")].gradient;
  EXPECT_NEAR(g[3], -e.at("wedge_stroke") / (std::cos(alpha) * std::cos(alpha)), 1e-13);
  EXPECT_NEAR(e[p->metric_id("max_pressure_angle")].gradient[3], -1, 1e-15);
  // The model kinematics prints the PRP group's pressure angle and the
  // ram's slide.
  const auto r = problems::linkage::kinematics_report(opt::ConfigNode::load(path), {0.3});
  EXPECT_NEAR(r["angles"][0]["pressure_angles"]["PRP (block, ram)"].get<double>(), alpha, 1e-15);
  EXPECT_TRUE(r["angles"][0]["slides"].contains("ram"));
  EXPECT_TRUE(r["angles"][0]["reactions"].contains("B_ram"));
}

// A wedge whose lines turn parallel: exactly (cos(pi/2) the same in both
// lines' directions) it cannot assemble; 1e-9 rad off it passes within
// 1e-6 of a singular position at every angle. Both named by the group.
TEST(LinkageProblem, WedgeStatuses) {
  const std::string path = std::string(MECHOPT_SOURCE_DIR) + "/configs/linkage/wedge_press.yaml";
  const auto p = opt::make_problem(opt::ConfigNode::load(path));
  Eigen::VectorXd x = p->initial_point();
  x[3] = kPi / 2;  // the block's line at 90 deg on the wedge, as the ram's
  auto e = p->evaluate(x, opt::MetricSet::all(), false);
  EXPECT_EQ(e.status, mech::Status::cannot_assemble);
  EXPECT_NE(e.message.find("PRP (block, ram) cannot assemble at crank angle 0 deg"), std::string::npos) << e.message;
  x[3] = kPi / 2 - 1e-9;
  e = p->evaluate(x, opt::MetricSet::all(), false);
  EXPECT_EQ(e.status, mech::Status::singular_position);
  EXPECT_NE(e.message.find("PRP (block, ram) passes a singular position"), std::string::npos) << e.message;
}

// A PRP group's mistakes as located errors.
TEST(LinkageProblem, BadWedgesAreLocatedErrors) {
  const std::string base =
      "problem: linkage\nmodel:\n"
      "  ground: {O: [0 m, 0 m], R: [0.6 m, -0.1 m]}\n"
      "  crank: {link: crank, pivot: O, joint: A, phase: 0 deg, speed: 60 rpm}\n"
      "  links:\n"
      "    crank: {length: 0.08 m}\n"
      "    rod: {length: 0.35 m}\n"
      "    wedge: {mass: 10 kg, line: {fixed_to: ground, through: O, angle: 0 deg}}\n"
      "    block: {line: {fixed_to: wedge, through: C, angle: -20 deg, offset: 0.04 m}}\n"
      "    ram: {mass: 20 kg, line: {fixed_to: ground, through: R, angle: 90 deg}}\n"
      "  groups:\n"
      "    - {type: RRP, links: [rod, wedge], from: A, joint: C, branch: 1}\n"
      "    - {type: PRP, links: [block, ram], joint: B}\n"
      "  outputs: [ram]\n";
  ASSERT_EQ(error_of(base), "");
  auto replaced = [&](const std::string& from, const std::string& to) {
    std::string s = base;
    return s.replace(s.find(from), from.size(), to);
  };
  const std::pair<std::string, std::string> cases[] = {
      {replaced("block: {line: {fixed_to: wedge, through: C, angle: -20 deg, offset: 0.04 m}}", "block: {}"),
       "the slider 'block' has no line"},
      {replaced("ram: {mass: 20 kg, line: {fixed_to: ground, through: R, angle: 90 deg}}", "ram: {mass: 20 kg}"),
       "the slider 'ram' has no line"},
      {replaced("angle: -20 deg", "angle: 90 deg"), "PRP (block, ram): its sliders' lines are parallel at crank angle 0"},
      {replaced("angle: -20 deg", "angle: 89.99999999 deg"), "its sliders' lines are parallel at crank angle 0"},
      {replaced("joint: B}", "joint: B, from: A}"), "from': unknown key"},
      {replaced("joint: B}", "joint: B, branch: 1}"), "branch': unknown key"},
      {replaced("links: [block, ram]", "links: [ram, ram]"), "a PRP group's two sliders are two links"},
      {replaced("fixed_to: wedge, through: C", "fixed_to: wedge, through: A"), "its point 'A' must be fixed there too"},
      {replaced("joint: B}", "joint: C}"), "point 'C' is defined twice"},
  };
  for (const auto& [yaml, expect] : cases) {
    const std::string what = error_of(yaml);
    EXPECT_NE(what.find(expect), std::string::npos) << "expected '" << expect << "', got: " << what;
    EXPECT_NE(what.find("<linkage>:"), std::string::npos) << what;  // located
  }
}

}  // namespace

namespace {

// The mean driving torque is the loads' work over 2 pi (work.hpp): each
// load's from its coordinate at the ends of the arcs where it acts. The
// independent computation: Gauss arcs over the loads' power at 2 n nodes
// a revolution between their switches, which every load takes once one
// of them cannot come from ends (a table over the crank angle, here all
// zeros: no power of its own). Values and gradients agree to 1e-12 of
// the largest load's work for: a torque on the crank, which turns round
// (its work 2 pi T, no switch); a torque on the rocker on its forward
// swings only; one against the rocker's swing over an efficiency; the
// joints' frictions, one between crank and coupler (turning round
// relative to each other); and on a slider-crank a force on the return
// stroke, a table over position on the forward one and an opposing force.
TEST(LinkageProblem, MeanTorqueFromTheArcsEndsIsGaussOfThePower) {
  auto four_bar = [](const std::string& extra) {
    return make("problem: linkage\nmodel:\n"
                "  ground: {O2: [0 m, 0 m], O4: [1 m, 0 m]}\n"
                "  crank: {link: crank, pivot: O2, joint: A, speed: 10 rad/s}\n"
                "  links: {crank: {length: 0.3 m}, coupler: {length: 1.1 m}, rocker: {length: 0.8 m}}\n"
                "  groups: [{type: RRR, links: [coupler, rocker], from: [A, O4], joint: B, near: [1.2 m, 0.8 m]}]\n"
                "  loads:\n"
                "    resisting: {link: crank, torque: -40 N m}\n"
                "    lift: {link: rocker, torque: 120 N m, when: forward}\n"
                "    drag: {link: rocker, torque: 30 N m, opposing: true, efficiency: 0.8}\n"
                "    pin_a: {at: A, friction_torque: 3 N m}\n"
                "    pin_b: {at: B, friction_torque: 5 N m}\n" +
                extra +
                "  outputs: [rocker]\n"
                "variables: {links.crank.length: {min: 0.1 m, max: 0.5 m}, links.coupler.length: {min: 0.5 m, max: 2 m},"
                " links.rocker.length: {min: 0.5 m, max: 2 m}, ground.O4.x: {min: 0.5 m, max: 2 m}}\n");
  };
  auto slider = [](const std::string& extra) {
    return make(slider_crank("  loads:\n"
                             "    back: {link: ram, force: 500 N, when: return}\n"
                             "    press: {link: ram, when: forward, table: {over: position, unit: [m, N],\n"
                             "            rows: [[0.65, 0], [0.8, -300], [0.95, 200]]}}\n"
                             "    drag: {link: ram, force: 80 N, opposing: true, efficiency: 0.9}\n" +
                                 extra,
                             "variables: {links.crank.length: {min: 0.1 m, max: 0.3 m},"
                             " links.rod.length: {min: 0.5 m, max: 1 m}, loads.back.force: {min: 0 N, max: 1 kN}}\n"));
  };
  const std::string zero_torque = "    zero: {link: rocker, table: {over: crank_angle, unit: [deg, N m], rows: [[0, 0], [360, 0]]}}\n";
  const std::string zero_force = "    zero: {link: ram, table: {over: crank_angle, unit: [deg, N], rows: [[0, 0], [360, 0]]}}\n";
  const std::pair<std::unique_ptr<opt::Problem>, std::unique_ptr<opt::Problem>> cases[] = {
      {four_bar(""), four_bar(zero_torque)}, {slider(""), slider(zero_force)}};
  for (const auto& [ends, gauss] : cases) {
    const auto e = ends->evaluate(ends->initial_point(), {"mean_drive_torque"}, true);
    const auto g = gauss->evaluate(gauss->initial_point(), {"mean_drive_torque"}, true);
    ASSERT_TRUE(e.ok() && g.ok()) << e.message << g.message;
    const auto &me = e[ends->metric_id("mean_drive_torque")], &mg = g[gauss->metric_id("mean_drive_torque")];
    const double scale = 120.0 / (2 * kPi) + 500.0 * 0.4 / (2 * kPi);
    EXPECT_GT(std::abs(me.value), 0.05 * scale);
    EXPECT_NEAR(me.value, mg.value, 1e-12 * scale);
    for (int i = 0; i < me.gradient.size(); ++i) EXPECT_NEAR(me.gradient[i], mg.gradient[i], 1e-12 * scale) << i;
  }
}

}  // namespace

// A workspace keeps the evaluation's plan (the wanted metrics and the
// quantities they ask) while the same metrics are wanted: evaluations
// that change the wanted set on one workspace, values and gradients,
// give the bits of a fresh workspace each time.
TEST(LinkageProblem, AKeptWorkspaceFollowsTheWantedMetrics) {
  const auto twin = opt::make_problem(
      opt::ConfigNode::load(std::string(MECHOPT_SOURCE_DIR) + "/configs/linkage/recuperative_drive.yaml"));
  auto set_of = [&](const std::vector<std::string>& names) {
    opt::MetricSet s;
    for (const auto& n : names) s.add(twin->metric_id(n));
    return s;
  };
  const std::vector<opt::MetricSet> sets = {
      set_of({"peak_drive_torque"}),
      set_of({"peak_kinetic_energy", "mean_kinetic_energy", "k1", "k2", "k3", "peak_drive_torque",
              "mean_drive_torque"}),
      set_of({"cart1_stroke", "k2"}),
      set_of({"peak_drive_torque"}),
      opt::MetricSet::all()};
  const Eigen::VectorXd x = twin->initial_point();
  const auto kept = twin->make_workspace();
  for (const bool gradient : {false, true}) {
    for (size_t i = 0; i < sets.size(); ++i) {
      opt::Evaluation warm, fresh;
      twin->evaluate(x, sets[i], gradient, warm, *kept);
      twin->evaluate(x, sets[i], gradient, fresh, *twin->make_workspace());
      ASSERT_TRUE(fresh.ok()) << fresh.message;
      ASSERT_EQ(warm.status, fresh.status);
      int compared = 0;
      for (size_t m = 0; m < fresh.values.size(); ++m) {
        const auto id = static_cast<opt::MetricId>(m);
        ASSERT_EQ(warm.has(id), fresh.has(id)) << "set " << i << ", metric " << m;
        if (!fresh.has(id)) continue;
        EXPECT_EQ(warm[id].value, fresh[id].value) << "set " << i << ", metric " << m;
        if (gradient) {
          EXPECT_EQ(warm[id].gradient, fresh[id].gradient) << "set " << i << ", metric " << m;
        }
        ++compared;
      }
      EXPECT_GE(compared, 1) << "set " << i;
    }
  }
}
