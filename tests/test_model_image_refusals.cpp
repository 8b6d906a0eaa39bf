// Model images (vines/image/model_image.hpp) refused: corrupt, truncated, too long
// and mismatched images (scalar, story count, device, law, field list) are
// refused and never leave the loader ready.
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
#include "vines/build/build_model.hpp"
#include "vines/image/model_image.hpp"
#include "vines/step/sim.hpp"

namespace vines {
namespace {

using namespace image_test;

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
  v2[4] = 1;
  EXPECT_EQ(load(f.ld, v2, 7), "model image: version 1, this node reads 3");
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

}  // namespace
}  // namespace vines
