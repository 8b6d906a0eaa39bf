// `vines stress`: running a drawn case, its checks, and the summary of many.
#include "sim_host/studies/stress.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>

#include "host/record.hpp"
#include "sim_host/engines/build_engine.hpp"
#include "sim_host/run/drive.hpp"
#include "sim_host/run/status.hpp"
#include "sim_host/scene/limits.hpp"
#include "sim_host/studies/parallel.hpp"

namespace vines::host {
namespace {

using nlohmann::json;

// Time after the first contact over which the halved step is compared [s].
constexpr double kCompareAfterContact = 0.1;

// One pass of the loop over the samples, with what the checks need from
// every step.
struct Pass {
  RunTotals totals;
  Snapshot last;          // at the end of the pass
  bool finite = true;     // every probe finite
  std::int64_t steps = 0;
  std::int64_t first_event = -1;   // step that held the first contact start or impact
  std::int64_t compare_step = 0;   // step the halved run is compared at
  double peak_at_compare = 0;      // running peak of the top floor then
  Snapshot at_compare;
  double energy_available = 0;     // initial energy + largest input work + largest change in a step
  double residual = 0;             // energy balance residual relative to the energy in play
  double free_overlap = 0;         // deepest overlap at a sample with no contact under way
};

// Runs `eng` over a[0..] for at most `stop` steps (-1: all). The compare step
// is `compare` if given, else shortly after the first contact (the end if none).
Pass run_pass(Engine& eng, const std::vector<double>& a, std::int64_t stop, std::int64_t compare, double rate_hz) {
  Pass p;
  const std::int64_t last = static_cast<std::int64_t>(a.size()) - 1;
  const std::int64_t end = stop >= 0 ? std::min(stop, last) : last;
  p.compare_step = compare >= 0 ? std::min(compare, end) : end;
  // The ledger counts the energy stored at t = 0 as put in (ledger.initial):
  // the balance is E0 + input = stored + dissipated.
  double initial = 0, residual0 = 0;
  double input_max = 0, input_prev = 0, input_jump = 0, worst_residual = 0, scale = 0;
  hal::RecordSource src(a.data(), static_cast<std::size_t>(end) + 1, rate_hz);
  drive(eng, src, 1, [&](std::size_t step) {
    const auto k = static_cast<std::int64_t>(step);
    const Probe pr = eng.probe();
    if (k == 0) {
      initial = scale = pr.ledger.initial;
      residual0 = pr.ledger.residual;
      return;
    }
    p.finite &= std::isfinite(pr.ledger.input) && std::isfinite(pr.ledger.residual) && std::isfinite(pr.peak_top) &&
                std::isfinite(pr.overlap);
    input_max = std::max(input_max, pr.ledger.input);
    input_jump = std::max(input_jump, std::fabs(pr.ledger.input - input_prev));
    input_prev = pr.ledger.input;
    worst_residual = std::max(worst_residual, std::fabs(pr.ledger.residual - residual0));
    scale = std::max({scale, initial + pr.ledger.input, pr.ledger.max_input});
    const auto mode = static_cast<Mode>(pr.mode);
    if (mode != Mode::kContactLeft && mode != Mode::kContactRight) p.free_overlap = std::max(p.free_overlap, pr.overlap);
    if (p.first_event < 0 && pr.count.events > 0) {
      p.first_event = k;
      if (compare < 0) p.compare_step = std::min(end, k + static_cast<std::int64_t>(std::ceil(kCompareAfterContact * rate_hz)));
    }
    if (k == p.compare_step) {
      p.peak_at_compare = pr.peak_top;
      p.at_compare = eng.snapshot();
    }
  });
  p.steps = end;
  p.totals = eng.totals();
  p.last = eng.snapshot();
  p.energy_available = initial + input_max + 2.0 * input_jump;
  p.residual = scale > 0 ? worst_residual / scale : 0.0;
  return p;
}

// The same piecewise-linear ground motion sampled twice as fast.
std::vector<double> midpoints(const std::vector<double>& a) {
  std::vector<double> out(2 * a.size() - 1);
  for (std::size_t k = 0; k < a.size(); ++k) {
    out[2 * k] = a[k];
    if (k + 1 < a.size()) out[2 * k + 1] = 0.5 * (a[k] + a[k + 1]);
  }
  return out;
}

// Non-finite outputs of a pass.
int count_nonfinite(const Pass& p, int n) {
  int bad = !p.finite;
  const RunTotals& t = p.totals;
  for (int i = 0; i < n; ++i) bad += !std::isfinite(t.peak_x[i]) + !std::isfinite(t.peak_drift[i]) +
                                     !std::isfinite(p.last.x[i]) + !std::isfinite(p.last.v[i]) +
                                     !std::isfinite(p.last.acc[i]);
  for (double v : {t.peak_top, t.elastic_energy, t.strain_increments, t.max_overlap, t.ledger.input,
                   t.ledger.residual, p.last.particle_x, p.last.particle_v, p.last.contact_force})
    bad += !std::isfinite(v);
  return bad;
}

// The engine of a case's parameters, built; nullptr and the reason if refused.
std::unique_ptr<Engine> build(const SceneParams& p, Scalar scalar, std::string* refusal) {
  try {
    return build_engine(p, scalar, "stress case");
  } catch (const EngineError& e) {
    *refusal = e.reason();
    return nullptr;
  }
}

// ---- bounds (measured over seeds 1-3, 6000 cases; see docs/speed.md, "vines stress") ----

// Energy balance residual, relative to the energy in play. The bare frame is
// exact (rounding only); contacts are integrated to contact_rtol per sub-step,
// and errors add up over the contacts of a run (Hertz, elastic, chatters
// most); float rounds every step at ~1e-7.
double energy_bound(const StressCase& c) {
  if (c.scalar == Scalar::kFloat) return 5e-3;
  if (c.params.device.kind == DeviceKind::kNone) return 1e-10;
  double bound = 0;
  with_law(c.params.device.vines.law, [&](auto law) { bound = decltype(law)::kBalanceTol; });
  return bound;
}

// Halved step, relative differences allowed: the state at the compare sample
// (top floor to its peak, particle in its box to the free travel) and the
// peak so far. The peak adds the interpolation between samples: quintic
// Hermite on exact steps, error ~ (w1 h)^6 / 46080 of the first mode (allowed
// 10x), cubic on sub-steps (1e-3 covers it and the higher modes).
struct HalfStepBounds {
  double state, peak;
};
HalfStepBounds half_step_bounds(const StressCase& c, const ModelInfo& info) {
  const double wh = 2 * M_PI * info.frequency_hz[0] * info.sensor_period;
  const double interpolation = std::pow(wh, 6) / 4608.0;
  if (c.scalar == Scalar::kFloat) return {1e-2, 1e-2 + interpolation};
  return {c.params.device.kind == DeviceKind::kNone ? 1e-9 : 1e-5, 1e-3 + interpolation};
}

// Overlap: the contact cannot store more than the energy put in,
// (2/5) C d^{5/2} <= E, nor reach past the radius; with no contact under way
// the particle may sit beyond a wall by rounding only: 1024 eps of the box and
// of how far the floor went (the firmware's event tolerance is 64 eps of the
// box, an impact is placed within two of them, and a particle riding a wall
// gathers the rounding of its sub-steps: up to ~550 eps seen).
void check_overlap(const StressCase& c, const ModelInfo& info, const Pass& full, StressResult* r) {
  const VinesDesign& d = info.vines;
  const double possible = std::min(d.radius, std::pow(2.5 * full.energy_available / d.c, 0.4));
  const double eps = c.scalar == Scalar::kFloat ? std::numeric_limits<float>::epsilon()
                                                : std::numeric_limits<double>::epsilon();
  const double floor_peak = full.totals.peak_x[static_cast<std::size_t>(info.device_floor - 1)];
  const double rounding = 1024.0 * eps * (2.0 * d.gap + d.radius + floor_peak);
  const double deepest = full.totals.max_overlap;
  r->checks[kOverlap] = {true, std::max(deepest / possible, full.free_overlap / rounding), 1.0};
  r->detail.update({{"max_overlap_m", deepest}, {"possible_overlap_m", possible},
                    {"free_overlap_m", full.free_overlap}, {"rounding_m", rounding},
                    {"energy_available_J", full.energy_available}, {"radius_m", d.radius}, {"gap_m", d.gap}});
}

// Halved step on the same piecewise-linear input, compared at the sample
// shortly after the first contact (the end if none): later, after many
// impacts, the VI NES is chaotic (docs/model.md section 12) and nothing is comparable.
void check_half_step(const StressCase& c, const SceneParams& p, const ModelInfo& info, const std::vector<double>& a,
                     const Pass& full, StressResult* r) {
  SceneParams half = p;
  half.loop.sensor_rate_hz *= 2;
  std::string refusal;
  std::unique_ptr<Engine> eng = build(half, c.scalar, &refusal);
  if (!eng) throw std::logic_error("halved step refused: " + refusal);  // any rate up to 1 MHz passes
  const Pass h2 = run_pass(*eng, midpoints(a), 2 * full.compare_step, 2 * full.compare_step, half.loop.sensor_rate_hz);
  const int top = p.frame.stories - 1, f = info.device_floor - 1;
  const Snapshot &s1 = full.at_compare, &s2 = h2.at_compare;
  const double peak = std::max(full.peak_at_compare, h2.peak_at_compare);
  const double d_peak = std::fabs(full.peak_at_compare - h2.peak_at_compare) / peak;
  double d_state = std::fabs(s1.x[top] - s2.x[top]) / peak;
  if (p.device.kind == DeviceKind::kVines)
    d_state = std::max(d_state, std::fabs((s1.particle_x - s1.x[f]) - (s2.particle_x - s2.x[f])) / (2 * info.vines.gap));
  // In double the first contact falls in the same sensor interval (step k is
  // steps 2k-1 and 2k at half the step); float may flip a grazing one.
  const std::int64_t first2 = h2.first_event < 0 ? -1 : (h2.first_event + 1) / 2;
  const bool same_first = c.scalar == Scalar::kFloat || first2 == full.first_event;
  const HalfStepBounds b = half_step_bounds(c, info);
  const double worst = std::max({d_state / b.state, d_peak / b.peak, same_first ? 0.0 : 2.0});
  r->checks[kConvergence] = {true, std::isfinite(worst) ? worst : INFINITY, 1.0};
  r->detail["half_step"] = {{"compare_step", full.compare_step}, {"state", d_state}, {"peak", d_peak},
                            {"first_event_step", {full.first_event, h2.first_event}}};
}

// A tiny sub-step cap: every step that reaches it must be counted as a cap
// hit (and none may go past it), and the outputs stay finite.
void check_small_cap(const StressCase& c, const SceneParams& p, const std::vector<double>& a, StressResult* r) {
  SceneParams small = p;
  small.loop.max_substeps_per_step = c.small_cap;
  std::string refusal;
  std::unique_ptr<Engine> eng = build(small, c.scalar, &refusal);
  if (!eng) throw std::logic_error("small cap refused: " + refusal);  // any cap >= 1 passes
  const Pass sp = run_pass(*eng, a, -1, -1, small.loop.sensor_rate_hz);
  const Counters& k = sp.totals.count;
  const bool silent = (k.max_substeps_in_step >= c.small_cap) != (k.cap_hits > 0);
  const bool beyond = k.max_substeps_in_step > c.small_cap;
  r->checks[kSmallCap] = {true, static_cast<double>(silent + beyond + count_nonfinite(sp, p.frame.stories)), 0.0};
  r->detail["small_cap"] = {{"cap", c.small_cap}, {"cap_hits", k.cap_hits}, {"max_substeps_in_a_step", k.max_substeps_in_step}};
}

}  // namespace

const char* check_name(int check) {
  static const char* const kNames[kCheckCount] = {"finite", "energy", "overlap", "guards",
                                                  "cap", "small_cap", "convergence"};
  return kNames[check];
}

bool StressResult::ok() const {
  return std::all_of(checks.begin(), checks.end(), [](const CheckResult& c) { return c.ok(); });
}

StressResult run_case(const StressCase& c, const std::vector<StressRecord>& records) {
  const auto t0 = std::chrono::steady_clock::now();
  StressResult r;
  r.done = true;
  const std::vector<double> a = case_samples(c, records);
  // Refused as a scene file would be: contact scales no run can resolve.
  if (const auto e = check_contact_scales(c.params)) {
    r.refusal = e->key + ": " + e->rule;
    return r;
  }
  std::unique_ptr<Engine> eng = build(c.params, c.scalar, &r.refusal);
  if (!eng) return r;
  const ModelInfo info = eng->info();
  const bool vines = c.params.device.kind == DeviceKind::kVines;
  const Pass full = run_pass(*eng, a, -1, -1, c.params.loop.sensor_rate_hz);
  const RunTotals& t = full.totals;
  r.steps = full.steps;
  r.contacts = t.count.contacts;
  r.cap_hits = t.count.cap_hits;
  r.detail = {{"events", t.count.events}, {"max_substeps_in_a_step", t.count.max_substeps_in_step},
              {"firmware_relative_residual", t.ledger.relative_residual()}};

  r.checks[kFinite] = {true, static_cast<double>(count_nonfinite(full, c.params.frame.stories)), 0.0};
  r.checks[kEnergy] = {true, full.residual, energy_bound(c)};
  r.checks[kGuards] = {true, static_cast<double>(t.count.divergences + t.count.bad_samples), 0.0};
  r.checks[kCap] = {vines, static_cast<double>(t.count.cap_hits), 0.0};
  if (vines) check_overlap(c, info, full, &r);
  r.degraded_reasons = run_status(t, c.params, info, c.scalar).codes();
  // The other runs keep the law's calibration (law_keep).
  SceneParams p = c.params;
  if (vines) law_keep(info.vines, &p.device.vines);
  check_half_step(c, p, info, a, full, &r);
  if (c.small_cap > 0) check_small_cap(c, p, a, &r);
  r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

StressRun run_stress(const StressOptions& opt, const std::vector<StressRecord>& records,
                     const std::atomic<bool>* stop) {
  StressRun run;
  const auto n = static_cast<std::size_t>(opt.count);
  run.cases.resize(n);
  run.results.resize(n);
  const auto t0 = std::chrono::steady_clock::now();
  // Case k is drawn from (seed, k) alone and stored at k.
  const MapOptions map{opt.threads, stop, opt.progress, "stress", "cases"};
  parallel_map(n, map, [&](std::size_t k) {
    run.cases[k] = draw_case(opt.seed, static_cast<std::int64_t>(k), records, opt.limits);
    run.results[k] = run_case(run.cases[k], records);
  });
  run.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return run;
}

json case_report(const StressCase& c, const StressResult& r, const std::vector<StressRecord>& records) {
  json checks = json::object();
  for (int i = 0; i < kCheckCount; ++i) {
    const CheckResult& k = r.checks[static_cast<std::size_t>(i)];
    if (k.applies) checks[check_name(i)] = {{"value", k.value}, {"bound", k.bound}, {"ok", k.ok()}};
  }
  json j = {{"scene", case_json(c, records)}, {"ok", r.ok()}, {"steps", r.steps}, {"contacts", r.contacts},
            {"cap_hits", r.cap_hits}, {"wall_time_s", r.wall_s}, {"checks", checks}, {"detail", r.detail}};
  if (!r.refusal.empty()) j["refused"] = r.refusal;
  else j.update({{"status", r.degraded_reasons.empty() ? "ok" : "degraded"}, {"degraded_reasons", r.degraded_reasons}});
  return j;
}

StressSummary stress_summary(const StressOptions& opt, const StressRun& run, int worst) {
  StressSummary s;
  s.seed = opt.seed;
  s.requested = opt.count;
  s.max_steps_per_run = opt.limits.max_steps;
  s.wall_s = run.wall_s;
  // Totals, and refusals by reason (in order of reason).
  std::map<std::string, RefusalSummary> refusals;
  for (std::size_t i = 0; i < run.results.size(); ++i) {
    const StressResult& r = run.results[i];
    if (!r.done) continue;
    ++s.cases;
    s.steps += r.steps;
    s.failed += !r.ok();
    s.degraded += !r.degraded_reasons.empty();
    if (r.refusal.empty()) continue;
    ++s.refused;
    ++refusals.try_emplace(r.refusal, RefusalSummary{r.refusal, 0, static_cast<std::int64_t>(i)}).first->second.cases;
  }
  for (auto& [reason, r] : refusals) s.refusals.push_back(r);
  s.passed = s.failed == 0 && s.cases == run.results.size();
  for (int c = 0; c < kCheckCount; ++c) {
    CheckSummary& sum = s.checks[static_cast<std::size_t>(c)];
    std::vector<std::size_t> idx;
    for (std::size_t i = 0; i < run.results.size(); ++i) {
      const CheckResult& k = run.results[i].checks[static_cast<std::size_t>(c)];
      if (!k.applies) continue;
      idx.push_back(i);
      sum.failed += !k.ok();
    }
    sum.runs = idx.size();
    // Worst first (cases at zero are not listed); ties by case index, so the
    // table does not depend on threads.
    auto ratio = [&](std::size_t i) { return run.results[i].checks[static_cast<std::size_t>(c)].ratio(); };
    std::stable_sort(idx.begin(), idx.end(), [&](std::size_t x, std::size_t y) { return ratio(x) > ratio(y); });
    for (std::size_t w = 0; w < idx.size() && static_cast<int>(w) < worst; ++w) {
      const CheckResult& k = run.results[idx[w]].checks[static_cast<std::size_t>(c)];
      if (k.value == 0) break;
      sum.worst.push_back({idx[w], k.value, k.bound, k.ok(), ""});
    }
  }
  return s;
}

json StressSummary::to_json(const StressRun& run, const std::vector<StressRecord>& records) const {
  json jc = json::object();
  for (int c = 0; c < kCheckCount; ++c) {
    const CheckSummary& sum = checks[static_cast<std::size_t>(c)];
    json list = json::array();
    for (const WorstCase& w : sum.worst) {
      json jw = {{"value", w.value}, {"bound", w.bound}, {"ok", w.ok}, {"scene", case_json(run.cases[w.index], records)}};
      if (!w.scene_file.empty()) jw["scene_file"] = w.scene_file;
      list.push_back(jw);
    }
    jc[check_name(c)] = {{"runs", sum.runs}, {"failed", sum.failed}, {"worst", list}};
  }
  json ref = json::array();
  for (const RefusalSummary& r : refusals)
    ref.push_back({{"reason", r.reason}, {"cases", r.cases}, {"first_case", r.first_case}});
  return {{"seed", seed},       {"cases", cases},        {"requested", requested}, {"refused", refused},
          {"failed", failed},   {"passed", passed},      {"steps", steps},         {"max_steps_per_run", max_steps_per_run},
          {"wall_time_s", wall_s}, {"cases_per_s", cases_per_s()}, {"refusals", ref}, {"checks", jc},
          {"degraded", degraded}};
}

}  // namespace vines::host
