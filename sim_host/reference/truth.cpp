#include "sim_host/reference/truth.hpp"

#include <chrono>
#include <cmath>
#include <string>

#include "sim_host/reference/integrators.hpp"

namespace vines::host::reference {
namespace {

// Tolerances each method can honour: the reference well above long-double
// rounding, DOP853 in double and CVODE well above double rounding.
constexpr double kReferenceDefault = 1e-15, kReferenceMin = 1e-17;
constexpr double kDoubleDefault = 1e-8, kDoubleMin = 1e-13;
constexpr double kMaxRtol = 1e-2;

std::string num(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", x);
  return buf;
}

Ground check_ground(const std::vector<double>& samples, double rate_hz, double duration_s) {
  if (samples.size() < 2)
    throw std::runtime_error("ground samples: need at least 2, got " + std::to_string(samples.size()));
  if (!(std::isfinite(rate_hz) && rate_hz > 0.0)) throw std::runtime_error("sample rate must be > 0, got " + num(rate_hz));
  for (std::size_t k = 0; k < samples.size(); ++k)
    if (!std::isfinite(samples[k])) throw std::runtime_error("ground sample " + std::to_string(k) + " is not finite");
  if (!(std::isfinite(duration_s) && duration_s >= 0.0))
    throw std::runtime_error("duration must be >= 0 (0: all samples), got " + num(duration_s));
  Ground g;
  g.samples = &samples;
  g.rate_hz = rate_hz;
  const double full = static_cast<double>(samples.size() - 1) / rate_hz;
  g.t_end = duration_s > 0.0 ? std::fmin(duration_s, full) : full;
  // Intervals that reach t_end (the last one may be cut short).
  g.intervals = static_cast<int>(std::ceil(g.t_end * rate_hz * (1.0 - 1e-12)));
  if (g.intervals < 1) g.intervals = 1;
  return g;
}

}  // namespace

const char* method_name(Method m) {
  switch (m) {
    case Method::kReference: return "reference (DOP853, long double)";
    case Method::kDop853: return "DOP853 (double)";
    case Method::kDop853Driver: return "DOP853 reference driver (double)";
    case Method::kCvodeAdams: return "CVODE Adams (fixed point)";
    default: return "CVODE BDF (Newton, dense)";
  }
}

const char* cvode_missing() {
#ifdef VINES_HAVE_CVODE
  return "";
#else
  return "this build has no CVODE (SUNDIALS was not found when it was configured): install libsundials-dev "
         "(bash tools/setup.sh all) and reconfigure (cmake --preset release), then rebuild";
#endif
}

Result integrate(const SceneParams& p, const std::vector<double>& samples, double sample_rate_hz, Method m,
                 const Options& o) {
  const Ground g = check_ground(samples, sample_rate_hz, o.duration_s);
  const bool ref = m == Method::kReference;
  const double rtol = o.rtol > 0.0 ? o.rtol : ref ? kReferenceDefault : kDoubleDefault;
  const double lo = ref ? kReferenceMin : kDoubleMin;
  if (!(rtol >= lo && rtol <= kMaxRtol))
    throw std::runtime_error(std::string("rtol ") + num(o.rtol) + " out of range for " + method_name(m) + ": [" +
                             num(lo) + ", " + num(kMaxRtol) + "]");
  const OdeSpec spec = make_spec(p);
  const bool cvode = m == Method::kCvodeAdams || m == Method::kCvodeBdf;
  if (cvode && *cvode_missing()) throw std::runtime_error(std::string(method_name(m)) + ": " + cvode_missing());
  const auto t0 = std::chrono::steady_clock::now();
#ifdef VINES_HAVE_CVODE
  Result r = ref                          ? integrate_dop853<long double>(spec, g, rtol)
             : m == Method::kDop853       ? integrate_dop853_tuned(spec, g, rtol)
             : m == Method::kDop853Driver ? integrate_dop853<double>(spec, g, rtol)
                                          : integrate_cvode(spec, g, rtol, m == Method::kCvodeBdf);
#else
  Result r = ref                    ? integrate_dop853<long double>(spec, g, rtol)
             : m == Method::kDop853 ? integrate_dop853_tuned(spec, g, rtol)
                                    : integrate_dop853<double>(spec, g, rtol);
#endif
  r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

}  // namespace vines::host::reference
