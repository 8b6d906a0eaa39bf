// run_hil: the bench from its options to its report, step by step; each step
// lives in the file named for it (hil_bench, hil_offline, hil_modes,
// hil_faults, hil_stream, hil_score, hil_report).
#include "sim_host/hil/hil.hpp"

#include <memory>

#include "sim_host/hil/bench.hpp"
#include "sim_host/hil/faults.hpp"
#include "sim_host/hil/link/stream.hpp"
#include "sim_host/hil/modes/modes.hpp"
#include "sim_host/hil/offline.hpp"
#include "sim_host/hil/record.hpp"
#include "sim_host/hil/score.hpp"

namespace vines::host {

HilReport run_hil(const Scene& scene, const HilOptions& opt, HilWatch* watch) {
  // The options checked against the scene; the node, the record, the node's
  // configuration and model image.
  const Bench b = make_bench(scene, opt);
  // What the node's telemetry is compared with: the offline run of the scene
  // (hybrid: the pure simulation, the device in the model).
  // (twin estimator: the estimator on the same measurements).
  link::NodeConfig offline_cfg = b.cfg;
  const bool estimator = b.cfg.estimator != link::TwinEstimator::kNone;
  if (!estimator) offline_cfg.mode = link::NodeMode::kReplay;
  const TwinInputs twin = estimator ? TwinInputs{&b.image, &b.twin.y} : TwinInputs{};
  const std::vector<link::Telemetry> offline = offline_run(offline_cfg, b.ex.samples, b.scene.path, {}, twin);
  // The mode's inputs (twin: the measured building; hybrid: the lab).
  const std::unique_ptr<BenchMode> mode = make_mode(b, offline);
  // Which faults hit which samples, drawn from the seed.
  std::vector<FaultEvent> events = plan_faults(b.opt, b.samples);
  // The run; what a node that restarted should have given: the clean run of
  // each of its lives, from rest at its restart (the offline run if none).
  if (watch) watch->start(b);
  const HilRecord rec = stream(b, *mode, &events, watch);
  std::vector<long long> restarts;
  for (const FaultEvent& e : events)
    if (e.kind == FaultKind::kRestart) restarts.push_back(e.k);
  const std::vector<link::Telemetry> lives = restarts.empty()
                                                 ? std::vector<link::Telemetry>{}
                                                 : offline_run(offline_cfg, b.ex.samples, b.scene.path, restarts, twin);
  // Its score, the mode's results and the CSV.
  HilReport report = score(b, rec, offline, restarts.empty() ? offline : lives, &events);
  mode->report(rec, offline, &report);
  if (!b.opt.csv.empty()) {
    CsvMeta meta;
    meta.columns = write_hil_csv(b.opt.csv, rec, offline, b.scene.params.frame.stories, b.h, mode->csv_columns(rec),
                                 b.opt.floors);
    meta.mode = hil_mode_name(b.opt.mode), meta.scene = b.scene.path, meta.rate_hz = 1 / b.h;
    meta.stories = b.scene.params.frame.stories, meta.floors = b.opt.floors;
    meta.device = device_layout(b.scene);
    write_hil_csv_meta(b.opt.csv, meta);
  }
  if (watch) watch->finish(report);
  return report;
}

}  // namespace vines::host
