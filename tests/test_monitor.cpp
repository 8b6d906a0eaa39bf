// The monitoring page's parts (sim_host/monitor/): the decimator keeps the
// run's own numbers; the hub gives every client every event in order, bounds
// its clients and its history, and drops a client that falls behind;
// `vines view` reads a run's --csv back into the same frames; the device's
// panel is the device. The server: test_page_server.cpp.
#include <gtest/gtest.h>

#include <sys/stat.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "sim_host/engines/build_engine.hpp"
#include "sim_host/hil/bench.hpp"
#include "sim_host/hil/offline.hpp"
#include "sim_host/monitor/decimator.hpp"
#include "sim_host/monitor/hub.hpp"
#include "sim_host/monitor/rows.hpp"
#include "sim_host/monitor/view.hpp"

namespace vines::host::monitor {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

// An event's name and its data as JSON.
std::pair<std::string, nlohmann::json> parse_event(const std::string& e) {
  const std::size_t nl = e.find('\n');
  EXPECT_EQ(e.rfind("event: ", 0), 0u) << e;
  EXPECT_EQ(e.substr(e.size() - 2), "\n\n");
  const std::string data = e.substr(nl + 1, e.size() - nl - 3);
  EXPECT_EQ(data.rfind("data: ", 0), 0u) << e;
  return {e.substr(7, nl - 7), nlohmann::json::parse(data.substr(6))};
}

// Every 5th sample in, 3 to a frame; the values as they were, bit for bit
// (shortest round trip), NaN as null; a sample again (after a restart) or
// older than the last kept is not sent twice.
TEST(Decimator, KeepsEveryMthSampleExactly) {
  Decimator d(5, 3, 2);
  std::vector<std::string> events;
  std::string e;
  const double third = 1.0 / 3.0;
  for (long long k = 0; k < 40; ++k) {
    if (!d.keeps(k)) continue;
    const double v = k == 20 ? std::numeric_limits<double>::quiet_NaN() : third * static_cast<double>(k);
    if (d.add(k, {v, -static_cast<double>(k)}, &e)) events.push_back(e);
  }
  EXPECT_FALSE(d.keeps(35));  // kept already
  EXPECT_FALSE(d.keeps(30));
  EXPECT_TRUE(d.flush(&e));
  events.push_back(e);
  EXPECT_FALSE(d.flush(&e));
  ASSERT_EQ(events.size(), 3u);  // 8 samples kept: 3 + 3 + 2
  std::vector<long long> ks;
  for (const std::string& ev : events) {
    const auto [name, j] = parse_event(ev);
    EXPECT_EQ(name, "frame");
    for (std::size_t i = 0; i < j["k"].size(); ++i) {
      const long long k = j["k"][i];
      ks.push_back(k);
      if (k == 20) EXPECT_TRUE(j["v"][0][i].is_null());
      else EXPECT_EQ(j["v"][0][i].get<double>(), third * static_cast<double>(k));  // bit for bit
      EXPECT_EQ(j["v"][1][i].get<double>(), -static_cast<double>(k));
    }
  }
  EXPECT_EQ(ks, (std::vector<long long>{0, 5, 10, 15, 20, 25, 30, 35}));
  std::string unused;
  EXPECT_THROW(d.add(40, {1.0}, &unused), std::invalid_argument);
  EXPECT_THROW(Decimator(0, 1, 1), std::invalid_argument);
}

// Event samples (a VI NES contact) are kept off the grid too, each once.
TEST(Decimator, KeepsEventSamplesOffTheGrid) {
  Decimator d(5, 100, 1);
  std::string event;
  std::vector<long long> kept;
  for (long long k = 0; k < 20; ++k) {
    const bool contact = k >= 7 && k <= 11;
    if (d.keeps(k, contact)) {
      kept.push_back(k);
      d.add(k, {static_cast<double>(k)}, &event);
    }
  }
  EXPECT_EQ(kept, (std::vector<long long>{0, 5, 7, 8, 9, 10, 11, 15}));
  EXPECT_FALSE(d.keeps(11, true));  // again (a restart, a late sample): not twice
}

TEST(Decimator, AboutTwoHundredPointsASecond) {
  EXPECT_EQ(page_every(1000), 5);
  EXPECT_EQ(page_every(2048), 10);
  EXPECT_EQ(page_every(50), 1);
}

// Reads a client's events until the end (or behind); their texts.
std::vector<std::string> read_all(Hub& hub, long long cursor, Hub::Next* last) {
  std::vector<std::string> got;
  std::vector<Event> ev;
  for (;;) {
    const Hub::Next n = hub.next(&cursor, &ev, 2000ms);
    for (const Event& e : ev) got.push_back(*e);
    if (n == Hub::Next::kEnd || n == Hub::Next::kBehind || n == Hub::Next::kIdle) {
      *last = n;
      return got;
    }
  }
}

// A client that joined before anything (and one after the run) gets the
// header first, then every event in order, then the end.
TEST(Hub, EveryClientGetsTheHeaderThenEveryEventInOrder) {
  Hub hub;
  const std::optional<long long> early = hub.join();
  ASSERT_TRUE(early);
  std::vector<std::string> got_early;
  Hub::Next last_early{};
  std::thread reader([&] { got_early = read_all(hub, *early, &last_early); });
  hub.set_header("H");
  for (int i = 0; i < 5000; ++i) hub.publish("e" + std::to_string(i));
  hub.close();
  reader.join();
  const std::optional<long long> late = hub.join();
  ASSERT_TRUE(late);
  Hub::Next last_late{};
  std::vector<std::string> got_late = read_all(hub, *late, &last_late);
  for (const std::vector<std::string>* got : {&got_early, &got_late}) {
    ASSERT_EQ(got->size(), 5001u);
    EXPECT_EQ((*got)[0], "H");
    for (int i = 0; i < 5000; ++i) ASSERT_EQ((*got)[static_cast<std::size_t>(i) + 1], "e" + std::to_string(i));
  }
  EXPECT_EQ(last_early, Hub::Next::kEnd);
  EXPECT_EQ(last_late, Hub::Next::kEnd);
  EXPECT_EQ(hub.published(), 5000);
}

// --serve-hold: the server waits for a client that comes after the run and
// reads it to its end, and no longer than it is told when none comes.
TEST(Hub, WaitsForAClientToReadTheWholeRun) {
  Hub hub;
  hub.set_header("H");
  hub.publish("e");
  hub.close();
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_FALSE(hub.wait_until_read(100ms));  // nobody came
  EXPECT_GE(std::chrono::steady_clock::now() - t0, 100ms);
  std::thread late([&] {
    std::this_thread::sleep_for(200ms);
    const std::optional<long long> c = hub.join();
    Hub::Next last{};
    EXPECT_EQ(read_all(hub, *c, &last).size(), 2u);
    EXPECT_EQ(last, Hub::Next::kEnd);
    hub.leave();
  });
  EXPECT_TRUE(hub.wait_until_read(10000ms));
  late.join();
  EXPECT_EQ(hub.clients(), 0);
}

// At most max_clients at once; one leaving frees its place.
TEST(Hub, BoundsItsClients) {
  Hub hub(HubLimits{2, 1 << 20});
  EXPECT_TRUE(hub.join());
  EXPECT_TRUE(hub.join());
  EXPECT_FALSE(hub.join());
  hub.leave();
  EXPECT_TRUE(hub.join());
  EXPECT_EQ(hub.clients(), 2);
}

// A client that does not read falls out of the bounded history and is told
// so (its server drops it); the bench publishes on, and a client that joins
// later gets the newest history.
TEST(Hub, AClientThatFallsOutOfTheHistoryIsBehind) {
  Hub hub(HubLimits{4, 1000});
  hub.set_header("H");
  const std::optional<long long> idle = hub.join();
  for (int i = 0; i < 1000; ++i) hub.publish(std::string(100, 'x'));  // 100 kB through a 1 kB history
  long long c = *idle;
  std::vector<Event> ev;
  EXPECT_EQ(hub.next(&c, &ev, 0ms), Hub::Next::kBehind);  // the header, then behind
  EXPECT_EQ(ev.size(), 1u);
  const std::optional<long long> fresh = hub.join();
  hub.close();
  Hub::Next last{};
  EXPECT_EQ(read_all(hub, *fresh, &last).size(), 1u + 10u);  // the header and the 10 newest
  EXPECT_EQ(last, Hub::Next::kEnd);
}

// `vines view`: a run's CSV back into the page's frames, the same series and
// samples as live (every 5th at 1 kHz, received only), the hybrid tracking
// RMS computed as the bench does; a bad cell named with its row and column.
TEST(View, ReadsARunsCsvIntoTheSameFrames) {
  const auto dir = std::filesystem::temp_directory_path() / "vines_test_view";
  std::filesystem::create_directories(dir);
  const auto csv = dir / "hybrid.csv";
  {
    std::ofstream f(csv);
    f << "k,t_s,ag_sent_mps2,ag_used_mps2,received,flags,latency_us,x_top_m,x_top_offline_m,deviation_m,"
         "acc_top_mps2,Ee_Js,particle_x_m,contact_force_n,dissipated_J,aux,drift_alarms,table_x_m,force_measured_n\n";
    for (int k = 0; k < 50; ++k)
      f << k << "," << k * 0.001 << "," << 0.1 * k << ",0," << (k == 10 ? 0 : 1) << ",0,0," << 0.01 * k
        << ",0,0,0,0,0,0,0," << 0.02 * k << ",0," << 0.011 * k << "," << 3 * k << "\n";
  }
  Hub hub;
  load_run(dir.string(), &hub);  // the folder's only .csv
  const std::optional<long long> c = hub.join();
  Hub::Next last{};
  const std::vector<std::string> events = read_all(hub, *c, &last);
  const auto [name, meta] = parse_event(events.at(0));
  EXPECT_EQ(name, "meta");
  EXPECT_EQ(meta["mode"], "hybrid");
  EXPECT_EQ(meta["every"], 5);
  std::vector<std::string> series;
  for (const auto& s : meta["series"]) series.push_back(s["name"]);
  EXPECT_EQ(series, (std::vector<std::string>{"ag_sent_mps2", "x_top_m", "flags", "table_x_m", "aux",
                                              "force_measured_n", "tracking_rms_pct"}));
  std::vector<long long> ks;
  std::vector<double> ag, tracking;
  for (std::size_t i = 1; i + 1 < events.size(); ++i) {
    const auto [n, j] = parse_event(events[i]);
    for (std::size_t p = 0; p < j["k"].size(); ++p) {
      ks.push_back(j["k"][p]);
      ag.push_back(j["v"][0][p]);
      tracking.push_back(j["v"][6][p]);
    }
  }
  EXPECT_EQ(parse_event(events.back()).first, "end");
  EXPECT_EQ(ks, (std::vector<long long>{0, 5, 15, 20, 25, 30, 35, 40, 45}));  // 10 not received
  EXPECT_EQ(ag[1], 0.1 * 5);
  // The table 10 % above the top floor throughout: 10 % RMS.
  EXPECT_NEAR(tracking.back(), 10.0, 1e-9);
  {
    std::ofstream f(dir / "hybrid.csv", std::ios::app);
    f << "50,0.05,oops,0,1,0,0,0,0,0,0,0,0,0,0,0,0,0,0\n";
  }
  Hub other;
  try {
    load_run(csv.string(), &other);
    ADD_FAILURE();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("line 52, column ag_sent_mps2: 'oops'"), std::string::npos) << e.what();
  }
  EXPECT_THROW(load_run((dir / "none.csv").string(), &other), std::runtime_error);
  std::filesystem::remove_all(dir);
}

