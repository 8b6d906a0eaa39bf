// The live modes of `vines hil` and the node's refusals: the digital twin
// against a damaged truth building, the shake-table (hybrid) mode with and
// without delay compensation, and a configuration the node must refuse.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <optional>
#include <string>
#include <vector>

#include "sim_host/hil/hil.hpp"
#include "sim_host/hil/link/child.hpp"
#include "vines/link/ats.hpp"
#include "vines/link/config.hpp"
#include "vines/link/frame.hpp"
#include "vines/link/messages.hpp"
#include "vines/model/frame_presets.hpp"

namespace vines::host {
namespace {

Scene vines_scene() { return load_scene(std::string(VINES_SOURCE_DIR) + "/data/scenes/elcentro_vines.toml"); }

HilOptions base(HilMode mode, double duration_s) {
  HilOptions o;
  o.node_command = VINES_EXE;
  o.mode = mode;
  o.duration_s = duration_s;
  o.timeout_s = 20;
  return o;
}

// The open-loop twin (--estimator none) of the nominal building, fed the
// top-floor acceleration of the measured one (with 0.02 m/s^2 sensor noise): on the nominal building the
// residual is the noise and no alarm is raised; it grows with the damage
// (eta_k 0.95, 0.85, 0.7) and raises the alarm. With the VI NES the residual
// is dominated by impacts that the damaged building times differently.
TEST(HilTwin, ResidualGrowsWithDamageAndRaisesTheAlarm) {
  for (const char* scene : {"elcentro_bare", "elcentro_vines"}) {
    double last = -1;
    for (double eta : {1.0, 0.95, 0.85, 0.7}) {
      HilOptions o = base(HilMode::kTwin, 20.0);
      o.estimator = HilEstimator::kNone;
      o.truth_stiffness_scale = eta;
      o.measure_noise_mps2 = 0.02;
      o.residual_limit_mps2 = 0.1;
      const HilReport r = run_hil(load_scene(std::string(VINES_SOURCE_DIR) + "/data/scenes/" + scene + ".toml"), o);
      ASSERT_TRUE(r.twin);
      const HilTwinReport& t = *r.twin;
      SCOPED_TRACE(std::string(scene) + ": " + to_json(r)["twin"].dump());
      const double rms = t.residual_rms_mps2;
      if (eta == 1.0) {
        EXPECT_NEAR(rms, 0.02, 0.002);  // the noise alone
        EXPECT_EQ(t.residual_alarm_steps, 0);
      } else {
        EXPECT_GT(rms, last);
        EXPECT_GT(rms, 0.5);
        EXPECT_GT(t.residual_alarm_steps, 0);
        ASSERT_TRUE(t.first_residual_alarm_s);
        EXPECT_LT(*t.first_residual_alarm_s, 3.0);
      }
      EXPECT_TRUE(r.bit_exact);  // predictions: the offline run of the nominal model
      last = rms;
    }
  }
}

TEST(HilTwin, DriftAlarmsNameTheStories) {
  HilOptions o = base(HilMode::kTwin, 10.0);
  o.estimator = HilEstimator::kNone;
  o.drift_limit_m = 0.02;
  const HilReport r = run_hil(vines_scene(), o);
  ASSERT_TRUE(r.twin);
  EXPECT_GT(r.twin->drift_alarm_steps, 0);
  EXPECT_FALSE(r.twin->stories_alarmed.empty());
  o.drift_limit_m = 1.0;  // beyond any drift of this record
  EXPECT_EQ(run_hil(vines_scene(), o).twin->drift_alarm_steps, 0);
}

// A 20 Hz servo with 5 ms delay: extrapolating the command over the delay and
// the servo's lag cuts the tracking error; the VI NES's impacts (overlaps of
// a few mm) are so sensitive to the table's error that the hybrid response
// still departs from the pure simulation; it stays bounded.
TEST(HilHybrid, CompensationReducesTrackingError) {
  HilOptions with = base(HilMode::kHybrid, 20.0), without = base(HilMode::kHybrid, 20.0);
  without.comp_delay_s = 0;
  const HilReport a = run_hil(vines_scene(), with), b = run_hil(vines_scene(), without);
  ASSERT_TRUE(a.hybrid && b.hybrid);
  const HilHybridReport &ha = *a.hybrid, &hb = *b.hybrid;
  SCOPED_TRACE(to_json(a)["hybrid"].dump() + "\n" + to_json(b)["hybrid"].dump());
  EXPECT_GT(ha.compensation_delay_s, 0.005);
  EXPECT_LT(ha.tracking_rms_m, 0.2 * hb.tracking_rms_m);
  EXPECT_LT(ha.tracking_peak_m, hb.tracking_peak_m);
  // The vRTHS criteria: uncompensated, the table lags by the servo's delay
  // (5 ms), its lag 2 zeta / w (11.14 ms) and half a period of the command's
  // hold (0.5 ms); compensated, by under a millisecond. Each floor is judged.
  ASSERT_TRUE(ha.tracking_delay_ms && hb.tracking_delay_ms);
  EXPECT_NEAR(*hb.tracking_delay_ms, 5 + 1e3 * 2 * 0.7 / (2 * M_PI * 20) + 0.5, 0.3);
  EXPECT_LT(std::fabs(*ha.tracking_delay_ms), 1.0);
  EXPECT_LT(*ha.tracking_rms_pct, 0.2 * *hb.tracking_rms_pct);
  EXPECT_EQ(ha.response_rms_pct.size(), 10u);
  EXPECT_EQ(ha.response_peak_pct.size(), 10u);
  for (const HilReport* r : {&a, &b}) {
    EXPECT_TRUE(r->outputs_finite);
    EXPECT_LT(r->hybrid->peak_top_hybrid_m, 2 * r->hybrid->peak_top_pure_m);
  }
}

// With a near-ideal actuator (2 kHz, no delay, no sensor noise) the hybrid
// peak comes within 5 % of the pure simulation's: the coupling is right.
TEST(HilHybrid, IdealActuatorReproducesThePureSimulationPeak) {
  HilOptions o = base(HilMode::kHybrid, 20.0);
  o.actuator_hz = 2000;
  o.actuator_delay_s = 0;
  o.force_noise_n = 0;
  o.force_lsb_n = 0;
  o.comp_delay_s = 0.001;  // the one-step lag of the command
  const HilReport r = run_hil(vines_scene(), o);
  ASSERT_TRUE(r.hybrid);
  const HilHybridReport& hy = *r.hybrid;
  EXPECT_NEAR(hy.peak_top_hybrid_m, hy.peak_top_pure_m, 0.05 * hy.peak_top_pure_m) << to_json(r)["hybrid"].dump();
}

// A linear specimen (the TMD): the hybrid response converges to the pure
// simulation as the tracking error shrinks. On the default actuator (16.6 ms
// behind): uncompensated, compensated for the pure delay and the hold only
// (5.5 ms), then for the servo's lag too (16.6 ms) by order 1 and order 2:
// the tracking and the top floor's RMS error fall at each, within the
// issue's 2 % once compensated. The ideal (the same 20 Hz servo without
// delay or load-cell noise, compensated for its lag 2 zeta / w and the hold
// h / 2) and order 2 meet at the floor the held command leaves (about 0.01 %).
// (A 2 kHz servo would follow the held command in steps, its velocity zero at
// each sample: the load cell then misses the dashpot's force and the response
// is 8 % off; a smooth servo is the ideal here.)
TEST(HilHybrid, TmdSpecimenConvergesToThePureSimulation) {
  const Scene tmd = load_scene(std::string(VINES_SOURCE_DIR) + "/data/scenes/elcentro_tmd.toml");
  const double lag = 2 * 0.7 / (2 * M_PI * 20), hold = 0.5e-3;
  std::vector<HilOptions> runs(5, base(HilMode::kHybrid, 0));
  runs[0].comp_delay_s = 0;
  runs[1].comp_delay_s = 0.005 + hold;
  runs[2].comp_order = 1;  // the default delay: 5 ms + lag + hold
  HilOptions& ideal = runs[4];
  ideal.actuator_delay_s = 0;
  ideal.force_noise_n = ideal.force_lsb_n = 0;
  ideal.comp_delay_s = lag + hold;
  std::vector<double> tracking, response;
  for (const HilOptions& o : runs) {
    const HilReport r = run_hil(tmd, o);
    ASSERT_TRUE(r.hybrid && r.outputs_finite);
    const HilHybridReport& hy = *r.hybrid;
    SCOPED_TRACE(to_json(r)["hybrid"].dump());
    ASSERT_TRUE(hy.tracking_rms_pct && hy.response_rms_pct.size() == 10u && hy.response_rms_pct[9]);
    tracking.push_back(*hy.tracking_rms_pct), response.push_back(*hy.response_rms_pct[9]);
    if (&o == &runs[3]) {
      EXPECT_NEAR(hy.compensation_delay_s, 0.005 + lag + hold, 1e-12);
      for (const std::optional<double>& v : hy.response_rms_pct) EXPECT_LE(*v, 2.0);
      // The paper's reductions: the pure simulation's are `vines run`'s
      // (README: x_r 13.20 %, E_r 77.33 %), and the hybrid's equal them.
      EXPECT_NEAR(hy.x_r_pure, 0.1320, 5e-5);
      EXPECT_NEAR(hy.E_r_pure, 0.7733, 5e-5);
      EXPECT_NEAR(hy.x_r_hybrid, hy.x_r_pure, 1e-3);
      EXPECT_NEAR(hy.E_r_hybrid, hy.E_r_pure, 1e-3);
    }
  }
  for (int i = 1; i < 4; ++i) {
    EXPECT_LT(tracking[i], tracking[i - 1]) << i;
    EXPECT_LT(response[i], response[i - 1]) << i;
  }
  EXPECT_GT(response[0], 1.0);  // uncompensated: percents
  EXPECT_LT(response[3], 0.05);
  EXPECT_LT(tracking[4], tracking[3]);
  EXPECT_LT(response[4], 0.05);
}

// The adaptive compensator (ATS) on El Centro and the default actuator meets
// the targets, tracking delay within 0.5 ms and RMS within 2 %, with
// the VI NES (whose impacts the fit must not follow) and the TMD, whose
// response stays within 2 % on every floor. Its coefficients stay within
// their bounds over the run, and a1 ends at the actuator's total lag:
// delay 5 ms + 2 zeta / w 11.14 ms + the hold's 0.5 ms.
TEST(HilHybrid, AdaptiveMeetsTheTargetsOnTheDefaultActuator) {
  for (const char* scene : {"elcentro_vines", "elcentro_tmd"}) {
    HilOptions o = base(HilMode::kHybrid, 0);
    o.comp = HilComp::kAdaptive;
    const HilReport r = run_hil(load_scene(std::string(VINES_SOURCE_DIR) + "/data/scenes/" + scene + ".toml"), o);
    ASSERT_TRUE(r.hybrid && r.outputs_finite);
    const HilHybridReport& hy = *r.hybrid;
    SCOPED_TRACE(std::string(scene) + ": " + to_json(r)["hybrid"].dump());
    ASSERT_TRUE(hy.tracking_delay_ms && hy.tracking_rms_pct && hy.adaptive);
    EXPECT_LE(std::fabs(*hy.tracking_delay_ms), 0.5);
    EXPECT_LE(*hy.tracking_rms_pct, 2.0);
    const HilAtsCoefficients& c = *hy.adaptive;
    for (int i = 0; i < 3; ++i) {
      EXPECT_GE(c.min[i], link::kAtsLow[i]) << i;
      EXPECT_LE(c.max[i], link::kAtsHigh[i]) << i;
    }
    EXPECT_NEAR(c.last[1], 0.005 + 2 * 0.7 / (2 * M_PI * 20) + 0.5e-3, 0.3e-3);
    if (std::string(scene) == "elcentro_tmd")
      for (const std::optional<double>& v : hy.response_rms_pct) EXPECT_LE(*v, 2.0);
  }
}

// A perturbed actuator (a 10 ms delay; a softer servo, 10 Hz) that the node
// only knows by its nominal delay (16.64 ms, the default actuator's): the
// polynomial extrapolates over the wrong delay; the adaptive one starts from
// it and learns the true lag (10 + 11.14 + 0.5 ms; 5 + 22.28 + 0.5 ms), so it
// tracks better by both criteria.
TEST(HilHybrid, AdaptiveTracksAPerturbedActuatorBetterThanThePolynomial) {
  const double nominal = 0.005 + 2 * 0.7 / (2 * M_PI * 20) + 0.5e-3;
  struct Case {
    double hz, delay_s;
  };
  for (const Case& k : {Case{20, 0.010}, Case{10, 0.005}}) {
    HilOptions poly = base(HilMode::kHybrid, 0);
    poly.actuator_hz = k.hz, poly.actuator_delay_s = k.delay_s;
    poly.comp_delay_s = nominal;
    HilOptions ats = poly;
    ats.comp = HilComp::kAdaptive;
    const HilReport p = run_hil(vines_scene(), poly), a = run_hil(vines_scene(), ats);
    ASSERT_TRUE(p.hybrid && a.hybrid);
    const HilHybridReport &hp = *p.hybrid, &ha = *a.hybrid;
    SCOPED_TRACE(to_json(p)["hybrid"].dump() + "\n" + to_json(a)["hybrid"].dump());
    ASSERT_TRUE(hp.tracking_delay_ms && ha.tracking_delay_ms && ha.adaptive);
    EXPECT_LT(std::fabs(*ha.tracking_delay_ms), 0.5);
    EXPECT_GT(std::fabs(*hp.tracking_delay_ms), 2.0);
    EXPECT_LT(*ha.tracking_rms_pct, *hp.tracking_rms_pct);
    EXPECT_LT(*ha.tracking_peak_pct, *hp.tracking_peak_pct);
    EXPECT_NEAR(ha.adaptive->last[1], k.delay_s + 2 * 0.7 / (2 * M_PI * k.hz) + 0.5e-3, 0.3e-3);
  }
}

// What the table cannot carry, each refused naming the scene and the key: an
// instantaneous contact law (no force for a load cell), no device, a device
// below the top floor (the table plays the top floor); and an adaptive start
// the compensator's bounds refuse, naming the option.
TEST(HilHybrid, RefusesWhatTheTableCannotCarry) {
  const std::string dir = std::string(VINES_SOURCE_DIR) + "/data/scenes/";
  auto refusal = [](const Scene& sc, HilOptions o = base(HilMode::kHybrid, 1.0)) {
    try {
      run_hil(sc, o);
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("(not refused)");
  };
  EXPECT_NE(refusal(load_scene(dir + "elcentro_vines_restitution.toml")).find("finite-duration contact law"),
            std::string::npos);
  EXPECT_NE(refusal(load_scene(dir + "elcentro_bare.toml")).find("device.kind"), std::string::npos);
  Scene low = load_scene(dir + "elcentro_tmd.toml");
  low.params.device.floor = 3;
  const std::string why = refusal(low);
  EXPECT_NE(why.find("elcentro_tmd.toml"), std::string::npos) << why;
  EXPECT_NE(why.find("device.floor 3"), std::string::npos) << why;
  // Nor can the adaptive compensator start beyond a1's bound (0.1 s).
  HilOptions slow = base(HilMode::kHybrid, 1.0);
  slow.comp = HilComp::kAdaptive;
  slow.comp_delay_s = 0.2;
  EXPECT_NE(refusal(load_scene(dir + "elcentro_tmd.toml"), slow).find("--comp-delay 0.2 s"), std::string::npos);
}

// A node given a frame with a NaN mass refuses it and names the field.
TEST(HilNode, RefusesABadConfigurationNamingTheField) {
  ChildProcess node({VINES_EXE, "node", "--idle-timeout", "10"});
  link::NodeConfig c;
  apply_frame_preset(FramePreset::kTable1, &c.scene.frame);
  c.scene.frame.mass_kg[2] = std::nan("");
  std::uint8_t blob[link::kMaxConfigBlob], payload[link::kMaxPayload], wire[link::kMaxWire];
  const std::size_t n = link::encode(c, blob, sizeof blob);
  std::uint16_t seq = 0;
  for (std::size_t off = 0; off < n; off += link::kChunk) {
    link::ConfigureChunk ch{link::ConfigPart::kSettings, static_cast<std::uint32_t>(off), static_cast<std::uint32_t>(n),
                            link::crc32(blob, n), blob + off, static_cast<std::uint16_t>(std::min(link::kChunk, n - off))};
    const std::size_t w = link::encode_frame(link::MsgType::kConfigure, seq++, payload,
                                             link::encode(ch, payload, sizeof payload), wire, sizeof wire);
    node.write_all(wire, w, 5);
  }
  link::Decoder dec;
  link::Status st;
  bool config_fault = false, refused = false;
  std::vector<std::uint8_t> bytes;
  for (int tries = 0; tries < 100 && !refused; ++tries) {
    bytes.clear();
    ASSERT_TRUE(node.read_some(&bytes, 0.05));
    for (std::uint8_t b : bytes) {
      if (dec.push(b) != link::DecodeResult::kFrame) continue;
      const link::Frame& f = dec.frame();
      link::Fault ft;
      if (f.type == link::MsgType::kFault && link::decode(f.payload, f.length, &ft))
        config_fault |= ft.code == link::FaultCode::kConfig;
      if (f.type == link::MsgType::kStatus && link::decode(f.payload, f.length, &st) && st.message[0] != '\0')
        refused = true;
    }
  }
  EXPECT_TRUE(config_fault);
  ASSERT_TRUE(refused);
  EXPECT_STREQ(st.message, "frame.masses[2]: must be finite and > 0");
  EXPECT_EQ(st.state, link::NodeState::kBooted);
  EXPECT_EQ(node.finish(5), 0);  // exits at the end of its input
}

}  // namespace
}  // namespace vines::host
