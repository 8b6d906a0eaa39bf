// Classic Runge-Kutta step of y' = f(y) (autonomous: time, where it
// matters, is a state), for the fixed-point contact integrations
// (fixed/bounce.hpp, split/forced_contact.hpp). Each rate is multiplied by
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

// The same step from increments, for a fixed-point scalar (whose products
// cost): k(y) returns h y' (the step folded into the rates), so the stages
// take halves and the sum one division by 6, each rounded to nearest
// (div_rounded: a truncating division would bias every step the same way),
// and no weight products. The increments are small: their sum stays in range.
template <typename Vec, typename K>
Vec rk4_increments(K&& k, const Vec& y) {
  const Vec k1 = k(y);
  Vec s;
  for (int i = 0; i < y.size(); ++i) s(i) = y(i) + div_rounded(k1(i), 2);
  const Vec k2 = k(s);
  for (int i = 0; i < y.size(); ++i) s(i) = y(i) + div_rounded(k2(i), 2);
  const Vec k3 = k(s);
  for (int i = 0; i < y.size(); ++i) s(i) = y(i) + k3(i);
  const Vec k4 = k(s);
  for (int i = 0; i < y.size(); ++i) s(i) = y(i) + div_rounded(k1(i) + k2(i) + k2(i) + k3(i) + k3(i) + k4(i), 6);
  return s;
}

}  // namespace vines::numeric
