// `vines hil`'s report as text (--json prints host::to_json instead).
#include "sim_host/cli/hil_print.hpp"

#include <cstdio>
#include <optional>
#include <string>
#include <utility>

namespace vines::cli {
namespace {

// printf into a string.
std::string format(const char* fmt, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, fmt, v);
  return buf;
}

// The twin's part of the report as text.
void print_twin(const host::HilTwinReport& t) {
  std::printf("  twin (%s estimator), truth %s, sensors on floors", t.estimator.c_str(),
              t.truth.empty() ? "the scene itself" : t.truth.c_str());
  for (int s : t.sensors) std::printf(" %d", s);
  std::printf("\n    residual RMS %.4g m/s^2 (max %.4g), residual alarm %lld steps", t.residual_rms_mps2,
              t.residual_max_mps2, t.residual_alarm_steps);
  if (t.first_residual_alarm_s) std::printf(" from %.2f s", *t.first_residual_alarm_s);
  std::printf(", drift alarm %lld steps\n", t.drift_alarm_steps);
  if (t.estimator == "none") return;
  if (t.truth_damage_time_s) std::printf("    the truth's damage strikes at %.3f s\n", *t.truth_damage_time_s);
  if (t.detected) {
    std::printf("    DAMAGE:");
    if (!t.story_identified) std::printf(" story not identified, loss about %.1f %%", 100 * t.size.value_or(0));
    for (std::size_t i = 0; i < t.stories.size(); ++i)
      std::printf("%s story %d, loss %.1f %%", i ? "," : "", t.stories[i], 100 * t.sizes[i]);
    if (t.truth_damage_time_s)
      std::printf(" at %.2f s (%.2f s after the truth's damage)", *t.detect_time_s, *t.detect_delay_s);
    else
      std::printf(" at %.2f s (%.2f s after strong motion starts at %.2f s)", *t.detect_time_s, *t.detect_delay_s,
                  t.strong_motion_start_s);
    if (t.onset_s) std::printf("; onset %.1f s", *t.onset_s);
    std::printf("\n");
  } else {
    std::printf("    no damage detected\n");
  }
  if (!t.caveat.empty()) std::printf("    CAVEAT: %s\n", t.caveat.c_str());
  std::printf("    eta_k (sd) by story:");
  for (std::size_t i = 0; i < t.eta_k.size(); ++i) std::printf(" %.3f (%.3f)", t.eta_k[i], t.eta_k_sd[i]);
  std::printf("\n    roof displacement NRMSE %s (steady-state sd %.3g mm)\n",
              t.roof_displacement_nrmse ? format("%.4f", *t.roof_displacement_nrmse).c_str() : "n/a",
              1e3 * t.roof_displacement_sd_m);
  const host::HilTwinDevice& d = t.device;
  if (d.kind == "vines")
    std::printf("    VI NES: sphere %s; impulse |F| dt %.4g N s (truth %.4g), %lld impacts seen (truth %lld contacts), "
                "added mass %.2f x the sphere's, floor travel %.3g m (the sphere's free travel %.3g m)\n",
                d.sphere.c_str(), d.impulse_estimated_ns, d.impulse_truth_ns, d.impacts_estimated, d.contacts_truth,
                d.added_mass_ratio, d.floor_travel_m, d.free_travel_m);
  if (d.kind == "tmd")
    std::printf("    TMD: frequency %.3f (sd %.3f) x its design (truth %.3f)%s\n", d.frequency_factor,
                d.frequency_factor_sd, d.truth_frequency_factor, d.detuned ? ": DETUNED" : "");
}

// The hil report as text.
}  // namespace

