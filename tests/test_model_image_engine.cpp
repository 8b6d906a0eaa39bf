// Model images through the host: the Engine's model_image / load_image (a
// loaded image runs like a build; a refused one keeps the model) and
// `vines image` (the file it writes, its refusals and usage).
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
                      " bytes, version 3, double, 10 stories, vines (kuwabara), CRC 0x"),
            std::string::npos)
      << text;
  // The file is the engine's image, and loads.
  const host::Scene scene = host::load_scene(scene_file("elcentro_vines.toml"));
  auto eng = host::make_engine(scene.params, host::Scalar::kDouble);
  ASSERT_TRUE(eng->build(scene.params).ok());
  EXPECT_TRUE(read_file(out) == eng->model_image());

  ASSERT_EQ(vines_cli("image " + scene_file("elcentro_tmd.toml") + " --scalar float --out " + out, &text), 0) << text;
  EXPECT_NE(text.find(std::to_string(image::image_bytes<float, 10, TmdDevice>()) +
                      " bytes, version 3, float, 10 stories, tmd, CRC 0x"),
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
  EXPECT_NE(text.find("/nonexistent_dir/x.img: cannot write: No such file or directory"), std::string::npos)
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
