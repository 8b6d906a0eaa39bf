#include "sim_host/hil/modes/lab.hpp"

#include <cmath>

#include "vines/model/contact_laws.hpp"

namespace vines::host {

ShakeTable::ShakeTable(const Specimen& sp, double h, const LabOptions& opt)
    : sp_(sp), mass_(sp.kind == DeviceKind::kTmd ? sp.tmd.mass : sp.vines.mass), h_(h), opt_(opt), rng_(opt.seed) {
  sub_ = static_cast<int>(std::ceil(h / 20e-6));
  const double dt = h / sub_;
  pipeline_.assign(static_cast<std::size_t>(std::llround(opt.delay_s / dt)), 0.0);
  s_ = sp.x0;
  sd_ = sp.v0;
}

double ShakeTable::force_on_mass(double s, double sd, double xt, double vt) const {
  // TMD: the spring and the dashpot between the mass and the table.
  if (sp_.kind == DeviceKind::kTmd) return -sp_.tmd.k * (s - xt) - sp_.tmd.c * (sd - vt);
  // VI NES: the law's force; none for an instantaneous law (refused by the
  // bench: a load cell sees no impulse).
  const VinesDesign& d = sp_.vines;
  auto kernel = [&](double o, double od) {
    double f = 0.0;
    with_law(sp_.law, [&](auto law) {
      using L = decltype(law);
      if constexpr (!L::kImpulsive) f = L::template kernel<double>(d)(o, od).total();
    });
    return f;
  };
  const double left = (xt - d.gap) - s, right = s - (xt + d.gap);
  if (left > 0) return kernel(left, vt - sd);
  if (right > 0) return -kernel(right, sd - vt);
  return 0.0;
}

double ShakeTable::advance(double command, double a0, double a1) {
  const double dt = h_ / sub_;
  const double w = 2 * M_PI * opt_.actuator_hz, z = opt_.actuator_zeta;
  for (int i = 0; i < sub_; ++i) {
    pipeline_.push_back(command);
    const double u = pipeline_.front();
    pipeline_.pop_front();
    // y = (x, v, s, sd); ground acceleration linear over the period.
    auto f = [&](const double* y, double t, double* dy) {
      const double ag = a0 + (a1 - a0) * t / h_;
      dy[0] = y[1];
      dy[1] = w * w * (u - y[0]) - 2 * z * w * y[1];
      dy[2] = y[3];
      dy[3] = -ag + force_on_mass(y[2], y[3], y[0], y[1]) / mass_;
    };
    const double t = i * dt, y0[4] = {x_, v_, s_, sd_};
    double k1[4], k2[4], k3[4], k4[4], y[4];
    f(y0, t, k1);
    for (int j = 0; j < 4; ++j) y[j] = y0[j] + 0.5 * dt * k1[j];
    f(y, t + 0.5 * dt, k2);
    for (int j = 0; j < 4; ++j) y[j] = y0[j] + 0.5 * dt * k2[j];
    f(y, t + 0.5 * dt, k3);
    for (int j = 0; j < 4; ++j) y[j] = y0[j] + dt * k3[j];
    f(y, t + dt, k4);
    x_ = y0[0] + dt / 6 * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0]);
    v_ = y0[1] + dt / 6 * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1]);
    s_ = y0[2] + dt / 6 * (k1[2] + 2 * k2[2] + 2 * k3[2] + k4[2]);
    sd_ = y0[3] + dt / 6 * (k1[3] + 2 * k2[3] + 2 * k3[3] + k4[3]);
  }
  force_ = force_on_mass(s_, sd_, x_, v_);
  const double measured = -force_ + opt_.force_noise_n * noise_(rng_);
  return opt_.force_lsb_n > 0 ? opt_.force_lsb_n * std::round(measured / opt_.force_lsb_n) : measured;
}

}  // namespace vines::host
