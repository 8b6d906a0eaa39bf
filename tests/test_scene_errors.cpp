// Scene files refused: every kind of bad scene is refused with a message that
// names the key (and the line).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "sim_host/run/run.hpp"
#include "sim_host/scene/scene.hpp"
#include "sim_host/scene/table.hpp"

#include "scene_support.hpp"

namespace {

using namespace vines::scene_test;

// ---- refused scenes: each message names the key ----

TEST(SceneError, UnknownKeyAndTable) {
  expect_refused(kBase + "[vines]\nbetta = 1.3\n", {"bad.toml:7:", "vines.betta", "unknown key"});
  expect_refused(kBase + "[foo]\nx = 1\n", {"bad.toml:6:", "foo", "unknown table"});
  expect_refused("top = 1\n" + kBase, {"bad.toml:1:", "top", "unknown table"});
}

TEST(SceneError, WrongType) {
  expect_refused(kBase + "[vines]\nbeta = \"big\"\n", {"bad.toml:7:", "vines.beta", "number"});
  expect_refused(kBase + "[device.x]\n", {"device.x", "unknown key"});
  expect_refused("device = 3\n" + kBase, {"device", "table"});
  expect_refused(kBase + "[loop]\nmax_substeps_per_step = 10.0\n",
                 {"loop.max_substeps_per_step", "integer"});
  expect_refused(kBase + "[output]\ntimeseries = 1\n", {"output.timeseries", "true or false"});
  expect_refused(kBase + "[vines]\nlaw = 3\n", {"vines.law", "string"});
  expect_refused(kBase + "[frame]\nrayleigh_modes = [1, 2.5]\n",
                 {"frame.rayleigh_modes[1]", "integer"});
  expect_refused(kBase + "[frame]\nrayleigh_zeta = [0.02]\n",
                 {"frame.rayleigh_zeta", "2 elements"});
  // Type errors count in inactive tables too.
  expect_refused("[device]\nkind = \"tmd\"\n[vines]\nbeta = \"x\"\n[record]\npath = \"a\"\n",
                 {"vines.beta", "number"});
}

TEST(SceneError, NegativeMass) {
  expect_refused(R"(
[frame]
preset = "custom"
masses_kg = [1000, -5]
stiffnesses_n_per_m = [1e6, 1e6]
[record]
path = "a"
)",
                 {"bad.toml:4:", "frame.masses_kg[1]", "> 0"});
  expect_refused("[device]\nkind = \"tmd\"\nmass_kg = -3\n[record]\npath = \"a\"\n",
                 {"bad.toml:3:", "device.mass_kg", "> 0"});
  expect_refused(kBase + "[frame]\nstiffness_scale = -1\n", {"frame.stiffness_scale"});
  // One factor per story (Table 1: 10), each in (0, 10].
  expect_refused(kBase + "[frame]\nstiffness_scales = [1, 0.9]\n",
                 {"frame.stiffness_scales", "one factor per story (10)"});
  expect_refused(kBase + "[frame]\nstiffness_scales = [1, 1, 0, 1, 1, 1, 1, 1, 1, 1]\n",
                 {"frame.stiffness_scales[2]", "(0, 10]"});
}

TEST(SceneError, VinesValues) {
  for (const char* beta : {"1.0", "0.9", "-2", "nan"})
    expect_refused(kBase + "[vines]\nbeta = " + beta + "\n", {"bad.toml:7:", "vines.beta", "> 1"});
  for (const char* eps : {"0", "0.0", "1.5", "-0.1"})
    expect_refused(kBase + "[vines]\neps = " + eps + "\n", {"bad.toml:7:", "vines.eps", "(0, 1]"});
  EXPECT_EQ(error_of(kBase + "[vines]\neps = 1\n"), "");  // eps = 1 is allowed
  // eps is not used by the Hertz law: any value passes there.
  EXPECT_EQ(error_of(kBase + "[vines]\nlaw = \"hertz\"\neps = 0\n"), "");
  expect_refused(kBase + "[vines]\nlaw = \"kuwabarra\"\n",
                 {"bad.toml:7:", "vines.law", "\"kuwabara\"", "kuwabarra"});
  expect_refused(kBase + "[vines]\npoisson = 0.5\n", {"vines.poisson"});
  expect_refused(kBase + "[vines]\nv_ref_mps = 0\n", {"vines.v_ref_mps"});
  // Bounded work whatever the parameters: a reference speed no impact has
  // is refused at once (1e-300 took 15 s to calibrate, tau 3e52 s).
  expect_refused(kBase + "[vines]\nv_ref_mps = 1e-300\n", {"bad.toml:7:", "vines.v_ref_mps", "[1e-4, 1000]"});
  // tau_s without bound ran for hours (1e6 s: the sphere held on the wall).
  expect_refused(kBase + "[vines]\ntau_s = 1e6\n", {"bad.toml:7:", "vines.tau_s", "(0, 1] s"});
  expect_refused(kBase + "[vines]\ntau_s = -1e-3\n", {"bad.toml:7:", "vines.tau_s", "(0, 1] s"});
  // A derived value out of range names the inputs it comes from (beta
  // 1e308: the free travel overflowed to null fields, status ok).
  expect_refused(kBase + "[vines]\nbeta = 1e308\n",
                 {"bad.toml:7:", "vines.beta", "free travel", "vines.beta 1e+308", "radius"});
}

