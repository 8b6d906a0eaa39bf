// Independent integrations of a scene, to check the firmware loop against:
//  - kReference: adaptive DOP853 in long double, step ends at every sample
//    (a_g has a kink there), events located to long-double rounding by
//    re-stepping (Illinois), the peak of |x_top| at the located zeros of the
//    top-floor velocity;
//  - kDop853: the `dop853` baseline of `vines bench`, DOP853 in double as a
//    competitor would write it: a fixed-size state on the stack, FSAL, the
//    step size carried across samples, events and the peak found on the
//    7th-order dense output, the step re-taken once to each event
//    (dop853_tuned.cpp);
//  - kDop853Driver: the reference's own driver in double (the `dop853-driver`
//    baseline: events located by re-taking the step);
//  - kCvodeAdams, kCvodeBdf: SUNDIALS CVODE on the same ODE in double, Adams
//    with fixed-point iteration (order at most 5) or BDF with Newton and a
//    dense solver, roots for the events, re-initialised at every mode
//    switch, stopping at every sample.
// Same model as the firmware (the device is designed by the firmware's design
// functions), integrated in physical coordinates by other code.
#pragma once

#include <stdexcept>
#include <vector>

#include "vines/model/params.hpp"

namespace vines::host::reference {

enum class Method { kReference, kDop853, kDop853Driver, kCvodeAdams, kCvodeBdf };

struct Options {
  double rtol = 0;        // 0: method default (reference 1e-15, DOP853 and CVODE 1e-8)
  double duration_s = 0;  // 0: all samples
};

struct Result {
  double peak_top = 0, t_peak_top = 0;  // max |x_top| over the run [m], and when [s]
  double elastic_energy = 0;            // E_e [J s]
  int contacts = 0;                     // contacts (or impacts) deeper than the counting depth
  std::vector<double> contact_start_s;
  double max_overlap = 0;  // [m]
  long long steps = 0, rejected = 0, rhs_evals = 0, events = 0;
  double wall_s = 0;
};

// samples: ground acceleration [m/s^2] at sample_rate_hz, linear between samples.
// Throws std::runtime_error naming the problem on bad input (e.g. invalid params: use vines::validate).
Result integrate(const SceneParams& p, const std::vector<double>& samples, double sample_rate_hz, Method m,
                 const Options& o);

const char* method_name(Method m);

// Empty when this build has the CVODE baseline; else why not and how to get
// it (integrate() throws it for the CVODE methods).
const char* cvode_missing();

}  // namespace vines::host::reference
