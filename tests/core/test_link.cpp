// The link codec: COBS, CRC, frames, messages, the configuration blob, and the
// stream decoder's resynchronisation after garbage and corruption.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "vines/link/config.hpp"
#include "vines/link/extrapolate.hpp"
#include "vines/link/frame.hpp"
#include "vines/link/messages.hpp"

namespace vines::link {
namespace {

std::vector<std::uint8_t> wire_of(MsgType type, std::uint16_t seq, const std::vector<std::uint8_t>& payload) {
  std::vector<std::uint8_t> w(kMaxWire);
  const std::size_t n = encode_frame(type, seq, payload.data(), payload.size(), w.data(), w.size());
  w.resize(n);
  return w;
}

// Feeds bytes; returns every non-kNone result, and the frames' payloads.
struct Fed {
  std::vector<DecodeResult> results;
  std::vector<std::vector<std::uint8_t>> payloads;
  std::vector<std::uint16_t> seqs;
};
Fed feed(Decoder& d, const std::vector<std::uint8_t>& bytes) {
  Fed out;
  for (std::uint8_t b : bytes) {
    const DecodeResult r = d.push(b);
    if (r == DecodeResult::kNone) continue;
    out.results.push_back(r);
    if (r == DecodeResult::kFrame) {
      out.payloads.emplace_back(d.frame().payload, d.frame().payload + d.frame().length);
      out.seqs.push_back(d.frame().seq);
    }
  }
  return out;
}

TEST(Crc32, CheckValue) {
  const char* s = "123456789";
  EXPECT_EQ(crc32(reinterpret_cast<const std::uint8_t*>(s), 9), 0xCBF43926u);
  EXPECT_EQ(crc32(nullptr, 0), 0u);
}

TEST(Cobs, RoundTripsEveryLengthAndZeroPattern) {
  std::mt19937 rng(3);
  for (std::size_t n : {0u, 1u, 2u, 253u, 254u, 255u, 256u, 508u, 509u, 600u}) {
    for (int pattern = 0; pattern < 4; ++pattern) {
      std::vector<std::uint8_t> in(n);
      for (auto& b : in) b = static_cast<std::uint8_t>(pattern == 0 ? 0 : pattern == 1 ? 0x11 : rng() % (pattern == 2 ? 3 : 256));
      std::vector<std::uint8_t> enc(cobs_max_encoded(n)), dec(n + 1);
      const std::size_t e = cobs_encode(in.data(), n, enc.data(), enc.size());
      ASSERT_GT(e, 0u);
      for (std::size_t i = 0; i < e; ++i) ASSERT_NE(enc[i], 0) << "n " << n;
      const long d = cobs_decode(enc.data(), e, dec.data(), dec.size());
      ASSERT_EQ(d, static_cast<long>(n));
      EXPECT_TRUE(std::equal(in.begin(), in.end(), dec.begin()));
    }
  }
}

TEST(Cobs, RefusesBadInputAndSmallBuffers) {
  std::uint8_t out[8];
  const std::uint8_t runs_past[] = {5, 1, 2};
  EXPECT_EQ(cobs_decode(runs_past, 3, out, sizeof out), -1);
  const std::uint8_t has_zero[] = {3, 0, 1};
  EXPECT_EQ(cobs_decode(has_zero, 3, out, sizeof out), -1);
  const std::uint8_t fine[] = {3, 1, 2, 2, 9};  // 1 2 0 9
  EXPECT_EQ(cobs_decode(fine, 5, out, 3), -1);
  EXPECT_EQ(cobs_decode(fine, 5, out, 4), 4);
  std::uint8_t in[10] = {};
  EXPECT_EQ(cobs_encode(in, 10, out, sizeof out), 0u);
}

TEST(Frame, RoundTripKeepsTypeSeqAndPayload) {
  Decoder d;
  std::vector<std::uint8_t> stream;
  std::vector<std::vector<std::uint8_t>> sent;
  std::mt19937 rng(5);
  for (std::uint16_t seq = 65530; seq != 6; ++seq) {  // wraps
    std::vector<std::uint8_t> p(rng() % (kMaxPayload + 1));
    for (auto& b : p) b = static_cast<std::uint8_t>(rng() % 4);  // many zeros
    const auto w = wire_of(MsgType::kSample, seq, p);
    ASSERT_FALSE(w.empty());
    stream.insert(stream.end(), w.begin(), w.end());
    sent.push_back(p);
  }
  const Fed f = feed(d, stream);
  ASSERT_EQ(f.payloads.size(), sent.size());
  for (std::size_t i = 0; i < sent.size(); ++i) {
    EXPECT_EQ(f.payloads[i], sent[i]);
    EXPECT_EQ(f.seqs[i], static_cast<std::uint16_t>(65530 + i));
  }
  std::uint8_t big[kMaxPayload + 1] = {}, out[2 * kMaxWire];
  EXPECT_EQ(encode_frame(MsgType::kSample, 0, big, sizeof big, out, sizeof out), 0u);
}

TEST(Frame, EveryByteCorruptionIsDetectedAndTheNextFrameSurvives) {
  const std::vector<std::uint8_t> payload = {1, 0, 2, 0, 0, 3, 250, 7, 0, 9};
  const auto good = wire_of(MsgType::kSample, 42, payload);
  const auto next = wire_of(MsgType::kStop, 43, {});
  for (std::size_t pos = 0; pos + 1 < good.size(); ++pos) {  // all but the delimiter
    for (int bit = 0; bit < 8; ++bit) {
      auto bad = good;
      bad[pos] ^= static_cast<std::uint8_t>(1u << bit);
      bad.insert(bad.end(), next.begin(), next.end());
      Decoder d;
      const Fed f = feed(d, bad);
      ASSERT_EQ(f.payloads.size(), 1u) << "pos " << pos << " bit " << bit;
      EXPECT_EQ(f.seqs[0], 43);  // only the following frame, intact
      for (std::size_t i = 0; i + 1 < f.results.size(); ++i) EXPECT_TRUE(is_error(f.results[i]));
    }
  }
}

TEST(Frame, ResyncsAfterGarbageOversizeAndTruncation) {
  Decoder d;
  std::mt19937 rng(11);
  std::vector<std::uint8_t> stream;
  for (int i = 0; i < 3000; ++i) stream.push_back(static_cast<std::uint8_t>(1 + rng() % 255));  // no delimiter: oversize
  const auto a = wire_of(MsgType::kStart, 1, {9, 9});
  stream.insert(stream.end(), a.begin(), a.end());  // lost with the garbage: no delimiter before it
  stream.insert(stream.end(), a.begin(), a.end());
  const auto b = wire_of(MsgType::kStop, 2, {});
  stream.insert(stream.end(), b.begin(), b.begin() + 3);  // truncated...
  stream.push_back(0);                                     // ...then cut by a delimiter
  stream.insert(stream.end(), {0, 0});                     // empty frames
  stream.insert(stream.end(), b.begin(), b.end());
  const Fed f = feed(d, stream);
  EXPECT_EQ(f.seqs, (std::vector<std::uint16_t>{1, 2}));
  EXPECT_EQ(f.results, (std::vector<DecodeResult>{DecodeResult::kOversize, DecodeResult::kFrame, DecodeResult::kBadCobs,
                                                 DecodeResult::kEmpty, DecodeResult::kEmpty, DecodeResult::kFrame}));
}

TEST(Frame, VersionAndTypeAreChecked) {
  std::uint8_t raw[16] = {static_cast<std::uint8_t>(kProtocolVersion + 1), 3, 0, 0};
  Writer w(raw + 4, 4);
  w.u32(crc32(raw, 4));
  std::uint8_t enc[32];
  std::size_t e = cobs_encode(raw, 8, enc, sizeof enc);
  enc[e++] = 0;
  Decoder d;
  Fed f = feed(d, std::vector<std::uint8_t>(enc, enc + e));
  EXPECT_EQ(f.results, std::vector<DecodeResult>{DecodeResult::kBadVersion});
  raw[0] = kProtocolVersion;
  raw[1] = 99;
  Writer w2(raw + 4, 4);
  w2.u32(crc32(raw, 4));
  e = cobs_encode(raw, 8, enc, sizeof enc);
  enc[e++] = 0;
  f = feed(d, std::vector<std::uint8_t>(enc, enc + e));
  EXPECT_EQ(f.results, std::vector<DecodeResult>{DecodeResult::kBadType});
}

template <class M>
M round_trip(const M& m) {
  std::uint8_t buf[kMaxPayload];
  const std::size_t n = encode(m, buf, sizeof buf);
  EXPECT_GT(n, 0u);
  M out;
  EXPECT_TRUE(decode(buf, n, &out));
  // One byte short, or one too many, is refused.
  EXPECT_FALSE(decode(buf, n - 1, &out));
  buf[n] = 0;
  EXPECT_FALSE(decode(buf, n + 1, &out));
  decode(buf, n, &out);
  return out;
}

TEST(Messages, RoundTripBitForBit) {
  Sample s{7, 123456789012ull, -0.1234567890123, std::numeric_limits<double>::quiet_NaN(), -0.0123456789};
  const Sample s2 = round_trip(s);
  EXPECT_EQ(s2.k, 7u);
  EXPECT_EQ(s2.t_ns, 123456789012ull);
  EXPECT_EQ(std::memcmp(&s2.ag, &s.ag, 8), 0);
  EXPECT_TRUE(std::isnan(s2.aux));
  EXPECT_EQ(s2.table_x, s.table_x);
  std::uint8_t sample_payload[kMaxPayload];
  EXPECT_EQ(encode(s, sample_payload, sizeof sample_payload), 4u + 8 + 8 + 8 + 8 + 1);  // k, t_ns, ag, aux, table_x, ny
  // The twin's measured floors: as many as ny says, at most kMaxSensors.
  s.ny = 3;
  for (int i = 0; i < 3; ++i) s.y[i] = -0.5 + i;
  const Sample s3 = round_trip(s);
  EXPECT_EQ(s3.ny, 3);
  EXPECT_EQ(std::memcmp(s3.y, s.y, 3 * sizeof(double)), 0);
  EXPECT_EQ(encode(s, sample_payload, sizeof sample_payload), 4u + 8 + 8 + 8 + 8 + 1 + 3 * 8);
  s.ny = twin::kMaxSensors + 1;
  EXPECT_EQ(encode(s, sample_payload, sizeof sample_payload), 0u);

  Telemetry t;
  t.rx = 9;
  t.k = 99;
  t.flags = kHeld | kDriftAlarm;
  t.n = 40;
  for (int i = 0; i < 40; ++i) t.x[i] = std::ldexp(1.0 + i, -i) / 3.0;
  t.acc_top = -1e-300;
  t.dissipated = 5.5;
  t.drift_alarms = 1ull << 39;
  t.comp[0] = 1.01, t.comp[1] = 0.0166, t.comp[2] = 1.4e-4;
  t.est_index = 40, t.alarm_story = 3, t.est_eta = 0.9, t.est_sd = 0.01;
  t.est_stat = 123.5, t.stat_threshold = 12, t.second_story = 7, t.damage_size = 0.0987, t.second_size = 0.05;
  t.onset_s = 15.25, t.change_score = 61.5;
  std::uint8_t telemetry_payload[kMaxPayload];
  EXPECT_EQ(encode(t, telemetry_payload, sizeof telemetry_payload), 499u);  // 40 stories: the largest
  const Telemetry t2 = round_trip(t);
  EXPECT_EQ(t2.est_stat, 123.5);
  EXPECT_EQ(t2.stat_threshold, 12.0);
  EXPECT_EQ(t2.second_story, 7);
  EXPECT_EQ(t2.damage_size, 0.0987);
  EXPECT_EQ(t2.second_size, 0.05);
  EXPECT_EQ(t2.onset_s, 15.25);
  EXPECT_EQ(t2.change_score, 61.5);
  EXPECT_EQ(t2.est_index, 40);
  EXPECT_EQ(t2.alarm_story, 3);
  EXPECT_EQ(t2.est_eta, 0.9);
  EXPECT_EQ(t2.est_sd, 0.01);
  EXPECT_EQ(std::memcmp(t2.comp, t.comp, sizeof t.comp), 0);
  EXPECT_EQ(std::memcmp(t2.x, t.x, sizeof t.x), 0);
  EXPECT_EQ(t2.acc_top, t.acc_top);
  EXPECT_EQ(t2.flags, t.flags);
  EXPECT_EQ(t2.drift_alarms, t.drift_alarms);

  Status st;
  st.state = NodeState::kRunning;
  st.faults[static_cast<int>(FaultCode::kStall)] = 3;
  std::strcpy(st.message, "frame.masses[2]: must be finite and > 0");
  const Status st2 = round_trip(st);
  EXPECT_EQ(st2.state, NodeState::kRunning);
  EXPECT_EQ(st2.faults[static_cast<int>(FaultCode::kStall)], 3u);
  EXPECT_STREQ(st2.message, st.message);

  const Fault f2 = round_trip(Fault{1, FaultCode::kLate, 77, 2});
  EXPECT_EQ(f2.code, FaultCode::kLate);
  EXPECT_EQ(f2.k, 77u);
  EXPECT_EQ(round_trip(Start{5, 6}).k0, 5u);

  std::uint8_t bad_fault[13] = {};
  bad_fault[4] = kFaultCodes;  // out of range code
  Fault f;
  EXPECT_FALSE(decode(bad_fault, sizeof bad_fault, &f));
}

TEST(Config, RoundTripsEveryField) {
  NodeConfig c;
  c.scene.frame.stories = 3;
  for (int i = 0; i < 3; ++i) c.scene.frame.mass_kg[i] = 1e5 + i, c.scene.frame.stiffness_n_per_m[i] = 5e7 - i;
  c.scene.frame.damping = DampingRule::kRayleigh;
  c.scene.frame.stiffness_scale = 0.8;
  c.scene.frame.stiffness_scales[1] = 0.9;
  c.scene.device.kind = DeviceKind::kVines;
  c.scene.device.vines.law = ContactLaw::kTsuji;
  c.scene.device.vines.beta = 1.7;
  c.scene.loop.sensor_rate_hz = 200;
  c.scene.loop.energy_ledger = true;
  c.mode = NodeMode::kTwin;
  c.scalar = 1;
  c.drift_limit_m[2] = 0.02;
  c.comp_order = 3;
  c.comp_kind = CompKind::kAdaptive;
  c.comp_window_s = 0.7;
  c.estimator = TwinEstimator::kKalman;
  std::uint8_t blob[kMaxConfigBlob];
  const std::size_t n = encode(c, blob, sizeof blob);
  ASSERT_GT(n, 0u);
  NodeConfig d;
  ASSERT_TRUE(decode(blob, n, &d));
  std::uint8_t blob2[kMaxConfigBlob];
  ASSERT_EQ(encode(d, blob2, sizeof blob2), n);
  EXPECT_EQ(std::memcmp(blob, blob2, n), 0);
  EXPECT_EQ(d.scene.frame.damping, DampingRule::kRayleigh);
  EXPECT_EQ(d.scene.device.vines.law, ContactLaw::kTsuji);
  EXPECT_EQ(d.mode, NodeMode::kTwin);
  EXPECT_EQ(d.drift_limit_m[2], 0.02);
  EXPECT_EQ(d.comp_kind, CompKind::kAdaptive);
  EXPECT_EQ(d.comp_window_s, 0.7);
  EXPECT_EQ(d.scene.frame.stiffness_scales[1], 0.9);
  EXPECT_EQ(d.estimator, TwinEstimator::kKalman);
  EXPECT_EQ(validate_node(d), nullptr);
  NodeConfig replay = d;
  replay.mode = NodeMode::kReplay;  // an estimator outside twin mode
  EXPECT_STREQ(validate_node(replay), "estimator: only in twin mode");
  blob[n - 1] = 2;  // no such estimator
  EXPECT_FALSE(decode(blob, n, &d));
  blob[n - 1] = 1;
  EXPECT_FALSE(decode(blob, n - 1, &d));
  blob[0] = 41;  // stories out of range
  EXPECT_FALSE(decode(blob, n, &d));
  // The largest configuration fits its blob.
  c.scene.frame.stories = kMaxStories;
  EXPECT_GT(encode(c, blob, sizeof blob), 0u);
  c.comp_order = 0;
  EXPECT_NE(validate_node(c), nullptr);
}

// The compensation settings out of range are refused naming the field: a
// kind beyond adaptive (any u8 decodes, so that the node can say which), a
// window outside 0.05-100 s, an adaptive start beyond a1's bound.
TEST(Config, CompensationSettingsAreChecked) {
  NodeConfig c;
  c.scene.loop.sensor_rate_hz = 1000;
  EXPECT_EQ(validate_node(c), nullptr);
  std::uint8_t blob[kMaxConfigBlob];
  c.comp_kind = static_cast<CompKind>(3);
  const std::size_t n = encode(c, blob, sizeof blob);
  NodeConfig d;
  ASSERT_TRUE(decode(blob, n, &d));
  EXPECT_STREQ(validate_node(d), "comp_kind: must be 0 (none), 1 (polynomial) or 2 (adaptive)");
  c.comp_kind = CompKind::kAdaptive;
  c.comp_window_s = 0.01;
  EXPECT_STREQ(validate_node(c), "comp_window: must be 0.05 to 100 s");
  c.comp_window_s = 1;
  c.comp_delay_s = 0.2;  // fine for a polynomial...
  EXPECT_STREQ(validate_node(c), "comp_delay: the adaptive compensator's initial a1 must be 0 to 0.1 s");
  c.comp_kind = CompKind::kPolynomial;
  EXPECT_EQ(validate_node(c), nullptr);  // ...not for the adaptive one
}

TEST(Extrapolate, ExactForPolynomialsOfItsOrder) {
  const double c[4] = {1, -2, 0.5, -0.1}, h = 0.01, tau = 0.013;
  for (int p = 0; p <= 3; ++p) {
    auto f = [&](double t) {
      double v = 0;
      for (int i = p; i >= 0; --i) v = v * t + c[i];
      return v;
    };
    double y[4];
    for (int i = 0; i < 4; ++i) y[i] = f(-i * h);
    EXPECT_NEAR(extrapolate(y, p, tau, h), f(tau), 1e-12) << p;
    if (p > 0) {
      EXPECT_GT(std::fabs(extrapolate(y, p - 1, tau, h) - f(tau)), 1e-9) << p;  // one order less is not exact
    }
  }
}

}  // namespace
}  // namespace vines::link
