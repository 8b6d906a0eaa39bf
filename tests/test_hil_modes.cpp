// The live modes of `vines hil` and the node's refusals: the digital twin
// against a damaged truth building, the shake-table (hybrid) mode with and
// without delay compensation, and a configuration the node must refuse.
#include <gtest/gtest.h>

#include <cstring>
#include <string>

#include "sim_host/hil.hpp"
#include "sim_host/hil_child.hpp"
#include "vines/link/config.hpp"
#include "vines/link/frame.hpp"
#include "vines/link/messages.hpp"
#include "vines/frame_presets.hpp"

namespace vines::host {
namespace {

Scene vines_scene() { return load_scene(std::string(VINES_SOURCE_DIR) + "/data/scenes/elcentro_vines.toml"); }

HilOptions base(const char* mode, double duration_s) {
  HilOptions o;
  o.node_command = VINES_EXE;
  o.mode = mode;
  o.duration_s = duration_s;
  o.timeout_s = 20;
  return o;
}

// The twin of the nominal building: residual zero on the nominal truth, and
// growing with the damage of the measured one (eta_k 0.95, 0.85, 0.7), with
// its alarm raised.
TEST(HilTwin, ResidualGrowsWithDamageAndRaisesTheAlarm) {
  double last = -1;
  for (double eta : {1.0, 0.95, 0.85, 0.7}) {
    HilOptions o = base("twin", 20.0);
    o.truth_stiffness_scale = eta;
    o.residual_limit_mps2 = 0.1;
    const nlohmann::json j = run_hil(vines_scene(), o);
    const auto& t = j["twin"];
    SCOPED_TRACE(t.dump());
    const double rms = t["residual_rms_mps2"].get<double>();
    if (eta == 1.0) {
      EXPECT_EQ(rms, 0.0);  // the same model measured and predicted
      EXPECT_EQ(t["residual_alarm_steps"].get<long long>(), 0);
    } else {
      EXPECT_GT(rms, last * 1.5);
      if (eta <= 0.85) EXPECT_GT(t["residual_alarm_steps"].get<long long>(), 0);
    }
    EXPECT_TRUE(j["bit_exact"].get<bool>());  // predictions: the offline run of the nominal model
    last = rms;
  }
}

TEST(HilTwin, DriftAlarmsNameTheStories) {
  HilOptions o = base("twin", 10.0);
  o.drift_limit_m = 0.02;
  const nlohmann::json j = run_hil(vines_scene(), o);
  const auto& t = j["twin"];
  EXPECT_GT(t["drift_alarm_steps"].get<long long>(), 0);
  EXPECT_FALSE(t["stories_alarmed"].empty());
  o.drift_limit_m = 1.0;  // beyond any drift of this record
  EXPECT_EQ(run_hil(vines_scene(), o)["twin"]["drift_alarm_steps"].get<long long>(), 0);
}

TEST(HilHybrid, CompensationReducesTrackingError) {
  HilOptions with = base("hybrid", 20.0), without = base("hybrid", 20.0);
  without.comp_delay_s = 0;
  const nlohmann::json a = run_hil(vines_scene(), with), b = run_hil(vines_scene(), without);
  const auto &ha = a["hybrid"], &hb = b["hybrid"];
  SCOPED_TRACE(ha.dump() + "\n" + hb.dump());
  EXPECT_GT(ha["compensation_delay_s"].get<double>(), 0.005);
  EXPECT_LT(ha["tracking_rms_m"].get<double>(), 0.5 * hb["tracking_rms_m"].get<double>());
  EXPECT_TRUE(a["outputs_finite"].get<bool>());
  // The hybrid top floor follows the pure simulation to within a fraction of its peak.
  EXPECT_LT(ha["top_diff_from_pure_rms_m"].get<double>(), 0.2 * ha["peak_top_pure_m"].get<double>());
  EXPECT_GT(ha["top_diff_from_pure_rms_m"].get<double>(), 0.0);
}

TEST(HilHybrid, RefusesAnInstantaneousLaw) {
  Scene sc = load_scene(std::string(VINES_SOURCE_DIR) + "/data/scenes/elcentro_vines_restitution.toml");
  EXPECT_THROW(run_hil(sc, base("hybrid", 1.0)), std::runtime_error);
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
    link::ConfigureChunk ch{static_cast<std::uint16_t>(off), static_cast<std::uint16_t>(n), link::crc32(blob, n),
                            blob + off, static_cast<std::uint16_t>(std::min(link::kChunk, n - off))};
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
