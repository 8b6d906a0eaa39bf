// The fixed-point model image (firmware/include/vines/fixed/image.hpp) and
// the fixed-point node's plant (vines/link/fixed_plant.hpp), on the host:
// an engine loaded with another's image runs the same bits; the plant a
// Cortex-M3 board runs, fed the same samples, reports what the host's
// fixed-point engine reports, bit for bit (the board's own test is
// mcu_hil_clean_* of the cortex-m3 preset); broken, foreign and mismatched
// images and settings are refused with their reason.
#include <gtest/gtest.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "sim_host/engines/build_engine.hpp"
#include "sim_host/scene/scene.hpp"
#include "support.hpp"
#include "vines/link/fixed_plant.hpp"

namespace {

using namespace vines;
using namespace vines::host;

const std::string kScenes = std::string(VINES_SOURCE_DIR) + "/data/scenes/";

Scene fixed_scene(const std::string& device) { return load_scene(kScenes + "elcentro_" + device + "_fixed.toml"); }

std::unique_ptr<Engine> engine_of(const SceneParams& p) { return build_engine(p, Scalar::kFixed, "test"); }

// 3 s of El Centro at 1 kHz through the first contacts.
std::vector<double> samples() {
  std::vector<double> a = test::elcentro(1000.0);
  a.resize(3001);
  return a;
}

// An engine built with other scales, then loaded with the scene's image,
// steps and reads the same bits as the scene's own engine.
TEST(FixedImage, LoadedEngineRunsTheSameBits) {
  const std::vector<double> a = samples();
  for (const char* device : {"bare", "tmd", "vines"}) {
    const Scene sc = fixed_scene(device);
    const auto own = engine_of(sc.params);
    const std::vector<std::uint8_t> image = own->model_image();
    ASSERT_TRUE(fixed::is_fixed_image(image.data(), image.size())) << device;
    SceneParams other = sc.params;
    other.fixed.accel_mps2 = 9.80665;
    const auto loaded = engine_of(other);
    ASSERT_EQ(loaded->load_image(image.data(), image.size()), "") << device;
    own->init(a[0]);
    loaded->init(a[0]);
    for (std::size_t k = 1; k < a.size(); ++k) {
      own->step(a[k]);
      loaded->step(a[k]);
      const Snapshot s = own->snapshot(), t = loaded->snapshot();
      for (int i = 0; i < sc.params.frame.stories; ++i) ASSERT_EQ(s.x[i], t.x[i]) << device << " step " << k;
      ASSERT_EQ(s.elastic_energy, t.elastic_energy) << device;
    }
    EXPECT_GT(std::fabs(own->snapshot().x[9]), 1e-3) << device;  // the building moved
    std::printf("%s: image %zu bytes, 3 s the same bits\n", device, image.size());
  }
}

// The plant of a fixed-point board, compiled here, against the engine (with
// the energy ledger, the contacts' dissipation too).
template <typename Dev>
void plant_matches_engine(const char* device, bool ledger = false) {
  using Plant = link::FixedPlant<10, Dev>;
  Scene sc = fixed_scene(device);
  sc.params.loop.energy_ledger = ledger;
  const auto eng = engine_of(sc.params);
  const std::vector<std::uint8_t> image = eng->model_image();
  auto model = std::make_unique<typename Plant::ModelT>();
  auto data = std::make_unique<typename Plant::DataT>();
  Plant plant(model.get(), data.get());
  ASSERT_EQ(plant.image_begin(static_cast<std::uint32_t>(image.size())), nullptr);
  // In two pieces, as frames bring it.
  const std::size_t half = image.size() / 2;
  ASSERT_EQ(plant.image_push(image.data(), half), nullptr);
  ASSERT_EQ(plant.image_push(image.data() + half, image.size() - half), nullptr);
  ASSERT_EQ(plant.image_finish(), nullptr);
  link::NodeConfig c;
  c.scene = sc.params;
  c.scalar = link_code(Scalar::kFixed);
  char msg[160] = {};
  ASSERT_TRUE(plant.configure(c, msg, sizeof msg)) << msg;
  const std::vector<double> a = samples();
  eng->init(a[0]);
  plant.init(a[0], 0);
  long long contacts = 0;
  for (std::size_t k = 1; k < a.size(); ++k) {
    eng->step(a[k]);
    plant.step(a[k], 0);
    link::Telemetry t;
    plant.read(&t);
    const Snapshot s = eng->snapshot();
    for (int i = 0; i < 10; ++i) ASSERT_EQ(t.x[i], s.x[i]) << device << " step " << k << " floor " << i;
    ASSERT_EQ(t.acc_top, s.acc[9]) << device << " step " << k;
    ASSERT_EQ(t.elastic_energy, s.elastic_energy) << device << " step " << k;
    ASSERT_EQ(t.particle_x, s.particle_x) << device << " step " << k;
    ASSERT_EQ(t.particle_v, s.particle_v) << device << " step " << k;
    ASSERT_EQ(t.contact_force, s.contact_force) << device << " step " << k;
    ASSERT_EQ(t.dissipated, eng->probe().ledger.contact) << device << " step " << k;
    ASSERT_EQ(t.flags & link::kGuard, 0) << device << " step " << k;
    contacts += t.contact_force != 0;
  }
  if constexpr (Dev::kKind == DeviceKind::kVines) EXPECT_GT(contacts, 0);  // through contacts
  if (ledger && Dev::kKind == DeviceKind::kVines) EXPECT_GT(eng->probe().ledger.contact, 0) << device;
}

TEST(FixedImage, BoardPlantReportsTheEngineBitForBit) {
  plant_matches_engine<NoDevice>("bare");
  plant_matches_engine<TmdDevice>("tmd");
  plant_matches_engine<VinesDevice<ContactLaw::kKuwabara>>("vines");
  plant_matches_engine<NoDevice>("bare", true);
  plant_matches_engine<VinesDevice<ContactLaw::kKuwabara>>("vines", true);
}

// What a fixed-point node refuses, and why.
TEST(FixedImage, RefusesBrokenForeignAndMismatched) {
  const Scene vines_sc = fixed_scene("vines");
  const auto eng = engine_of(vines_sc.params);
  const std::vector<std::uint8_t> good = eng->model_image();
  auto refusal = [&](std::vector<std::uint8_t> img) { return engine_of(vines_sc.params)->load_image(img.data(), img.size()); };
  std::vector<std::uint8_t> bad = good;
  bad[bad.size() / 2] ^= 0x10;
  EXPECT_NE(refusal(bad).find("CRC mismatch"), std::string::npos);
  bad = good;
  bad.resize(bad.size() - 1);
  EXPECT_NE(refusal(bad).find("truncated"), std::string::npos);
  const std::vector<std::uint8_t> tmd = engine_of(fixed_scene("tmd").params)->model_image();
  EXPECT_NE(refusal(tmd).find("device.kind"), std::string::npos);
  const std::vector<std::uint8_t> dbl = build_engine(vines_sc.params, Scalar::kDouble, "test")->model_image();
  EXPECT_NE(refusal(dbl).find("not a fixed-point model image"), std::string::npos);

  // The plant: an image of another size at once, settings that differ from
  // the image's.
  using Plant = link::FixedPlant<10, VinesDevice<ContactLaw::kKuwabara>>;
  auto model = std::make_unique<Plant::ModelT>();
  auto data = std::make_unique<Plant::DataT>();
  Plant plant(model.get(), data.get());
  EXPECT_NE(plant.image_begin(static_cast<std::uint32_t>(tmd.size())), nullptr);
  ASSERT_EQ(plant.image_begin(static_cast<std::uint32_t>(good.size())), nullptr);
  ASSERT_EQ(plant.image_push(good.data(), good.size()), nullptr);
  ASSERT_EQ(plant.image_finish(), nullptr);
  char msg[160] = {};
  link::NodeConfig c;
  c.scene = vines_sc.params;
  c.scalar = link_code(Scalar::kFloat);
  EXPECT_FALSE(plant.configure(c, msg, sizeof msg));
  EXPECT_NE(std::string(msg).find("Q3.28"), std::string::npos) << msg;
  c.scalar = link_code(Scalar::kFixed);
  c.scene.loop.split_steps = 16;
  EXPECT_FALSE(plant.configure(c, msg, sizeof msg));
  EXPECT_NE(std::string(msg).find("loop.split_steps"), std::string::npos) << msg;
  c.scene.loop.split_steps = vines_sc.params.loop.split_steps;
  c.scene.loop.sensor_rate_hz = 2000;
  EXPECT_FALSE(plant.configure(c, msg, sizeof msg));
  EXPECT_NE(std::string(msg).find("loop.sensor_rate_hz"), std::string::npos) << msg;
  c.scene.loop.sensor_rate_hz = vines_sc.params.loop.sensor_rate_hz;
  c.scene.loop.energy_ledger = true;  // the image keeps none
  EXPECT_FALSE(plant.configure(c, msg, sizeof msg));
  EXPECT_NE(std::string(msg).find("loop.energy_ledger"), std::string::npos) << msg;
  c.scene.loop.energy_ledger = false;
  EXPECT_TRUE(plant.configure(c, msg, sizeof msg)) << msg;
}

}  // namespace
