// The step-size controller of the adaptive Dormand-Prince 5(4) sub-steps
// (substep.hpp) and of the bounce kernel (bounce.hpp): from a step's error
// norm en (relative to the tolerance; en <= 1 accepts), the next step's
// length. The error norm itself is the caller's (its own scales).
#pragma once

#include <cmath>

#include "vines/numeric/inline.hpp"

namespace vines::numeric {

// After a rejected step: 0.9 en^(-1/5), at most 10x shorter.
template <typename S>
VINES_INLINE S shrink_factor(S en) {
  return std::fmax(S(0.1), S(0.9) * std::pow(std::fmax(en, S(1e-10)), S(-0.2)));
}

// After an accepted step, elementary control: 0.9 en^(-1/5) within [0.2, 5].
template <typename S>
VINES_INLINE S grow_factor(S en) {
  return std::fmin(S(5), std::fmax(S(0.2), S(0.9) * std::pow(std::fmax(en, S(1e-10)), S(-0.2))));
}

// PI control (Gustafsson; Hairer's DOPRI5 constants) with the error of the
// last accepted step carried, and no growth right after a rejection.
template <typename S>
struct PiControl {
  S ln_en_old = std::log(S(1e-4));
  bool rejected_last = false;

  static bool accepts(S en) { return en <= S(1); }

  // The next length after a rejected step of length h.
  S rejected(S h, S en) {
    rejected_last = true;
    return h * shrink_factor(en);
  }

  // The next length after an accepted step of length h.
  S accepted(S h, S en) {
    const S ln_en = std::log(std::fmax(en, S(1e-4)));
    S fac = S(0.9) * std::exp(S(-0.17) * ln_en + S(0.04) * ln_en_old);
    fac = std::fmin(rejected_last ? S(1) : S(5), std::fmax(S(0.2), fac));
    ln_en_old = ln_en;
    rejected_last = false;
    return h * fac;
  }
};

}  // namespace vines::numeric