void print_hil(const host::HilReport& r) {
  std::printf("hil %s: %s mode, %s clock, %s, %.0f Hz, node %s\n", r.scene.c_str(), host::hil_mode_name(r.mode),
              r.realtime ? "realtime" : "virtual", scalar_name(r.scalar), r.sensor_rate_hz, r.node.c_str());
  // The node's deadline monitor (and a board's instruction counts)
  const link::StepTiming& nd = r.node_deadline;
  std::printf("  node deadline monitor: %lld overruns of a %lld-tick budget, worst step %lld ticks (k %lld)",
              static_cast<long long>(nd.overruns), static_cast<long long>(nd.budget_ticks),
              static_cast<long long>(nd.worst_ticks), static_cast<long long>(nd.worst_k));
  if (r.board)
    std::printf("; %.0f instructions (median %.0f)", r.board->worst_step_instructions,
                r.board->median_step_instructions);
  if (nd.stack_peak_bytes > 0) std::printf("; stack %lld B", static_cast<long long>(nd.stack_peak_bytes));
  std::printf("\n");
  // Steps, deadlines and latency
  std::printf("  steps %lld of %lld, deadline misses %lld (deadline %.3g ms)", r.steps, r.samples, r.deadline_misses,
              1e3 * r.deadline_s);
  if (r.latency_us)
    std::printf(", latency mean %.0f us, p99 %.0f us, max %.0f us", r.latency_us->mean, r.latency_us->p99,
                r.latency_us->max);
  if (r.bench_service) {
    std::printf("\n  real-time service: bench %s; node %s", host::describe(*r.bench_service).c_str(),
                r.node_service ? host::describe(*r.node_service).c_str() : "elsewhere, its own (vines node --realtime-priority)");
  }
  // Faults, by kind
  std::printf("\n  faults injected %lld, detected %lld, survived %lld; node restarts %lld\n", r.faults_injected,
              r.faults_detected, r.faults_survived, r.node_restarts);
  // Each kind's verdict: its deviation from the clean run against the bound.
  for (const auto& [name, c] : r.faults) {
    std::printf("    %-10s injected %5lld  detected %5lld  %s: deviation %.3g m %s bound %.3g m", name.c_str(),
                c.injected, c.detected, c.ok ? "survived" : "NOT survived", c.deviation_m,
                c.deviation_m <= c.bound_m ? "within" : "beyond", c.bound_m);
    if (c.unanswered) std::printf(", %lld judged samples without telemetry", c.unanswered);
    std::printf("\n");
  }
  std::printf("  max deviation from offline %.3g m%s; outputs finite: %s\n", r.max_deviation_from_offline,
              r.bit_exact ? " (bit for bit equal)" : "", r.outputs_finite ? "yes" : "NO");
  // The modes
  if (r.twin) print_twin(*r.twin);
  if (r.hybrid) {
    const host::HilHybridReport& hy = *r.hybrid;
    // The compensation, then the tracking and the top floor against the pure simulation.
    if (hy.compensation == host::HilComp::kAdaptive)
      std::printf("  hybrid: adaptive compensation (window %.3g s, a1 from %.2f ms)", hy.compensation_window_s,
                  1e3 * hy.compensation_delay_s);
    else if (hy.compensation == host::HilComp::kPoly && hy.compensation_delay_s > 0)
      std::printf("  hybrid: compensation %.2f ms (order %d)", 1e3 * hy.compensation_delay_s, hy.compensation_order);
    else
      std::printf("  hybrid: no compensation");
    std::printf(": tracking RMS %.3g mm, peak %.3g mm; top floor vs pure simulation RMS %.3g mm, peak %.3g mm "
                "(peaks %.4f / %.4f m)\n",
                1e3 * hy.tracking_rms_m, 1e3 * hy.tracking_peak_m, 1e3 * hy.top_diff_from_pure_rms_m,
                1e3 * hy.top_diff_from_pure_peak_m, hy.peak_top_hybrid_m, hy.peak_top_pure_m);
    std::printf("    against the bare frame: x_r %.2f %% (pure %.2f %%), E_r %.2f %% (pure %.2f %%)\n",
                100 * hy.x_r_hybrid, 100 * hy.x_r_pure, 100 * hy.E_r_hybrid, 100 * hy.E_r_pure);
    if (hy.adaptive) {
      const host::HilAtsCoefficients& c = *hy.adaptive;
      std::printf("    adaptive coefficients at the end (range over the run): a0 %.4f (%.4f to %.4f), a1 %.3f ms "
                  "(%.3f to %.3f), a2 %.3g s^2 (%.3g to %.3g)\n",
                  c.last[0], c.min[0], c.max[0], 1e3 * c.last[1], 1e3 * c.min[1], 1e3 * c.max[1], c.last[2], c.min[2],
                  c.max[2]);
    }
    // The vRTHS benchmark's criteria (docs/rths_criteria.md); "n/a": no scale or beyond the search.
    auto pct = [](const std::optional<double>& v) { return v ? format("%.3g", *v) : std::string("n/a"); };
    std::printf("  vRTHS criteria: tracking delay %s ms, RMS %s %%, peak %s %%\n",
                hy.tracking_delay_ms ? format("%.3f", *hy.tracking_delay_ms).c_str() : "n/a",
                pct(hy.tracking_rms_pct).c_str(), pct(hy.tracking_peak_pct).c_str());
    for (const auto& [name, v] : {std::pair{"RMS", &hy.response_rms_pct}, std::pair{"peak", &hy.response_peak_pct}}) {
      std::printf("    response %-4s %% by floor (bottom first):", name);
      for (const std::optional<double>& x : *v) std::printf(" %s", pct(x).c_str());
      std::printf("\n");
    }
  }
}

}  // namespace vines::cli
