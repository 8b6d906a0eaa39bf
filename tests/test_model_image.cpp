// Model images (vines/image/model_image.hpp): a model built on the host, written as
// an image and loaded through the streaming Loader in chunks of any size
// steps bit for bit like the model built in place (every device and law,
// double and float, 10 stories, El Centro); padding stays out of the image;
// the sizes of the El Centro scenes' images. Refusals:
// test_model_image_refusals.cpp; the host Engine and `vines image`:
// test_model_image_engine.cpp.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <memory>
#include <new>
#include <string>
#include <vector>

#include "model_image_support.hpp"
#include "sim_host/engines/engine.hpp"
#include "sim_host/scene/scene.hpp"
#include "support.hpp"
#include "vines/image/model_image.hpp"
#include "vines/step/sim.hpp"

namespace vines {
namespace {

using namespace image_test;

template <typename S_, typename Dev_, DeviceKind K, ContactLaw L = ContactLaw::kKuwabara>
struct Inst {
  using S = S_;
  using Dev = Dev_;
  static constexpr DeviceKind kKind = K;
  static constexpr ContactLaw kLaw = L;
};
// No device, the TMD, and a VI NES with each law of the registry
// (contact_laws.hpp), in double and float.
template <typename... Ls>
::testing::Types<Inst<double, NoDevice, DeviceKind::kNone>, Inst<float, NoDevice, DeviceKind::kNone>,
                 Inst<double, TmdDevice, DeviceKind::kTmd>, Inst<float, TmdDevice, DeviceKind::kTmd>,
                 Inst<double, VinesDevice<Ls::kTag>, DeviceKind::kVines, Ls::kTag>...,
                 Inst<float, VinesDevice<Ls::kTag>, DeviceKind::kVines, Ls::kTag>...>
instances_of(LawTable<Ls...>);
using Instances = decltype(instances_of(ContactLaws{}));

template <typename T>
class ModelImage : public ::testing::Test {};
TYPED_TEST_SUITE(ModelImage, Instances);

TYPED_TEST(ModelImage, LoadedModelStepsBitForBitLikeTheBuiltOne) {
  using S = typename TypeParam::S;
  using Dev = typename TypeParam::Dev;
  using M = Model<S, 10, Dev>;
  using D = Data<S, 10, Dev>;
  const std::vector<double>& rec = elcentro_head();
  // The paper's scene with every output (energy ledger, per-floor peaks), the
  // same with none (plain exact steps), and a device below the top floor.
  std::vector<SceneParams> scenes(2, test::paper_scene(TypeParam::kKind, TypeParam::kLaw));
  scenes[1].loop.energy_ledger = scenes[1].loop.floor_peaks = false;
  if (TypeParam::kKind != DeviceKind::kNone) {
    scenes.push_back(scenes[0]);
    scenes.back().device.floor = 6;
  }
  for (std::size_t sc = 0; sc < scenes.size(); ++sc) {
    SCOPED_TRACE("scene variant " + std::to_string(sc));
    const auto ref = built<S, Dev>(scenes[sc]);
    const Bytes img = image_of(*ref);
    ASSERT_EQ(img.size(), (image::image_bytes<S, 10, Dev>()));

    // Loaded in chunks of every kind of size; each gives back the same image.
    auto loaded = dirty<M>();
    image::Loader<S, 10, Dev> ld(loaded.get());
    for (std::size_t chunk : {img.size(), std::size_t{256}, std::size_t{1}, std::size_t{3}, std::size_t{29},
                              std::size_t{1000}}) {
      ASSERT_EQ(load(ld, img, chunk), "") << "chunks of " << chunk;
      ASSERT_TRUE(image_of(*loaded) == img) << "chunks of " << chunk;
    }
    EXPECT_EQ(loaded->h, ref->h);
    EXPECT_EQ(loaded->floor, ref->floor);

    // step() on both, compared after every step.
    auto da = dirty<D>(), db = dirty<D>();
    init(*ref, *da, static_cast<S>(rec[0]));
    init(*loaded, *db, static_cast<S>(rec[0]));
    ASSERT_EQ(first_difference(*ref, *da, *loaded, *db), nullptr) << "after init";
    for (std::size_t k = 1; k < rec.size(); ++k) {
      step(*ref, *da, static_cast<S>(rec[k]));
      step(*loaded, *db, static_cast<S>(rec[k]));
      const char* diff = first_difference(*ref, *da, *loaded, *db);
      ASSERT_EQ(diff, nullptr) << "step " << k;
    }
    if (TypeParam::kKind == DeviceKind::kVines) {
      EXPECT_GT(da->count.contacts, 0) << "no contact: the comparison never left the free steps";
      EXPECT_GT(da->count.careful_steps, 0);
    }
    // run() in blocks on both (the block path of exact steps).
    init(*ref, *da, static_cast<S>(rec[0]));
    init(*loaded, *db, static_cast<S>(rec[0]));
    for (std::size_t k = 1; k < rec.size(); k += 700) {
      const std::size_t n = std::min<std::size_t>(700, rec.size() - k);
      run(*ref, *da, rec.data() + k, n);
      run(*loaded, *db, rec.data() + k, n);
      ASSERT_EQ(first_difference(*ref, *da, *loaded, *db), nullptr) << "run() up to sample " << k + n;
    }
    EXPECT_EQ(da->count.steps, static_cast<std::int64_t>(rec.size() - 1));
  }
}

TEST(ModelImage, PaddingIsNotInTheImageAndZeroAfterLoad) {
  using M = Model<double, 10, Kuwabara>;
  Fixture<double, Kuwabara> f(test::paper_scene(DeviceKind::kVines));
  ASSERT_EQ(load(f.ld, f.img, 256), "");
  const M& m = *f.target;
  for (int j = 10; j < M::kP; ++j) {  // padding modes, if this build pads
    EXPECT_EQ(m.lti.p11(j), 0.0);
    EXPECT_EQ(m.lti.p22(j), 0.0);
    EXPECT_EQ(m.rows.top(j), 0.0);
    EXPECT_EQ(m.pos_map.col(j).cwiseAbs().sum(), 0.0);
    EXPECT_EQ(m.top_acc_z(j), 0.0);
    EXPECT_EQ(m.top_acc_z(M::kP + j), 0.0);
  }
  // The reporting-only parts are not carried: zero, not left as they were.
  EXPECT_EQ(m.modal.omega.cwiseAbs().sum(), 0.0);
  EXPECT_EQ(m.frame.K.cwiseAbs().sum(), 0.0);
  // The device's design is carried (read by the guard and host snapshots).
  EXPECT_EQ(m.dev.design.radius, f.ref->dev.design.radius);
  EXPECT_EQ(m.dev.design.gap, f.ref->dev.design.gap);
}

TEST(ModelImage, SizesOfTheElCentroScenes) {
  const std::size_t kd = image::image_bytes<double, 10, Kuwabara>(), kf = image::image_bytes<float, 10, Kuwabara>();
  const std::size_t td = image::image_bytes<double, 10, TmdDevice>(), tf = image::image_bytes<float, 10, TmdDevice>();
  const std::size_t bd = image::image_bytes<double, 10, NoDevice>(), bf = image::image_bytes<float, 10, NoDevice>();
  std::printf("model image bytes, 10 stories: VI NES (Kuwabara) double %zu float %zu; TMD double %zu float %zu; "
              "bare double %zu float %zu\n",
              kd, kf, td, tf, bd, bf);
  RecordProperty("vines_kuwabara_double", static_cast<int>(kd));
  RecordProperty("vines_kuwabara_float", static_cast<int>(kf));
  RecordProperty("tmd_double", static_cast<int>(td));
  RecordProperty("tmd_float", static_cast<int>(tf));
  // A float image is about half a double one (the header and a few doubles
  // of design, loop settings and the period aside).
  EXPECT_LT(kf, kd / 2 + 200);
  EXPECT_LT(tf, td / 2 + 200);
  // What write_image returns for a real model.
  Fixture<double, Kuwabara> f(test::paper_scene(DeviceKind::kVines));
  EXPECT_EQ(f.img.size(), kd);
  Bytes small(kd - 1);
  EXPECT_EQ(image::write_image(*f.ref, small.data(), small.size()), 0u);
  image::HeaderInfo h;
  ASSERT_TRUE(image::read_header(f.img.data(), f.img.size(), &h));
  EXPECT_EQ(h.version, image::kVersion);
  EXPECT_EQ(h.length, kd);
  EXPECT_EQ(h.stories, 10);
  EXPECT_EQ(h.scalar, 0);
  EXPECT_EQ(h.device, static_cast<std::uint8_t>(DeviceKind::kVines));
  EXPECT_EQ(h.law, static_cast<std::uint8_t>(ContactLaw::kKuwabara));
}

// ---- host Engine and `vines image`


}  // namespace
}  // namespace vines
