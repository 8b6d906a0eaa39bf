// Polynomial extrapolation of a uniformly sampled signal: the Lagrange
// polynomial through the last p+1 samples (spacing h), evaluated tau past the
// newest. The shake-table mode uses it to lead the actuator by its delay.
#pragma once

namespace vines::link {

// y[0] newest, y[1] one step older, ... y[p]; p from 0 to 3.
inline double extrapolate(const double* y, int p, double tau, double h) {
  const double s = tau / h;  // in steps past the newest sample
  double sum = 0;
  for (int i = 0; i <= p; ++i) {
    double w = 1;
    for (int j = 0; j <= p; ++j)
      if (j != i) w *= (s + j) / static_cast<double>(j - i);
    sum += w * y[i];
  }
  return sum;
}

}  // namespace vines::link
