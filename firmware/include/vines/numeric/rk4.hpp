// Classic Runge-Kutta step of y' = f(y) (autonomous: time, where it
// matters, is a state), for the fixed-point contact integrations
// (fixed/bounce.hpp, fixed/forced_contact.hpp). Each rate is multiplied by
// its weight before any sum: in Q3.28 two rates of 5 would overflow the
// range of 8 where their weighted increments are far below it.
#pragma once

namespace vines::numeric {

template <typename Vec, typename S, typename F>
Vec rk4_step(F&& f, const Vec& y, S h) {
  const S half = h / 2, sixth = h / 6, third = h / 3;
  const Vec k1 = f(y);
  const Vec k2 = f(Vec(y + k1 * half));
  const Vec k3 = f(Vec(y + k2 * half));
  const Vec k4 = f(Vec(y + k3 * h));
  return y + (k1 * sixth + k2 * third + k3 * third + k4 * sixth);
}

}  // namespace vines::numeric