TEST(SceneError, ZeroMeansDefaultKeys) {
  expect_refused(kBase + "[vines]\ntau_s = 0\n", {"vines.tau_s", "leave the key out"});
  expect_refused(kBase + "[vines]\nradius_m = 0.0\n", {"vines.radius_m", "leave the key out"});
  expect_refused(
      "[device]\nkind = \"tmd\"\n[tmd]\nk_n_per_m = 1e5\nc_ns_per_m = 0\n"
      "[record]\npath = \"a\"\n",
      {"tmd.c_ns_per_m", "leave the key out"});
  // c without k is refused by validate.
  expect_refused("[device]\nkind = \"tmd\"\n[tmd]\nc_ns_per_m = 10\n[record]\npath = \"a\"\n",
                 {"bad.toml:4:", "tmd.c_ns_per_m", "k_n_per_m"});
}

TEST(SceneError, Conflicts) {
  expect_refused(kBase + "[vines]\nbeta = 1.3\nbox_length_m = 3\n",
                 {"bad.toml:8:", "vines.box_length_m", "vines.beta"});
  expect_refused(kBase + "[vines]\nv_ref_mps = 0.5\ntau_s = 1e-3\n", {"vines.tau_s", "conflicts"});
  expect_refused(
      "[device]\nkind = \"vines\"\nmass_ratio = 0.05\nmass_kg = 1e4\n[record]\npath = \"a\"\n",
      {"device.mass_kg", "conflicts"});
  expect_refused(
      "[device]\nkind = \"vines\"\nmass_ratio = 0.05\n[vines]\nradius_m = 1\n"
      "[record]\npath = \"a\"\n",
      {"vines.radius_m", "device.mass_ratio"});
  expect_refused(kBase + "scale = 2\npga_g = 0.3\n", {"record.pga_g", "conflicts"});
}

TEST(SceneError, DeviceKindAndFloor) {
  expect_refused("[device]\nkind = \"nes\"\n[record]\npath = \"a\"\n",
                 {"bad.toml:2:", "device.kind", "\"vines\"", "nes"});
  expect_refused("[device]\nfloor = 3\n[record]\npath = \"a\"\n", {"device.kind", "required"});
  expect_refused(kBase.substr(0, kBase.find("[record]")) + "floor = 11\n[record]\npath = \"a\"\n",
                 {"bad.toml:4:", "device.floor"});
  expect_refused(kBase.substr(0, kBase.find("[record]")) + "floor = 0\n[record]\npath = \"a\"\n",
                 {"device.floor", "top floor"});
}

TEST(SceneError, FramePresetAndArrays) {
  expect_refused(kBase + "[frame]\npreset = \"table2\"\n",
                 {"bad.toml:7:", "frame.preset", "table2"});
  expect_refused(
      kBase + "[frame]\npreset = \"custom\"\nmasses_kg = [1, 2]\nstiffnesses_n_per_m = [1]\n",
      {"bad.toml:9:", "frame.stiffnesses_n_per_m", "2"});
  expect_refused(kBase + "[frame]\npreset = \"custom\"\nstiffnesses_n_per_m = [1]\n",
                 {"frame.masses_kg", "required"});
  expect_refused(kBase + "[frame]\npreset = \"custom\"\nmasses_kg = []\nstiffnesses_n_per_m = []\n",
                 {"frame.masses_kg", "1 to 40"});
  std::string many = "[";
  for (int i = 0; i < 41; ++i) many += "1.0, ";
  many += "]";
  expect_refused(kBase + "[frame]\npreset = \"custom\"\nmasses_kg = " + many +
                     "\nstiffnesses_n_per_m = " + many + "\n",
                 {"frame.masses_kg", "1 to 40"});
  expect_refused(kBase + "[frame]\nmasses_kg = [1.0]\n", {"frame.masses_kg", "custom"});
  expect_refused(kBase + "[frame]\ndamping = \"viscous\"\n", {"frame.damping"});
  expect_refused(kBase + "[frame]\ndamping = \"rayleigh\"\nrayleigh_modes = [2, 2]\n",
                 {"frame.rayleigh_modes", "different"});
  expect_refused(kBase + "[frame]\ndamping = \"modal\"\nmodal_zeta = 1.0\n", {"frame.modal_zeta"});
}