// The message load_run refuses FILE with ("" if it takes it).
std::string view_refusal(const std::filesystem::path& file) {
  Hub hub;
  try {
    load_run(file.string(), &hub);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

// `vines view` reads what the run wrote beside its CSV (FILE.json: the rate,
// the device, its floor and walls, the stories), takes CRLF lines, and
// refuses a file it cannot trust, naming the line and the column (issue 53).
TEST(View, ReadsTheRunsDescriptionAndRefusesWhatItCannotTrust) {
  const auto dir = std::filesystem::temp_directory_path() / "vines_test_view_trust";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const std::string head =
      "k,t_s,ag_sent_mps2,ag_used_mps2,received,flags,latency_us,x_top_m,x_top_offline_m,deviation_m,"
      "acc_top_mps2,Ee_Js,particle_x_m,contact_force_n,dissipated_J,aux,drift_alarms";
  // A VI NES replay at 2048 Hz with no impact yet, as `vines hil --csv` writes it (t_s to the microsecond).
  const auto write = [&](const std::string& name, const std::string& header, int rows, const std::string& eol,
                         const std::string& bad_row = "") {
    std::ofstream f(dir / name, std::ios::binary);
    f << header << eol;
    for (int k = 0; k < rows; ++k) {
      char t[32];
      std::snprintf(t, sizeof t, "%.6f", k / 2048.0);
      f << k << "," << t << ",0.1,0,1,0,0,0.01,0,0,0,0,0.001,0,0,0,0" << eol;
    }
    f << bad_row;
    return dir / name;
  };
  const auto csv = write("run.csv", head, 40, "\r\n");
  {
    std::ofstream m(dir / "run.csv.json");
    m << R"({"format": "vines hil --csv", "columns": 17, "mode": "replay", "scene": "s.toml",
            "sensor_rate_hz": 2048, "stories": 10, "device": {"kind": "vines", "floor": 10, "gap_m": 0.0135},
            "floors": []})";
  }
  Hub hub;
  load_run(csv.string(), &hub);
  const std::optional<long long> c = hub.join();
  Hub::Next last{};
  const auto [name, meta] = parse_event(read_all(hub, *c, &last).at(0));
  EXPECT_EQ(meta["rate_hz"], 2048.0);
  EXPECT_EQ(meta["stories"], 10);
  EXPECT_EQ(meta["device"]["kind"], "vines");  // no contact yet: drawn as a TMD before
  EXPECT_EQ(meta["device"]["floor_series"], "x_top_m");
  EXPECT_EQ(meta["device"]["gap_m"], 0.0135);
  // Without the description: the rate from the times' whole span (1/(t1 - t0) gave 2049.18 Hz).
  const auto bare = write("bare.csv", head, 40, "\n");
  Hub h2;
  load_run(bare.string(), &h2);
  const auto [n2, m2] = parse_event(read_all(h2, *h2.join(), &last).at(0));
  EXPECT_NEAR(m2["rate_hz"].get<double>(), 2048.0, 0.01);
  // A description of another file.
  { std::ofstream(dir / "bare.csv.json") << R"({"format": "vines hil --csv", "columns": 18})"; }
  EXPECT_NE(view_refusal(bare).find("bare.csv.json: describes a CSV of 18 columns"), std::string::npos)
      << view_refusal(bare);
  std::filesystem::remove(dir / "bare.csv.json");
  // Cells it cannot trust: each named by its line and column.
  const std::string row = "0.1,0,1,0,0,0.01,0,0,0,0,0,0,0,0,0\n";
  const std::vector<std::pair<std::string, std::string>> bad = {
      {"40,nan," + row, "line 42, column t_s: 'nan'"},
      {"40,0.001," + row, "line 42, column t_s: '0.001' is not a time after"},
      {"39,0.5," + row, "line 42, column k: '39'"},
      {"nan,0.5," + row, "line 42, column k: 'nan'"},
      {"1e300,0.5," + row, "line 42, column k: '1e300'"},
      {"-5,0.5," + row, "line 42, column k: '-5'"},
      {"40.5,0.5," + row, "line 42, column k: '40.5'"},
      {"40,0.5,0.1,0,nan,0,0,0.01,0,0,0,0,0,0,0,0,0\n", "line 42, column received: 'nan' is neither 0 nor 1"},
  };
  for (const auto& [r, want] : bad) {
    const auto f = write("bad.csv", head, 40, "\n", r);
    EXPECT_NE(view_refusal(f).find(want), std::string::npos) << r << " -> " << view_refusal(f);
  }
  EXPECT_NE(view_refusal(write("dup.csv", head + ",x_top_m", 3, "\n")).find("line 1: column 18 is 'x_top_m' again (column 8)"),
            std::string::npos);
  std::string wide = head;
  for (int i = 0; i < 5000; ++i) wide += ",x_" + std::to_string(i);
  EXPECT_NE(view_refusal(write("wide.csv", wide, 0, "\n")).find("line 1 has 5017 columns (at most 4096)"),
            std::string::npos);
  const auto fifo = dir / "fifo.csv";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_NE(view_refusal(fifo).find("not a regular file"), std::string::npos) << view_refusal(fifo);
  EXPECT_NE(view_refusal("/dev/zero").find("/dev/zero: not a regular file"), std::string::npos);
  std::filesystem::remove_all(dir);
}

