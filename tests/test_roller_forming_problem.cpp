// The roller_forming problem (seed 003, exercise 6) against the independent
// mpmath reference tests/ref/crank_press_ref.py (30 digits; run it and read
// the key exercise6 of its JSON, whose keys are named next to each table) and
// against closed forms: the bite angle atan f + atan f1, the cart stroke
// (6.4) from its parts, the crank radius as half the stroke, and d L_X /
// d delta = 2.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include "mech/roller_forming.hpp"
#include "opt/config.hpp"
#include "opt/derivatives.hpp"
#include "opt/registry.hpp"
#include "paths.hpp"

namespace {

constexpr double kDeg = std::numbers::pi / 180;
// Relative: the chain is a dozen closed-form steps in double (each within an
// ulp or two) against a 30-digit reference rounded to double; the values
// agree to ~1e-15, 1e-12 leaves room for exp, acos and the cancellation in
// (6.5)'s denominator (at most a factor 3 here: 2 tau0 (2 + sin alpha1) =
// 1500 Pa against L_p rho0 g >= 6500 Pa).
constexpr double kTol = 1e-12;

std::unique_ptr<opt::Problem> forming(const std::string& model, const std::string& variables = "") {
  return opt::make_problem(opt::ConfigNode::parse(
      "problem: roller_forming\nmodel: {" + model + "}\n" + (variables.empty() ? "" : "variables: {" + variables + "}\n"),
      "<roller_forming>"));
}

opt::Evaluation evaluate(const opt::Problem& p) { return p.evaluate(p.initial_point(), opt::MetricSet::all(), false); }

std::string variant(int i) { return "variant: " + std::to_string(i); }

// The message of the ConfigError f throws, or "" when it throws none.
template <class F>
std::string config_error(F&& f) {
  try {
    f();
  } catch (const opt::ConfigError& e) {
    return e.what();
  }
  return "";
}

// exercise6.feed_exponent_negative.variants[i]: variant, R_p, h_n_min, L_p, a,
// a_denominator_Pa, L_X, crank_radius, t3, productivity_m3_per_s,
// capture_angle_deg, N_compaction_W_as_printed,
// productivity_m3_per_s_L_rest_0.35m.
struct Row {
  int variant;
  double R_p, h_n_min, L_p, a, den, L_X, crank_radius, t3, productivity, capture_deg, N, productivity_035;
};
const Row kNegative[] = {
    {1, 0.11, 0.003725696502403561, 0.6173342349588055, 0.0923549171116003, 13034.517227870117, 0.3423549171116003, 0.17117745855580016, 27.907997116925227, 0.002376112144508496, 14.954727475233508, 4085.9957314357243, 0.0017742248762228096},
    {2, 0.11, 0.003485415102106399, 0.4949195287980195, 0.09506072163937282, 10152.38538602057, 0.3450607216393728, 0.1725303608196864, 34.3775300683072, 0.0018569149182360645, 14.461788373958896, 3158.7033140390417, 0.0014750583646769954},
    {3, 0.088, 0.003330829508624677, 0.27620747252832956, 0.10765570220600987, 5003.028733206991, 0.31365570220600986, 0.15682785110300493, 19.527736852944237, 0.0007666027399694408, 15.814372032629361, 2267.402398386285, 0.0006808038791906695},
    {4, 0.088, 0.003330829508624677, 0.4143112087924944, 0.09787420664917389, 8254.543099810488, 0.30387420664917386, 0.15193710332458693, 19.012481691904014, 0.0009129454266214854, 15.814372032629361, 3537.147741482604, 0.0007591245502042433},
    {5, 0.11, 0.003725696502403561, 0.6173342349588055, 0.0923549171116003, 13034.517227870117, 0.3423549171116003, 0.17117745855580016, 26.143849395899267, 0.0012732305659763014, 14.954727475233508, 4796.603684728894, 0.0009522676503773318},
    {6, 0.132, 0.004182498122527679, 0.8248658813300325, 0.08975618400088954, 17920.642310034284, 0.3837561840008895, 0.19187809200044476, 35.98984100003707, 0.001803261969332375, 14.461788373958896, 5264.505523398403, 0.0011741708621109865},
    {7, 0.132, 0.004182498122527679, 0.659892705064026, 0.09167452750781743, 14036.513848027429, 0.38567452750781744, 0.19283726375390872, 33.774090268136334, 0.0017848177939303162, 14.461788373958896, 4913.538488505176, 0.0012913109380935646},
    {8, 0.11, 0.003725696502403561, 0.4630006762191041, 0.0960389408132173, 9400.887920902587, 0.3460389408132173, 0.17301947040660864, 25.54590181553703, 0.0013454864707810048, 14.954727475233508, 3863.930746031609, 0.0010951755082485523},
    {9, 0.132, 0.004470835802884273, 0.30866711747940273, 0.1043651619212117, 5767.258613935059, 0.3983651619212117, 0.19918258096060584, 28.747685181478776, 0.0010703561448843692, 14.954727475233508, 2220.6498540411544, 0.0009362439911824225},
    {10, 0.11, 0.003485415102106399, 0.8248658813300325, 0.08975618400088954, 17920.642310034284, 0.3397561840008895, 0.16987809200044476, 33.06754553849575, 0.0018550719645872658, 14.461788373958896, 5703.214317014937, 0.0012073139621605264},
    {11, 0.11, 0.003725696502403561, 0.4630006762191041, 0.0960389408132173, 9400.887920902587, 0.3460389408132173, 0.17301947040660864, 26.25300565372496, 0.0009712187643258838, 14.954727475233508, 3597.45276354667, 0.0007899932999348349},
    {12, 0.11, 0.003485415102106399, 0.659892705064026, 0.09167452750781743, 14036.513848027429, 0.3416745275078174, 0.1708372637539087, 32.202661696707764, 0.0012793562104823329, 14.461788373958896, 4913.538488505176, 0.0009326837150254011},
    {13, 0.132, 0.004182498122527679, 0.8248658813300325, 0.08975618400088954, 17920.642310034284, 0.3837561840008895, 0.19187809200044476, 36.68505147829954, 0.00332024640539067, 14.461788373958896, 5045.151126590136, 0.002133725786793902},
    {14, 0.132, 0.004182498122527679, 0.4949195287980195, 0.09506072163937282, 10152.38538602057, 0.38906072163937283, 0.19453036081968642, 34.96387390920665, 0.001361985847794284, 14.461788373958896, 3421.928590208962, 0.0010802791428373628},
    {15, 0.11, 0.003725696502403561, 0.30866711747940273, 0.1043651619212117, 5767.258613935059, 0.3543651619212117, 0.17718258096060585, 26.12471891203462, 0.0007865197227006017, 14.954727475233508, 2487.1278365260932, 0.0006907253271992112},
    {16, 0.132, 0.004182498122527679, 0.659892705064026, 0.09167452750781743, 14036.513848027429, 0.38567452750781744, 0.19283726375390872, 33.2991216382006, 0.0015067582187944187, 14.461788373958896, 5089.02200595179, 0.0010955025055971255},
    {17, 0.11, 0.003725696502403561, 0.4630006762191041, 0.0960389408132173, 9400.887920902587, 0.3460389408132173, 0.17301947040660864, 27.534631360440578, 0.0011500469975369335, 14.954727475233508, 3197.7357898192627, 0.0009303013598960904},
    {18, 0.132, 0.004182498122527679, 0.659892705064026, 0.09167452750781743, 14036.513848027429, 0.38567452750781744, 0.19283726375390872, 35.426981100312695, 0.0020415069471139856, 14.461788373958896, 4387.087936165336, 0.0014657489486377751},
    {19, 0.132, 0.004182498122527679, 0.329946352532013, 0.1026434294632333, 6268.2569240137145, 0.3966434294632333, 0.19832171473161664, 35.255516517816666, 0.0009229090018450692, 14.461788373958896, 2281.2857268059747, 0.0008001055800472332},
    {20, 0.11, 0.004163536885780846, 0.690518681320824, 0.09124207178602536, 14757.571833017479, 0.34124207178602534, 0.17062103589301267, 19.583157150800563, 0.002104959568526724, 15.814372032629361, 6121.986475642969, 0.0014705222391344335},
    {21, 0.11, 0.003725696502403561, 0.6173342349588055, 0.0923549171116003, 13034.517227870117, 0.3423549171116003, 0.17117745855580016, 25.78156906033144, 0.0017503761033646726, 14.954727475233508, 4974.2556730521865, 0.001307608527733465},
    {22, 0.11, 0.003725696502403561, 0.4630006762191041, 0.0960389408132173, 9400.887920902587, 0.3460389408132173, 0.17301947040660864, 26.64735202502207, 0.0013387131110882422, 14.954727475233508, 3464.213772304201, 0.0010849974609407737},
    {23, 0.132, 0.004182498122527679, 0.659892705064026, 0.09167452750781743, 14036.513848027429, 0.38567452750781744, 0.19283726375390872, 36.069771979492394, 0.0017655247842014062, 14.461788373958896, 4211.604418718723, 0.0012663163907434246},
    {24, 0.132, 0.004182498122527679, 0.4949195287980195, 0.09506072163937282, 10152.38538602057, 0.38906072163937283, 0.19453036081968642, 35.562428865574915, 0.0016540121065656641, 14.461788373958896, 3290.315952124002, 0.0013255599477634372},
};

// exercise6.feed_exponent_as_printed.variants[i]: variant, h_n_min, L_p,
// a_denominator_Pa (status "infeasible" in every row).
struct Printed {
  int variant;
  double h_n_min, L_p, den;
};
const Printed kAsPrinted[] = {
    {1, 0.3962005337871825, 0.005805141093614567, -1363.3237580919385},
    {2, 0.4235142442830525, 0.004073062531627884, -1404.103815755353},
    {3, 0.2836286519804888, 0.0032436779344256375, -1423.630846711883},
    {4, 0.2836286519804888, 0.004865516901638457, -1385.4462700678241},
    {5, 0.3962005337871825, 0.005805141093614567, -1363.3237580919385},
    {6, 0.508217093139663, 0.0067884375527131405, -1340.173026258922},
    {7, 0.508217093139663, 0.0054307500421705126, -1372.1384210071374},
    {8, 0.3962005337871825, 0.0043538558202109254, -1397.492818568954},
    {9, 0.475440640544619, 0.0029025705468072836, -1431.6618790459693},
    {10, 0.4235142442830525, 0.0067884375527131405, -1340.173026258922},
    {11, 0.3962005337871825, 0.0043538558202109254, -1397.492818568954},
    {12, 0.4235142442830525, 0.0054307500421705126, -1372.1384210071374},
    {13, 0.508217093139663, 0.0067884375527131405, -1340.173026258922},
    {14, 0.508217093139663, 0.004073062531627884, -1404.103815755353},
    {15, 0.3962005337871825, 0.0029025705468072836, -1431.6618790459693},
    {16, 0.508217093139663, 0.0054307500421705126, -1372.1384210071374},
    {17, 0.3962005337871825, 0.0043538558202109254, -1397.492818568954},
    {18, 0.508217093139663, 0.0054307500421705126, -1372.1384210071374},
    {19, 0.508217093139663, 0.0027153750210852563, -1436.0692105035687},
    {20, 0.35453581497561104, 0.008109194836064095, -1309.077116779707},
    {21, 0.3962005337871825, 0.005805141093614567, -1363.3237580919385},
    {22, 0.3962005337871825, 0.0043538558202109254, -1397.492818568954},
    {23, 0.508217093139663, 0.0054307500421705126, -1372.1384210071374},
    {24, 0.508217093139663, 0.004073062531627884, -1404.103815755353},
};

// exercise6.L_X_over_guide_ranges[i]: variant, L_X_min, L_X_max over every
// corner of k1 0.3-0.45, t_pr 5-8 s, t_zas 0.5-1 s, k1' 1-1.6, delta 0.01-0.02 m
// (printed 0.01...0.2, corrected: a 0.2 m clearance is 0.76-1.14 roller
// diameters and 52-59% of the cart's stroke; docs/reproduction.md, exercise 6).
struct Range {
  int variant;
  double lo, hi;
};
const Range kRanges[] = {
    {1, 0.3066534390559013, 0.39049953172658536},
    {2, 0.30735888925260724, 0.4008081778004602},
    {3, 0.2669046989167154, 0.4121123593700808},
    {4, 0.2643326542967606, 0.3659382601407289},
    {5, 0.3066534390559013, 0.39049953172658536},
    {6, 0.3498505140662078, 0.4261729761787684},
    {7, 0.3504081711848571, 0.43255295982801856},
    {8, 0.30769578214052307, 0.40394391266093643},
    {9, 0.3538814285164442, 0.48529981297224645},
    {10, 0.30585051406620783, 0.38217297617876844},
    {11, 0.30769578214052307, 0.40394391266093643},
    {12, 0.30640817118485714, 0.3885529598280186},
    {13, 0.3498505140662078, 0.4261729761787684},
    {14, 0.3513588892526073, 0.44480817780046017},
    {15, 0.3098814285164442, 0.44129981297224646},
    {16, 0.3504081711848571, 0.43255295982801856},
    {17, 0.30769578214052307, 0.40394391266093643},
    {18, 0.3504081711848571, 0.43255295982801856},
    {19, 0.3533443970600334, 0.4779799011851266},
    {20, 0.30640558179521077, 0.38617266333465683},
    {21, 0.3066534390559013, 0.39049953172658536},
    {22, 0.30769578214052307, 0.40394391266093643},
    {23, 0.3504081711848571, 0.43255295982801856},
    {24, 0.3513588892526073, 0.44480817780046017},
};

void expect_rel(double value, double ref, double tol = kTol) { EXPECT_NEAR(value / ref, 1, tol) << value << " vs " << ref; }

TEST(RollerFormingProblem, Table61EveryMetric) {
  for (const Row& v : kNegative) {
    SCOPED_TRACE("variant " + std::to_string(v.variant));
    const auto e = evaluate(*forming(variant(v.variant)));
    ASSERT_TRUE(e.ok()) << e.message;
    expect_rel(e.at("roller_radius"), v.R_p);
    expect_rel(e.at("min_layer"), v.h_n_min);
    expect_rel(e.at("roller_length"), v.L_p);
    expect_rel(e.at("outlet_width"), v.a);
    expect_rel(e.at("outlet_denominator"), v.den);
    expect_rel(e.at("cart_stroke"), v.L_X);
    expect_rel(e.at("crank_radius"), v.crank_radius);
    expect_rel(e.at("cycle_time"), v.t3);
    expect_rel(e.at("productivity"), v.productivity);
    expect_rel(e.at("capture_angle") / kDeg, v.capture_deg);
    expect_rel(e.at("compaction_power"), v.N);
  }
}

TEST(RollerFormingProblem, PrintedRemainingLength) {
  for (const Row& v : kNegative) {
    SCOPED_TRACE("variant " + std::to_string(v.variant));
    const auto e = evaluate(*forming(variant(v.variant) + ", remaining_length: printed"));
    ASSERT_TRUE(e.ok()) << e.message;
    expect_rel(e.at("productivity"), v.productivity_035);
    expect_rel(e.at("cart_stroke"), v.L_X);  // only (6.6), (6.9) read L_ost
  }
}

// As printed, e^(+(N-1)/(k1 N)) makes the layer 2.8-5.1 H and the roller a
// few mm long: (6.5)'s denominator is negative for every variant.
TEST(RollerFormingProblem, AsPrintedExponentIsInfeasible) {
  for (const Printed& v : kAsPrinted) {
    SCOPED_TRACE("variant " + std::to_string(v.variant));
    const auto e = evaluate(*forming(variant(v.variant) + ", feed_exponent: as_printed"));
    EXPECT_EQ(e.status, mech::Status::invalid_parameter);
    EXPECT_EQ(e.message, "(6.5) denominator <= 0: no outlet width exists");
    expect_rel(e.at("outlet_denominator"), v.den);
    expect_rel(e.at("min_layer"), v.h_n_min);
    expect_rel(e.at("roller_length"), v.L_p);
    EXPECT_FALSE(e.has("outlet_width"));
    EXPECT_FALSE(e.has("cart_stroke"));
  }
}

// The extremes of L_X over the guide's ranges sit at two corners: L_X falls
// as L_p grows (a = c L_p / (L_p rho0 g - c')), and L_p grows with t_pr - t_zas
// and as k1 falls (h_n,min ~ e^(-(N-1)/(k1 N))); a grows with k1', L_X with delta.
TEST(RollerFormingProblem, StrokeOverTheGuideRanges) {
  const std::string least = ", stage_factor: 0.3, pass_time: 8 s, feed_time: 0.5 s, outlet_safety: 1, gap: 0.01 m";
  const std::string most = ", stage_factor: 0.45, pass_time: 5 s, feed_time: 1 s, outlet_safety: 1.6, gap: 0.02 m";
  for (const Range& v : kRanges) {
    SCOPED_TRACE("variant " + std::to_string(v.variant));
    expect_rel(evaluate(*forming(variant(v.variant) + least)).at("cart_stroke"), v.lo);
    expect_rel(evaluate(*forming(variant(v.variant) + most)).at("cart_stroke"), v.hi);
  }
}

TEST(RollerFormingProblem, ClosedForms) {
  // exercise6.feed_exponent_negative.bite_angle_deg; atan((f + f1)/(1 - f f1)) = atan f + atan f1.
  EXPECT_NEAR(mech::bite_angle(0.35, 0.58) / kDeg, 49.40377937017117, 1e-12);
  EXPECT_NEAR(mech::bite_angle(0.35, 0.58), std::atan(0.35) + std::atan(0.58), 1e-15);
  const auto p = forming(variant(1));
  EXPECT_NEAR(p->settings()["model"]["derived"]["bite_angle_deg"].get<double>(), 49.40377937017117, 1e-12);
  for (const std::string gap : {"15 mm", "10 mm", "0.2 m"}) {
    for (int i = 1; i <= 24; ++i) {
      const auto e = evaluate(*forming(variant(i) + ", gap: " + gap + ", roller_ratio: 1.4"));
      ASSERT_TRUE(e.ok());
      EXPECT_EQ(e.at("crank_radius"), e.at("cart_stroke") / 2);
      const double delta = opt::parse_quantity(gap, opt::Dimension::length).value;
      EXPECT_NEAR(e.at("cart_stroke"), 2 * e.at("roller_radius") + e.at("outlet_width") + 2 * delta, 1e-15);
      // cos phi = 1 - h_n,min / R_p; R_p = (R_p/H) H.
      EXPECT_NEAR(std::cos(e.at("capture_angle")), 1 - e.at("min_layer") / e.at("roller_radius"), 1e-15);
    }
  }
  // The cart drive's crank speed: a centred slider-crank's slider travels
  // twice its stroke 2 r = L_X per turn, so its mean speed is L_X w / pi,
  // which must be v_p of Table 6.1 (variant 1: 0.23 m/s; variant 9: 0.25).
  for (const auto& [i, v_p] : {std::pair{1, 0.23}, {9, 0.25}}) {
    const auto e = evaluate(*forming(variant(i)));
    EXPECT_NEAR(e.at("cart_stroke") * e.at("crank_speed") / std::numbers::pi, v_p, 1e-15);
  }
  // Variant 0 with every product value given is the same chain: variant 1's.
  const auto explicit_v1 = evaluate(*forming(
      "variant: 0, product_length: 3 m, width: 2 m, thickness: 100 mm, forming_speed: 0.004, cart_speed: 0.23, "
      "passes: 8"));
  expect_rel(explicit_v1.at("productivity"), kNegative[0].productivity);
  expect_rel(explicit_v1.at("compaction_power"), kNegative[0].N);
  // A product value given overrides the variant's.
  EXPECT_EQ(evaluate(*forming(variant(1) + ", thickness: 0.12 m")).at("roller_radius"), 1.1 * 0.12);
}

TEST(RollerFormingProblem, RollerLongerThanTheProduct) {
  const auto e = evaluate(*forming(variant(1) + ", product_length: 0.5 m"));  // L_p = 0.617 m
  EXPECT_EQ(e.status, mech::Status::invalid_parameter);
  EXPECT_NE(e.message.find("L - L_p <= 0"), std::string::npos);
}

TEST(RollerFormingProblem, ConfigErrorsNameTheKey) {
  EXPECT_NE(config_error([] { forming("variant: 25"); }).find("variant"), std::string::npos);
  const std::string no_thickness =
      "variant: 0, product_length: 3 m, width: 2 m, forming_speed: 0.004, cart_speed: 0.23, passes: 8";
  EXPECT_NE(config_error([&] { forming(no_thickness); }).find("thickness"), std::string::npos);
  EXPECT_NE(config_error([] { forming("variant: 0"); }).find("product_length"), std::string::npos);
  EXPECT_NE(config_error([] { forming(variant(1) + ", roller_ratio: 1.0"); }).find("roller_ratio"), std::string::npos);
  EXPECT_NE(config_error([] { forming(variant(1), "roller_ratio: {min: 1.0, max: 2}"); }).find("roller_ratio"),
            std::string::npos);
  EXPECT_NE(config_error([] { forming(variant(1) + ", feed_time: 7 s"); }).find("feed_time"), std::string::npos);
  EXPECT_NE(config_error([] { forming(variant(1) + ", feed_exponent: positive"); }).find("feed_exponent"),
            std::string::npos);
  EXPECT_NO_THROW(forming(variant(1) + ", roller_ratio: 1.1"));  // the guide's rule is inclusive
}

TEST(RollerFormingProblem, Gradients) {
  const std::string vars = "roller_ratio: {min: 1.1, max: 2, initial: 1.3}, gap: {min: 10 mm, max: 20 mm}";
  for (int i : {1, 3, 9, 20, 24}) {
    for (const std::string reading : {"", ", remaining_length: printed"}) {
      SCOPED_TRACE(variant(i) + reading);
      const auto p = forming(variant(i) + reading, vars);
      for (const auto& c : opt::check_derivatives(*p, p->initial_point()))
        EXPECT_TRUE(c.ok) << c.metric << " d/d" << c.variable << ": " << c.autodiff << " vs " << c.central;
    }
  }
  // d L_X / d delta = 2 and d r / d delta = 1 exactly (6.4).
  const auto p = forming(variant(1), "gap: {min: 10 mm, max: 20 mm}");
  const auto e = p->evaluate(p->initial_point(), opt::MetricSet::all(), true);
  ASSERT_TRUE(e.ok());
  EXPECT_EQ(e[p->metric_id("cart_stroke")].gradient(0), 2.0);
  EXPECT_EQ(e[p->metric_id("crank_radius")].gradient(0), 1.0);
}

}  // namespace