TEST(SceneError, HostKeys) {
  expect_refused(kBase + "[loop]\nsensor_rate_hz = 100\n[output]\nrate_hz = 200\n",
                 {"bad.toml:9:", "output.rate_hz", "sensor_rate_hz"});
  expect_refused(kBase + "[loop]\nsensor_rate_hz = 50\n", {"output.rate_hz", "default"});
  expect_refused(kBase + "[output]\nrate_hz = 300\n", {"output.rate_hz", "divide"});
  expect_refused(kBase + "[output]\nrate_hz = 0\n", {"output.rate_hz", "> 0"});
  expect_refused(kBase + "[loop]\nsensor_rate_hz = 0\n", {"loop.sensor_rate_hz"});
  expect_refused(kBase + "[loop]\nscalar = \"half\"\n", {"loop.scalar", "\"fixed\""});
  expect_refused(kBase + "[loop]\nfixed_accel_mps2 = 0\n", {"loop.fixed_accel_mps2", "(0, 1000]"});
  expect_refused(kBase + "[loop]\nfixed_amplification = 0.5\n", {"loop.fixed_amplification", "[1, 1000]"});
  expect_refused(kBase + "[loop]\nfixed_contact_speed_mps = nan\n", {"loop.fixed_contact_speed_mps", "(0, 100]"});
  expect_refused("[scene]\nname = \"\"\n" + kBase, {"bad.toml:2:", "scene.name", "empty"});
  expect_refused("[device]\nkind = \"none\"\n", {"record", "missing"});
  expect_refused("[record]\nformat = \"at2\"\n", {"record.path", "required"});
  expect_refused(kBase + "format = \"accel\"\n", {"record.dt_s", "required"});
  expect_refused(kBase + "dt_s = 0.02\n", {"record.dt_s", "accel"});
  expect_refused(kBase + "format = \"at2\"\ncolumn = 2\n", {"record.column"});
  expect_refused(kBase + "column = 0\n", {"record.column", ">= 1"});
  expect_refused(kBase + "units = \"ft/s2\"\n", {"record.units"});
  expect_refused(kBase + "scale = 0\n", {"record.scale"});
  expect_refused(kBase + "pga_g = -1\n", {"record.pga_g"});
  expect_refused(kBase + "duration_s = -1\n", {"record.duration_s"});
}

TEST(SceneError, SyntaxErrorHasLine) {
  const std::string msg = error_of("[device]\nkind = \"vines\"\nbeta = = 2\n");
  EXPECT_NE(msg.find("bad.toml:3:"), std::string::npos) << msg;
  EXPECT_NE(msg.find("syntax"), std::string::npos) << msg;
  expect_refused(kBase + "[device]\nkind = \"tmd\"\n", {"bad.toml:6:", "device"});  // defined twice
  // Found by scene_fuzz on toml++ 3.3.0 compiled with assertions and UBSan
  // (tests/fuzz/README.md): a control character where a key starts, a
  // non-ASCII character where whitespace may stand. The library the program
  // links refuses both.
  expect_refused("[\x01loop]\n" + kBase, {"bad.toml:1:2:", "syntax", "bare key"});
  expect_refused("[record]\npath = \"a\" \xc2\xa1\n", {"bad.toml:2:12:", "syntax"});
  expect_refused("\xef\xb7\xbf[record]\npath = \"a\"\n", {"bad.toml:1:1:", "syntax"});
}

TEST(SceneError, MissingFile) {
  try {
    load_scene("/nonexistent/dir/scene.toml");
    FAIL() << "no error";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/dir/scene.toml"), std::string::npos);
  }
}

}  // namespace