// The device's panel. The TMD's mass the page draws (the node's telemetry,
// particle_x_m) is the TMD the engine steps, sample by sample (before, the
// node sent 0); the page's meta names the floor it sits on, and for the VI
// NES the box's free travel as the model designs it, (b/2 - R) with
// b = beta 2R.
TEST(Rows, TheDevicePanelIsTheDevice) {
  const std::string scenes = std::string(VINES_SOURCE_DIR) + "/data/scenes/";
  HilOptions opt;
  opt.duration_s = 5;
  const Bench tmd = make_bench(load_scene(scenes + "elcentro_tmd.toml"), opt);
  const std::vector<link::Telemetry> tel = offline_run(tmd.cfg, tmd.ex.samples, "tmd");
  const std::unique_ptr<Engine> eng = build_engine(tmd.scene.params, tmd.scene.scalar, "tmd");
  eng->init(tmd.ex.samples[0]);
  double peak = 0;
  for (std::size_t k = 0; k < tel.size(); ++k) {
    if (k > 0) eng->step(tmd.ex.samples[k]);
    const Snapshot s = eng->snapshot();
    ASSERT_EQ(tel[k].particle_x, s.tmd_x) << "sample " << k;
    ASSERT_EQ(tel[k].particle_v, s.tmd_v) << "sample " << k;
    peak = std::max(peak, std::fabs(s.tmd_x));
  }
  EXPECT_GT(peak, 0.05);  // the TMD moved
  const BenchRows tmd_rows(tmd);
  EXPECT_EQ(tmd_rows.meta().device, "tmd");
  EXPECT_EQ(tmd_rows.meta().device_floor_series, "x_top_m");
  EXPECT_EQ(tmd_rows.meta().series.at(2).name, "particle_x_m");
  // The fixed-point TMD node does not send its mass: not on the page.
  Scene fixed = load_scene(scenes + "elcentro_tmd_fixed.toml");
  const BenchRows fixed_rows(make_bench(fixed, opt));
  for (const Series& x : fixed_rows.meta().series) EXPECT_NE(x.name, "particle_x_m");

  const Scene vs = load_scene(scenes + "elcentro_vines.toml");
  const BenchRows vines_rows(make_bench(vs, opt));
  const VinesParams& v = vs.params.device.vines;
  const double radius = build_engine(vs.params, vs.scalar, "vines")->info().vines.radius;
  EXPECT_EQ(vines_rows.meta().device, "vines");
  EXPECT_NEAR(vines_rows.meta().gap_m, (v.beta - 1) * radius, 1e-15);
  EXPECT_GT(vines_rows.meta().gap_m, 0.0);
  // Replay, twin (its estimator gives no sphere) and hybrid, as the --csv has them.
  EXPECT_EQ(series_names("replay", device_series("replay", DeviceKind::kVines, false), {}, {"x_3_m"}),
            (std::vector<std::string>{"ag_sent_mps2", "x_top_m", "particle_x_m", "contact_force_n", "flags", "x_3_m"}));
  EXPECT_EQ(series_names("twin", device_series("twin", DeviceKind::kTmd, true), {"eta_1", "eta_tmd"}, {}),
            (std::vector<std::string>{"ag_sent_mps2", "x_top_m", "flags", "x_top_truth_m", "aux", "eta_1", "eta_tmd",
                                      "eta_sd_1", "eta_sd_tmd", "alarm_story"}));
}

}  // namespace
}  // namespace vines::host::monitor