namespace {

// configs/recuperative_drive/forming_chain.yaml: the drive's crank radius and
// speed from a forming variant (config links), as one DOE sample sets it.
// The radius is the reference's crank_radius; the speed makes the carts'
// mean speed v_p, so the drive's least mean kinetic energy (both carts at
// their mean speed, 2 x m v^2 / 2 with m = 1000 kg) is 1000 v_p^2 J.
TEST(FormingChain, EachVariantSetsTheDrivesCrankRadiusAndSpeed) {
  const opt::ConfigNode chain =
      opt::ConfigNode::load(std::string(MECHOPT_SOURCE_DIR) + "/configs/recuperative_drive/forming_chain.yaml");
  for (const auto& [i, v_p] : {std::pair{1, 0.23}, {9, 0.25}, {24, 0.25}}) {
    YAML::Node over;
    opt::set_dotted(over["model"], "crank_radius.variant", YAML::Node(std::to_string(i)));
    const auto drive = opt::make_problem(chain.with(over, "sample"));
    const Row& ref = kNegative[i - 1];
    const nlohmann::json record = drive->record();
    expect_rel(record["model"]["crank_radius"].get<double>(), ref.crank_radius);
    expect_rel(record["model"]["crank_speed"].get<double>(), std::numbers::pi * v_p / ref.L_X);
    ASSERT_EQ(record["links"].size(), 2u);
    EXPECT_EQ(record["links"][1]["key"], "crank_speed");
    const auto e = drive->evaluate(drive->initial_point(false), std::vector<std::string>{"least_mean_kinetic_energy"}, false);
    EXPECT_NEAR(e[drive->metric_id("least_mean_kinetic_energy")].value, 1000 * v_p * v_p, 1e-12) << "variant " << i;
  }
}

TEST(FormingChain, ALinkNamingALinkTakesNoModelValuesOfItsOwn) {
  const auto error = config_error([] {
    opt::make_problem(opt::ConfigNode::parse(
        "problem: recuperative_drive\nmodel:\n  crank_radius: {from: " + std::string(MECHOPT_SOURCE_DIR) +
            "/configs/roller_forming/variant.yaml, metric: crank_radius}\n"
            "  crank_speed: {from: crank_radius, metric: crank_speed, variant: 3}\n",
        "<chain>"));
  });
  EXPECT_NE(error.find("<chain>:4:67: key 'model.crank_speed.variant': this link evaluates the design of "
                       "crank_radius; give the linked model values there"),
            std::string::npos)
      << error;
}

}  // namespace
