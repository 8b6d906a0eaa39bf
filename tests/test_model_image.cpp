// Model images (vines/model_image.hpp): a model built on the host, written as
// an image and loaded through the streaming Loader in chunks of any size
// steps bit for bit like the model built in place (every device and law,
// double and float, 10 stories, El Centro); corrupt, truncated, too long and
// mismatched images are refused and never leave the loader ready. Also the
// host Engine's model_image/load_image and `vines image`.
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

#include "sim_host/engine.hpp"
#include "sim_host/scene.hpp"
#include "support.hpp"
#include "vines/model_image.hpp"
#include "vines/sim.hpp"

namespace vines {
namespace {

using Bytes = std::vector<std::uint8_t>;
using Kuwabara = VinesDevice<ContactLaw::kKuwabara>;

// Heap blocks whose storage is filled with 0xFF before construction: every
// member without an initialiser (most of a Model) starts as NaN or -1, so a
// loaded model owes nothing to what the storage held.
template <typename T>
struct FreeDirty {
  void operator()(T* p) const {
    p->~T();
    ::operator delete(p, std::align_val_t(alignof(T)));
  }
};
template <typename T>
using Dirty = std::unique_ptr<T, FreeDirty<T>>;
template <typename T>
Dirty<T> dirty() {
  void* raw = ::operator new(sizeof(T), std::align_val_t(alignof(T)));
  std::memset(raw, 0xFF, sizeof(T));
  return Dirty<T>(new (raw) T);
}

template <typename S, typename Dev>
Dirty<Model<S, 10, Dev>> built(const SceneParams& p) {
  auto m = dirty<Model<S, 10, Dev>>();
  const ParamError e = build_model(p, m.get());
  EXPECT_TRUE(e.ok()) << e.field << ": " << e.message;
  return m;
}

template <typename S, int N, typename Dev>
Bytes image_of(const Model<S, N, Dev>& m) {
  Bytes b(image::image_bytes<S, N, Dev>());
  b.resize(image::write_image(m, b.data(), b.size()));
  return b;
}

// Pushes `bytes` in chunks of `chunk` then finishes: "" if the loader ends
// ready, else the first refusal. The loader must be ready exactly when
// nothing was refused.
template <typename S, int N, typename Dev>
std::string load(image::Loader<S, N, Dev>& ld, const Bytes& bytes, std::size_t chunk) {
  ld.reset();
  std::string why;
  for (std::size_t i = 0; i < bytes.size() && why.empty(); i += chunk) {
    const std::size_t n = std::min(chunk, bytes.size() - i);
    if (const char* e = ld.push(bytes.data() + i, n)) why = e;
  }
  if (why.empty())
    if (const char* e = ld.finish()) why = e;
  EXPECT_EQ(ld.ready(), why.empty()) << why;
  return why;
}

// ---- bit-for-bit comparison of two runs

template <typename T>
bool same_bits(const T& a, const T& b) {
  return std::memcmp(&a, &b, sizeof(T)) == 0;
}
template <typename Sc, int R, int C, int O, int MR, int MC>
bool same_bits(const Eigen::Matrix<Sc, R, C, O, MR, MC>& a, const Eigen::Matrix<Sc, R, C, O, MR, MC>& b) {
  for (int i = 0; i < a.size(); ++i)
    if (!same_bits(a.data()[i], b.data()[i])) return false;
  return true;
}

// The first part of the data blocks (and the outputs read off them) that
// differs in any bit, or nullptr.
template <typename S, int N, typename Dev>
const char* first_difference(const Model<S, N, Dev>& ma, const Data<S, N, Dev>& a, const Model<S, N, Dev>& mb,
                             const Data<S, N, Dev>& b) {
#define VINES_SAME(x) \
  if (!same_bits(a.x, b.x)) return #x
  VINES_SAME(z);
  VINES_SAME(s);
  VINES_SAME(sd);
  VINES_SAME(xt);
  VINES_SAME(vt);
  VINES_SAME(xf);
  VINES_SAME(vf);
  VINES_SAME(k);
  VINES_SAME(peak_top);
  VINES_SAME(peak_top_velocity);
  VINES_SAME(t_peak_top);
  VINES_SAME(ee_sum);
  VINES_SAME(ee_open);
  VINES_SAME(a_prev);
  VINES_SAME(mode);
  VINES_SAME(substep);
  VINES_SAME(substep_w);
  VINES_SAME(q);
  VINES_SAME(contact_force);
  VINES_SAME(contact_depth);
  VINES_SAME(max_overlap);
  VINES_SAME(peak_x);
  VINES_SAME(peak_drift);
  VINES_SAME(strain_increments);
  VINES_SAME(last_strain);
  VINES_SAME(ledger.initial);
  VINES_SAME(ledger.input);
  VINES_SAME(ledger.damping);
  VINES_SAME(ledger.contact);
  VINES_SAME(ledger.kinetic);
  VINES_SAME(ledger.strain);
  VINES_SAME(ledger.device);
  VINES_SAME(ledger.residual);
  VINES_SAME(ledger.max_abs_residual);
  VINES_SAME(ledger.max_input);
  VINES_SAME(count.steps);
  VINES_SAME(count.careful_steps);
  VINES_SAME(count.substeps);
  VINES_SAME(count.contact_substeps);
  VINES_SAME(count.rejected);
  VINES_SAME(count.events);
  VINES_SAME(count.contacts);
  VINES_SAME(count.cap_hits);
  VINES_SAME(count.max_substeps_in_step);
  VINES_SAME(count.bad_samples);
  VINES_SAME(count.divergences);
#undef VINES_SAME
  if (!same_bits(floor_displacements(ma, a), floor_displacements(mb, b))) return "floor displacements";
  if (!same_bits(floor_velocities(ma, a), floor_velocities(mb, b))) return "floor velocities";
  if (!same_bits(absolute_accel(ma, a), absolute_accel(mb, b))) return "absolute accelerations";
  if (!same_bits(elastic_energy(ma, a), elastic_energy(mb, b))) return "E_e";
  return nullptr;
}

// The first seconds of El Centro (docs/model.md section 6) at 1 kHz.
const std::vector<double>& elcentro_head() {
  static const std::vector<double> a = [] {
    std::vector<double> all = test::elcentro(1000.0);
    all.resize(5001);  // 5 s
    return all;
  }();
  return a;
}

// ---- every instance: build -> bytes -> load in chunks -> the same steps

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

// ---- refusals

// An image of instance <S, Dev>, and a loader of the same instance.
template <typename S, typename Dev>
struct Fixture {
  Dirty<Model<S, 10, Dev>> ref, target = dirty<Model<S, 10, Dev>>();
  Bytes img;
  image::Loader<S, 10, Dev> ld{target.get()};
  explicit Fixture(const SceneParams& p) : ref(built<S, Dev>(p)), img(image_of(*ref)) {}
};

template <typename S, typename Dev>
void check_corruption_refused(DeviceKind kind) {
  Fixture<S, Dev> f(test::paper_scene(kind));
  const Bytes& img = f.img;
  ASSERT_EQ(load(f.ld, img, 64), "");

  // Every header byte, flipped in one bit and in all eight: refused, by the
  // header check as soon as the header is in, or (the CRC field itself) by
  // the CRC.
  for (std::size_t i = 0; i < image::kHeaderBytes; ++i)
    for (std::uint8_t flip : {std::uint8_t{0x01}, std::uint8_t{0x80}, std::uint8_t{0xFF}}) {
      Bytes bad = img;
      bad[i] ^= flip;
      f.ld.reset();
      const char* at_push = f.ld.push(bad.data(), image::kHeaderBytes);
      const std::string why = load(f.ld, bad, 97);
      EXPECT_NE(why, "") << "header byte " << i << " ^ " << int(flip);
      EXPECT_FALSE(f.ld.ready());
      if (i >= 24) EXPECT_EQ(why, "model image: CRC mismatch") << "byte " << i;
      else EXPECT_NE(at_push, nullptr) << "header byte " << i << " ^ " << int(flip) << " passed the header check";
    }
  // A sample of body bytes (a prime stride, and the last): the CRC.
  std::vector<std::size_t> sample;
  for (std::size_t i = image::kHeaderBytes; i < img.size(); i += 131) sample.push_back(i);
  sample.push_back(img.size() - 1);
  EXPECT_GT(sample.size(), 30u);
  for (std::size_t j : sample) {
    Bytes bad = img;
    bad[j] ^= static_cast<std::uint8_t>(1u << (j % 8));
    EXPECT_EQ(load(f.ld, bad, 256), "model image: CRC mismatch") << "body byte " << j;
  }

  // Truncated, at any point (the header included).
  const std::string total = std::to_string(img.size());
  for (std::size_t n : {img.size() - 1, img.size() / 2, image::kHeaderBytes, std::size_t{5}, std::size_t{0}}) {
    const Bytes cut(img.begin(), img.begin() + static_cast<std::ptrdiff_t>(n));
    EXPECT_EQ(load(f.ld, cut, 256), "model image: truncated (" + std::to_string(n) + " of " + total + " bytes)");
  }
  // Too long: one byte more in the last chunk, or a chunk after finish().
  Bytes longer = img;
  longer.push_back(0);
  EXPECT_EQ(load(f.ld, longer, img.size() + 1), "model image: longer than its header says");
  EXPECT_EQ(load(f.ld, longer, 1), "model image: longer than its header says");
  ASSERT_EQ(load(f.ld, img, 256), "");
  const std::uint8_t extra = 0;
  EXPECT_STREQ(f.ld.push(&extra, 1), "model image: longer than its header says");
  EXPECT_FALSE(f.ld.ready());

  // Another version (header patched: the check comes before the CRC).
  Bytes v2 = img;
  v2[4] = 2;
  EXPECT_EQ(load(f.ld, v2, 7), "model image: version 2, this node reads 1");
  // Not an image at all.
  Bytes junk(img.size(), 0x42);
  EXPECT_EQ(load(f.ld, junk, 256), "model image: not a model image (no VNMI magic)");

  // A refusal is sticky until reset(), and a good image then loads.
  f.ld.reset();
  ASSERT_NE(f.ld.push(v2.data(), v2.size()), nullptr);
  EXPECT_NE(f.ld.push(img.data(), img.size()), nullptr);
  EXPECT_NE(f.ld.finish(), nullptr);
  EXPECT_FALSE(f.ld.ready());
  EXPECT_EQ(load(f.ld, img, 256), "");
  // reset() takes a ready loader back to not ready.
  f.ld.reset();
  EXPECT_FALSE(f.ld.ready());
}

TEST(ModelImageRefusal, CorruptTruncatedLongVersionVinesDouble) {
  check_corruption_refused<double, Kuwabara>(DeviceKind::kVines);
}
TEST(ModelImageRefusal, CorruptTruncatedLongVersionTmdFloat) {
  check_corruption_refused<float, TmdDevice>(DeviceKind::kTmd);
}
TEST(ModelImageRefusal, CorruptTruncatedLongVersionBareDouble) {
  check_corruption_refused<double, NoDevice>(DeviceKind::kNone);
}

TEST(ModelImageRefusal, WrongScalar) {
  const SceneParams p = test::paper_scene(DeviceKind::kVines);
  Fixture<double, Kuwabara> d(p);
  Fixture<float, Kuwabara> f(p);
  EXPECT_EQ(load(d.ld, f.img, 256), "model image: built for float, this node runs double");
  EXPECT_EQ(load(f.ld, d.img, 1), "model image: built for double, this node runs float");
  // The scalar's size is checked too.
  Bytes odd = d.img;
  odd[7] = 4;
  EXPECT_EQ(load(d.ld, odd, 256), "model image: scalar of 4 bytes, this node's double has 8");
}

TEST(ModelImageRefusal, WrongStoryCount) {
  // A real 3-story image on a 10-story node, and a 10-story header saying 20.
  SceneParams p3;
  p3.frame.stories = 3;
  for (int i = 0; i < 3; ++i) {
    p3.frame.mass_kg[i] = 1e5;
    p3.frame.stiffness_n_per_m[i] = 1e8;
  }
  auto m3 = dirty<Model<double, 3, NoDevice>>();
  ASSERT_TRUE(build_model(p3, m3.get()).ok());
  const Bytes img3 = image_of(*m3);
  Fixture<double, NoDevice> f(test::paper_scene(DeviceKind::kNone));
  EXPECT_EQ(load(f.ld, img3, 256), "model image: 3 stories, this node is built for 10");
  Bytes twenty = f.img;
  twenty[8] = 20;
  EXPECT_EQ(load(f.ld, twenty, 256), "model image: 20 stories, this node is built for 10");
  // And the 3-story image loads where it belongs.
  auto back = dirty<Model<double, 3, NoDevice>>();
  image::Loader<double, 3, NoDevice> ld3(back.get());
  EXPECT_EQ(load(ld3, img3, 5), "");
}

TEST(ModelImageRefusal, WrongDeviceOrLaw) {
  Fixture<double, Kuwabara> kuw(test::paper_scene(DeviceKind::kVines));
  Fixture<double, TmdDevice> tmd(test::paper_scene(DeviceKind::kTmd));
  Fixture<double, VinesDevice<ContactLaw::kHertz>> hertz(
      test::paper_scene(DeviceKind::kVines, ContactLaw::kHertz));
  Fixture<double, NoDevice> bare(test::paper_scene(DeviceKind::kNone));
  EXPECT_EQ(load(kuw.ld, tmd.img, 256), "model image: device tmd, this node runs vines (kuwabara)");
  EXPECT_EQ(load(kuw.ld, hertz.img, 256), "model image: device vines (hertz), this node runs vines (kuwabara)");
  EXPECT_EQ(load(kuw.ld, bare.img, 256), "model image: device none, this node runs vines (kuwabara)");
  EXPECT_EQ(load(tmd.ld, kuw.img, 256), "model image: device vines (kuwabara), this node runs tmd");
  EXPECT_EQ(load(bare.ld, hertz.img, 3), "model image: device vines (hertz), this node runs none");
}

TEST(ModelImageRefusal, OtherFieldListIsRefusedByLengthOrLayout) {
  Fixture<double, Kuwabara> f(test::paper_scene(DeviceKind::kVines));
  Bytes len = f.img;
  len[12] ^= 8;  // the header says 8 bytes more or fewer
  const std::string why = load(f.ld, len, 256);
  EXPECT_NE(why.find("bytes, this node expects " + std::to_string(f.img.size())), std::string::npos) << why;
  Bytes layout = f.img;
  layout[20] ^= 1;
  EXPECT_NE(load(f.ld, layout, 256).find("field layout"), std::string::npos);
  Bytes fields = f.img;
  fields[16] ^= 1;
  EXPECT_NE(load(f.ld, fields, 256).find("field layout"), std::string::npos);
}

// ---- what an image holds

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

std::string scene_file(const char* name) { return std::string(VINES_SOURCE_DIR) + "/data/scenes/" + name; }

TEST(ModelImageEngine, LoadImageRunsLikeBuild) {
  const std::vector<double>& rec = elcentro_head();
  for (const char* name : {"elcentro_vines.toml", "elcentro_vines_realtime.toml", "elcentro_tmd.toml", "elcentro_bare.toml"})
    for (host::Scalar scalar : {host::Scalar::kDouble, host::Scalar::kFloat}) {
      SCOPED_TRACE(std::string(name) + " " + host::scalar_name(scalar));
      const host::Scene scene = host::load_scene(scene_file(name));
      auto a = host::make_engine(scene.params, scalar), b = host::make_engine(scene.params, scalar);
      ASSERT_TRUE(a && b);
      ASSERT_TRUE(a->build(scene.params).ok());
      const Bytes img = a->model_image();
      ASSERT_GT(img.size(), image::kHeaderBytes);
      EXPECT_EQ(b->load_image(img.data(), img.size()), "");
      EXPECT_TRUE(b->model_image() == img);
      a->init(rec[0]);
      b->init(rec[0]);
      a->run(rec.data() + 1, rec.size() - 1);
      b->run(rec.data() + 1, rec.size() - 1);
      const host::RunTotals ta = a->totals(), tb = b->totals();
      EXPECT_TRUE(same_bits(ta.peak_x, tb.peak_x));
      EXPECT_TRUE(same_bits(ta.peak_top, tb.peak_top));
      EXPECT_TRUE(same_bits(ta.elastic_energy, tb.elastic_energy));
      EXPECT_TRUE(same_bits(ta.ledger.residual, tb.ledger.residual));
      EXPECT_TRUE(same_bits(ta.count.contacts, tb.count.contacts));
      EXPECT_TRUE(same_bits(ta.count.substeps, tb.count.substeps));
      if (scene.params.device.kind == DeviceKind::kVines) EXPECT_GT(ta.count.contacts, 0);
      const host::Snapshot sa = a->snapshot(), sb = b->snapshot();
      EXPECT_TRUE(same_bits(sa.x, sb.x));
      EXPECT_TRUE(same_bits(sa.acc, sb.acc));
      EXPECT_TRUE(same_bits(sa.particle_x, sb.particle_x));
      EXPECT_TRUE(same_bits(sa.wall_left, sb.wall_left));
      EXPECT_TRUE(same_bits(sa.tmd_x, sb.tmd_x));
      // info() after a load: what the image carries, no modal report.
      const host::ModelInfo ia = a->info(), ib = b->info();
      EXPECT_EQ(ib.stories, 10);
      EXPECT_EQ(ib.sensor_period, ia.sensor_period);
      EXPECT_EQ(ib.device_floor, ia.device_floor);
      EXPECT_EQ(ib.vines.gap, ia.vines.gap);
      EXPECT_EQ(ib.tmd.k, ia.tmd.k);
      EXPECT_EQ(ib.frequency_hz[0], 0.0);
      EXPECT_EQ(ib.total_mass, 0.0);
    }
}

TEST(ModelImageEngine, RefusedImageKeepsTheModel) {
  const host::Scene scene = host::load_scene(scene_file("elcentro_vines.toml"));
  auto a = host::make_engine(scene.params, host::Scalar::kDouble);
  ASSERT_TRUE(a->build(scene.params).ok());
  const Bytes img = a->model_image();
  Bytes bad = img;
  bad[bad.size() / 2] ^= 0x10;
  EXPECT_EQ(a->load_image(bad.data(), bad.size()), "model image: CRC mismatch");
  EXPECT_EQ(a->load_image(img.data(), 100), "model image: truncated (100 of " + std::to_string(img.size()) + " bytes)");
  auto f = host::make_engine(scene.params, host::Scalar::kFloat);
  EXPECT_EQ(f->load_image(img.data(), img.size()), "model image: built for double, this node runs float");
  EXPECT_TRUE(a->model_image() == img);  // still the built model
  EXPECT_GT(a->info().frequency_hz[0], 0.0);
}

// Runs `vines ARGS`; its exit status, stdout in *out.
int vines_cli(const std::string& args, std::string* out) {
  const std::string cmd = std::string(VINES_EXE) + " " + args + " 2>&1";
  std::FILE* p = popen(cmd.c_str(), "r");
  if (!p) return -1;
  char buf[512];
  out->clear();
  while (std::fgets(buf, sizeof buf, p)) *out += buf;
  const int st = pclose(p);
  return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

Bytes read_file(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return Bytes(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
}

TEST(ModelImageCli, WritesTheImageOfAScene) {
  const std::string dir = ::testing::TempDir();
  const std::string out = dir + "vines_image_test.img";
  std::string text;
  ASSERT_EQ(vines_cli("image " + scene_file("elcentro_vines.toml") + " --out " + out, &text), 0) << text;
  EXPECT_NE(text.find(std::to_string(image::image_bytes<double, 10, Kuwabara>()) +
                      " bytes, version 1, double, 10 stories, vines (kuwabara), CRC 0x"),
            std::string::npos)
      << text;
  // The file is the engine's image, and loads.
  const host::Scene scene = host::load_scene(scene_file("elcentro_vines.toml"));
  auto eng = host::make_engine(scene.params, host::Scalar::kDouble);
  ASSERT_TRUE(eng->build(scene.params).ok());
  EXPECT_TRUE(read_file(out) == eng->model_image());

  ASSERT_EQ(vines_cli("image " + scene_file("elcentro_tmd.toml") + " --scalar float --out " + out, &text), 0) << text;
  EXPECT_NE(text.find(std::to_string(image::image_bytes<float, 10, TmdDevice>()) +
                      " bytes, version 1, float, 10 stories, tmd, CRC 0x"),
            std::string::npos)
      << text;
  EXPECT_EQ(read_file(out).size(), (image::image_bytes<float, 10, TmdDevice>()));
  std::remove(out.c_str());
}

TEST(ModelImageCli, RefusalsAndUsage) {
  std::string text;
  const std::string scene = scene_file("elcentro_vines.toml");
  // Usage: 2.
  EXPECT_EQ(vines_cli("image " + scene, &text), 2) << text;
  EXPECT_NE(text.find("no --out FILE given"), std::string::npos) << text;
  EXPECT_EQ(vines_cli("image " + scene + " --scalar half --out x.img", &text), 2) << text;
  EXPECT_EQ(vines_cli("image --out x.img", &text), 2) << text;
  EXPECT_EQ(vines_cli("image " + scene + " --bogus --out x.img", &text), 2) << text;
  // Refused input or a failed write: 1, with the path and the reason.
  EXPECT_EQ(vines_cli("image /nonexistent/scene.toml --out x.img", &text), 1) << text;
  EXPECT_EQ(vines_cli("image " + scene + " --out /nonexistent_dir/x.img", &text), 1) << text;
  EXPECT_NE(text.find("/nonexistent_dir/x.img: cannot open for writing: No such file or directory"), std::string::npos)
      << text;
  if (std::ifstream("/dev/full").good()) {
    EXPECT_EQ(vines_cli("image " + scene + " --out /dev/full", &text), 1) << text;
    EXPECT_NE(text.find("/dev/full: cannot write: No space left on device"), std::string::npos) << text;
  }
  EXPECT_EQ(vines_cli("help image", &text), 0);
  EXPECT_NE(text.find("usage: vines image"), std::string::npos);
}

}  // namespace
}  // namespace vines
