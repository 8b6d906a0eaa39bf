// The firmware application's node as the board runs it (ModelPlant: one
// compiled instance, its model streamed in as the host-built image, timed by
// TimedPlant), in this process on the host's HAL port: the telemetry equals
// the host node's plant, refused images leave the node unconfigured with the
// reason, and the deadline monitor's counts reach the status.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "firmware/app/node_app.hpp"
#include "sim_host/engines/build_engine.hpp"
#include "sim_host/hil/modes/plant.hpp"
#include "support.hpp"
#include "vines/build/build_model.hpp"
#include "vines/image/model_image.hpp"
#include "vines/link/model_plant.hpp"

namespace vines::test {
namespace {

using Kuwabara = VinesDevice<ContactLaw::kKuwabara>;
using Plant = link::ModelPlant<double, 10, Kuwabara>;
using Timed = app::TimedPlant<Plant>;

// What the node wrote: its frames, decoded.
struct Capture {
  link::Decoder dec;
  std::vector<link::Telemetry> tel;
  link::Status status;
  std::vector<link::Fault> faults;
  void write(const std::uint8_t* p, std::size_t n) {
    for (std::size_t i = 0; i < n; ++i) {
      if (dec.push(p[i]) != link::DecodeResult::kFrame) continue;
      const link::Frame& f = dec.frame();
      link::Telemetry t;
      link::Fault x;
      if (f.type == link::MsgType::kTelemetry && link::decode(f.payload, f.length, &t)) tel.push_back(t);
      if (f.type == link::MsgType::kStatus) EXPECT_TRUE(link::decode(f.payload, f.length, &status));
      if (f.type == link::MsgType::kFault && link::decode(f.payload, f.length, &x)) faults.push_back(x);
    }
  }
};

// The bench's side of a session, one frame at a time into a node.
template <class NodeT>
struct Bench {
  NodeT* node;
  std::uint16_t seq = 0;
  void send(link::MsgType type, const std::uint8_t* payload, std::size_t n) {
    std::uint8_t wire[link::kMaxWire];
    const std::size_t w = link::encode_frame(type, seq++, payload, n, wire, sizeof wire);
    for (std::size_t i = 0; i < w; ++i) node->on_byte(wire[i], 0);
  }
  template <class Msg>
  void send(link::MsgType type, const Msg& m) {
    std::uint8_t p[link::kMaxPayload];
    send(type, p, link::encode(m, p, sizeof p));
  }
  void part(link::ConfigPart part, const std::vector<std::uint8_t>& bytes) {
    const std::uint32_t crc = link::crc32(bytes.data(), bytes.size());
    for (std::size_t off = 0; off < bytes.size(); off += link::kChunk)
      send(link::MsgType::kConfigure,
           link::ConfigureChunk{part, static_cast<std::uint32_t>(off), static_cast<std::uint32_t>(bytes.size()), crc,
                                bytes.data() + off,
                                static_cast<std::uint16_t>(std::min(link::kChunk, bytes.size() - off))});
  }
  void settings(const link::NodeConfig& c) {
    std::vector<std::uint8_t> blob(link::kMaxConfigBlob);
    blob.resize(link::encode(c, blob.data(), blob.size()));
    part(link::ConfigPart::kSettings, blob);
  }
  // Samples a[k], with the measured force f[k] in hybrid mode (none: 0).
  void run(const std::vector<double>& a, const std::vector<double>& f = {}) {
    send(link::MsgType::kStart, link::Start{0, 0});
    for (std::size_t k = 0; k < a.size(); ++k)
      send(link::MsgType::kSample, link::Sample{static_cast<std::uint32_t>(k), 0, a[k], f.empty() ? 0.0 : f[k]});
    send(link::MsgType::kStop, nullptr, 0);
  }
};

template <typename Dev>
std::vector<std::uint8_t> image_of(const SceneParams& p) {
  auto m = std::make_unique<Model<double, 10, Dev>>();
  EXPECT_TRUE(build_model(p, m.get()).ok());
  std::vector<std::uint8_t> out(image::image_bytes<double, 10, Dev>());
  EXPECT_EQ(image::write_image(*m, out.data(), out.size()), out.size());
  return out;
}

// The hybrid frame image the bench sends (sim_host/hil/offline.cpp): the
// bare frame's modes of scene p at its sensor rate.
std::vector<std::uint8_t> hybrid_image_of(SceneParams p) {
  p.device.kind = DeviceKind::kNone;
  return host::hybrid_image(host::build_engine(p, host::Scalar::kDouble, "test")->info(), 1.0 / p.loop.sensor_rate_hz);
}

link::NodeConfig config_of(const SceneParams& p) {
  link::NodeConfig c;
  c.scene = p;
  return c;
}

// The host plant's telemetry over samples a[k] (forces f[k]; none: 0).
std::vector<link::Telemetry> host_run(host::HostPlant* h, const std::vector<double>& a,
                                      const std::vector<double>& f = {}) {
  std::vector<link::Telemetry> out(a.size());
  for (std::size_t k = 0; k < a.size(); ++k) {
    const double fk = f.empty() ? 0.0 : f[k];
    if (k == 0) h->init(a[0], fk);
    else h->step(a[k], fk);
    h->read(&out[k]);
  }
  return out;
}

// The board's node: static-sized blocks, here on the heap of the test.
struct BoardNode {
  std::unique_ptr<Model<double, 10, Kuwabara>> model = std::make_unique<Model<double, 10, Kuwabara>>();
  std::unique_ptr<Data<double, 10, Kuwabara>> data = std::make_unique<Data<double, 10, Kuwabara>>();
  Plant plant{model.get(), data.get()};
  Timed timed{&plant};
  Capture out;
  std::unique_ptr<link::Node<Timed, Capture>> node = std::make_unique<link::Node<Timed, Capture>>(&timed, &out);
  Bench<link::Node<Timed, Capture>> bench{node.get()};
};

TEST(NodeApp, BoardNodeOnAnImageStepsAsTheHostNode) {
  const SceneParams p = paper_scene(DeviceKind::kVines);
  std::vector<double> a = elcentro(1000.0);
  a.resize(3000);  // 3 s: the first contacts
  BoardNode b;
  b.bench.part(link::ConfigPart::kModelImage, image_of<Kuwabara>(p));
  b.bench.settings(config_of(p));
  ASSERT_EQ(b.out.status.state, link::NodeState::kConfigured) << b.out.status.message;
  b.bench.run(a);
  ASSERT_EQ(b.out.tel.size(), a.size());
  EXPECT_TRUE(b.node->stopped());

  // The host node's plant: the engine of the same scene, built in place.
  host::HostPlant host;
  char msg[128] = {};
  ASSERT_TRUE(host.load(image_of<Kuwabara>(p), config_of(p), msg, sizeof msg)) << msg;
  const std::vector<link::Telemetry> ht = host_run(&host, a);
  double worst = 0, peak = 0;
  int contacts = 0;
  for (std::size_t k = 0; k < a.size(); ++k) {
    const link::Telemetry& t = ht[k];
    const link::Telemetry& n = b.out.tel[k];
    ASSERT_EQ(n.k, k);
    for (int i = 0; i < 10; ++i) worst = std::fmax(worst, std::fabs(n.x[i] - t.x[i]));
    worst = std::fmax(worst, std::fabs(n.particle_x - t.particle_x));
    peak = std::fmax(peak, std::fabs(t.x[9]));
    contacts += n.contact_mode != 0 && (k == 0 || b.out.tel[k - 1].contact_mode == 0);
  }
  EXPECT_GT(contacts, 0) << "the slice must exercise contacts";
  // Same source, same host: the two compiled copies of the loop may contract
  // differently, so agreement to rounding, not bits.
  EXPECT_LE(worst, 1e-12 * peak) << "peak " << peak;
  // The deadline monitor saw every step and reports them in STATUS.
  EXPECT_EQ(b.out.status.timing.counter_hz, 1000000000u);
  EXPECT_EQ(b.out.status.timing.budget_ticks, 1000000u);  // one period at 1 kHz, in ns
  EXPECT_GT(b.out.status.timing.worst_ticks, 0u);
  std::uint32_t worst_ticks = 0;
  for (const link::Telemetry& t : b.out.tel) worst_ticks = std::max(worst_ticks, t.step_ticks);
  EXPECT_EQ(b.out.status.timing.worst_ticks, worst_ticks);
  EXPECT_EQ(b.out.tel[b.out.status.timing.worst_k].step_ticks, worst_ticks);
}

TEST(NodeApp, ABudgetBelowEveryStepCountsEveryStepAsAnOverrun) {
  const SceneParams p = paper_scene(DeviceKind::kVines);
  std::vector<double> a = elcentro(1000.0);
  a.resize(200);
  BoardNode b;
  b.bench.part(link::ConfigPart::kModelImage, image_of<Kuwabara>(p));
  link::NodeConfig c = config_of(p);
  c.budget_ticks = 1;  // 1 ns
  b.bench.settings(c);
  b.bench.run(a);
  EXPECT_EQ(b.out.status.timing.budget_ticks, 1u);
  EXPECT_EQ(b.out.status.timing.overruns, a.size());
}

TEST(NodeApp, ACorruptImageIsRefusedWithTheReasonAndTheNodeStaysUnconfigured) {
  const SceneParams p = paper_scene(DeviceKind::kVines);
  const std::vector<std::uint8_t> good = image_of<Kuwabara>(p);
  for (std::size_t at : {std::size_t{0}, std::size_t{5}, good.size() / 2, good.size() - 1}) {
    std::vector<std::uint8_t> bad = good;
    bad[at] ^= 0x40;
    BoardNode b;
    b.bench.part(link::ConfigPart::kModelImage, bad);
    EXPECT_NE(std::string(b.out.status.message).find("model image"), std::string::npos)
        << "byte " << at << ": " << b.out.status.message;
    ASSERT_FALSE(b.out.faults.empty());
    EXPECT_EQ(b.out.faults.back().code, link::FaultCode::kConfig);
    b.bench.settings(config_of(p));
    EXPECT_EQ(b.out.status.state, link::NodeState::kBooted) << "byte " << at;
    EXPECT_STREQ(b.out.status.message, "no model image: send it before the settings");
  }
  // Truncated: the last chunk never comes, so the settings find no image.
  BoardNode b;
  std::vector<std::uint8_t> cut(good.begin(), good.end() - 300);
  const std::uint32_t crc = link::crc32(good.data(), good.size());
  for (std::size_t off = 0; off < cut.size(); off += link::kChunk)
    b.bench.send(link::MsgType::kConfigure,
                 link::ConfigureChunk{link::ConfigPart::kModelImage, static_cast<std::uint32_t>(off),
                                      static_cast<std::uint32_t>(good.size()), crc, cut.data() + off,
                                      static_cast<std::uint16_t>(std::min(link::kChunk, cut.size() - off))});
  b.bench.settings(config_of(p));
  EXPECT_EQ(b.out.status.state, link::NodeState::kBooted);
  EXPECT_STREQ(b.out.status.message, "no model image: send it before the settings");
}

TEST(NodeApp, AnImageOfAnotherDeviceOrSettingsThatDoNotFitAreRefused) {
  const SceneParams tmd = paper_scene(DeviceKind::kTmd);
  BoardNode b;
  b.bench.part(link::ConfigPart::kModelImage, image_of<TmdDevice>(tmd));
  EXPECT_NE(std::string(b.out.status.message).find("model image"), std::string::npos) << b.out.status.message;

  const SceneParams p = paper_scene(DeviceKind::kVines);
  SceneParams other_rate = p;
  other_rate.loop.sensor_rate_hz = 2000.0;
  BoardNode r;
  r.bench.part(link::ConfigPart::kModelImage, image_of<Kuwabara>(p));
  ASSERT_STREQ(r.out.status.message, "");
  r.bench.settings(config_of(other_rate));
  EXPECT_EQ(r.out.status.state, link::NodeState::kBooted);
  EXPECT_STREQ(r.out.status.message, "loop.sensor_rate_hz: differs from the model image's");
  link::NodeConfig hybrid = config_of(p);
  hybrid.mode = link::NodeMode::kHybrid;
  r.bench.settings(hybrid);
  EXPECT_EQ(r.out.status.state, link::NodeState::kBooted);
  EXPECT_STREQ(r.out.status.message, "mode hybrid: send a hybrid frame image before the settings");
  link::NodeConfig as_float = config_of(p);
  as_float.scalar = 1;
  r.bench.settings(as_float);
  EXPECT_STREQ(r.out.status.message, "scalar: this node runs double");
  r.bench.settings(config_of(p));
  EXPECT_EQ(r.out.status.state, link::NodeState::kConfigured) << r.out.status.message;
}

// Hybrid mode on the board: the bare frame's modes arrive as the hybrid
// frame image, and the board steps them with the table's force as the host
// node does; with no force the frame is the bare frame of the core loop.
TEST(NodeApp, BoardNodeRunsTheHybridFrameAsTheHostNode) {
  const SceneParams p = paper_scene(DeviceKind::kVines);
  std::vector<double> a = elcentro(1000.0);
  a.resize(5000);
  std::vector<double> f(a.size());
  for (std::size_t k = 0; k < f.size(); ++k) f[k] = 2e5 * std::sin(7.0 * 1e-3 * static_cast<double>(k));
  link::NodeConfig c = config_of(p);
  c.mode = link::NodeMode::kHybrid;
  const std::vector<std::uint8_t> img = hybrid_image_of(p);
  ASSERT_EQ(img.size(), link::hybrid_image_bytes(10));
  BoardNode b;
  b.bench.part(link::ConfigPart::kModelImage, img);
  b.bench.settings(c);
  ASSERT_EQ(b.out.status.state, link::NodeState::kConfigured) << b.out.status.message;
  b.bench.run(a, f);
  ASSERT_EQ(b.out.tel.size(), a.size());

  host::HostPlant host;
  char msg[128] = {};
  ASSERT_TRUE(host.load(img, c, msg, sizeof msg)) << msg;
  const std::vector<link::Telemetry> ht = host_run(&host, a, f);
  double worst = 0, peak = 0;
  for (std::size_t k = 0; k < a.size(); ++k) {
    const link::Telemetry& t = ht[k];
    for (int i = 0; i < 10; ++i) worst = std::fmax(worst, std::fabs(b.out.tel[k].x[i] - t.x[i]));
    peak = std::fmax(peak, std::fabs(t.x[9]));
  }
  EXPECT_GT(peak, 0.01);
  EXPECT_LE(worst, 1e-12 * peak) << "peak " << peak;

  // No force: the modal hybrid frame against the core's bare frame (the
  // exact step in physical coordinates), an independent discretisation.
  BoardNode z;
  z.bench.part(link::ConfigPart::kModelImage, img);
  z.bench.settings(c);
  z.bench.run(a);
  SceneParams bare = p;
  bare.device.kind = DeviceKind::kNone;
  host::HostPlant ref;
  ASSERT_TRUE(ref.load(image_of<NoDevice>(bare), config_of(bare), msg, sizeof msg)) << msg;
  const std::vector<link::Telemetry> rt = host_run(&ref, a);
  worst = peak = 0;
  for (std::size_t k = 0; k < a.size(); ++k) {
    const link::Telemetry& t = rt[k];
    for (int i = 0; i < 10; ++i) worst = std::fmax(worst, std::fabs(z.out.tel[k].x[i] - t.x[i]));
    peak = std::fmax(peak, std::fabs(t.x[9]));
  }
  EXPECT_GT(peak, 0.05);
  EXPECT_LE(worst, 1e-9 * peak) << "peak " << peak;
}

TEST(NodeApp, AHybridFrameImageIsCheckedWhole) {
  const SceneParams p = paper_scene(DeviceKind::kVines);
  const std::vector<std::uint8_t> good = hybrid_image_of(p);
  link::NodeConfig c = config_of(p);
  c.mode = link::NodeMode::kHybrid;
  const auto refused = [&](const std::vector<std::uint8_t>& img, const std::string& why) {
    BoardNode b;
    b.bench.part(link::ConfigPart::kModelImage, img);
    EXPECT_NE(std::string(b.out.status.message).find(why), std::string::npos) << b.out.status.message;
    b.bench.settings(c);
    EXPECT_EQ(b.out.status.state, link::NodeState::kBooted);
  };
  std::vector<std::uint8_t> nan = good;
  const double bad = std::nan("");
  std::memcpy(nan.data() + 16 + 8 * 3, &bad, 8);  // mode 1's a00
  refused(nan, "not finite");
  refused(std::vector<std::uint8_t>(good.begin(), good.end() - 8), "length");
  std::vector<std::uint8_t> version = good;
  version[4] = 9;
  refused(version, "version");
  link::ModalData tall;  // 11 modes of some frame: more than the board's 10
  tall.n = 11;
  link::ModeStep steps[11];
  std::vector<std::uint8_t> eleven(link::hybrid_image_bytes(11));
  ASSERT_EQ(link::write_hybrid_image(tall, steps, 1e-3, eleven.data(), eleven.size()), eleven.size());
  refused(eleven, "more stories");
  // A good image of another rate does not fit the settings.
  SceneParams other = p;
  other.loop.sensor_rate_hz = 2048.0;
  BoardNode b;
  b.bench.part(link::ConfigPart::kModelImage, hybrid_image_of(other));
  ASSERT_STREQ(b.out.status.message, "");
  b.bench.settings(c);
  EXPECT_STREQ(b.out.status.message, "loop.sensor_rate_hz: differs from the hybrid frame image's");
}

}  // namespace
}  // namespace vines::test
