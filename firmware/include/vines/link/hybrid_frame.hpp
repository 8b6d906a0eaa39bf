// The frame of a real-time hybrid simulation: the bare shear frame (no device)
// with an external force F on the top floor, measured on the shake table.
// In modal coordinates (mass-normalised shapes phi, classical damping) each
// mode obeys  q'' + 2 zeta w q' + w^2 q = -gamma a_g(t) + phi_top F(t);
// a_g and F are both taken linear over a step (first-order hold, like the core
// loop's ground acceleration), so every mode is stepped exactly by a 2x2
// transition and two input columns (lti.hpp's first-order-hold step).
//
// The node builds nothing: the host discretises the modes and sends them as
// the hybrid frame image (below) in the configuration's model-image part, as
// it sends a core model image in the other modes. No heap; n <= kMaxStories.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "vines/bytes/wire.hpp"
#include "vines/model/params.hpp"

namespace vines::link {

// Modal data of a frame: modes j, floors i (bottom first).
struct ModalData {
  int n = 0;
  double omega[kMaxStories] = {}, zeta[kMaxStories] = {}, gamma[kMaxStories] = {};
  double phi[kMaxStories][kMaxStories] = {};  // phi[i][j]: floor i in mode j
};

// A mode's exact first-order-hold step: (q, q')_{k+1} = a (q, q')_k + g0 u_k
// + g1 u_{k+1}, u the modal input.
struct ModeStep {
  double a[2][2] = {}, g0[2] = {}, g1[2] = {};
};

// The hybrid frame image, little-endian (wire.hpp), docs/link_protocol.md:
//   "VNHF", u16 version, u16 n, f64 h [s],
//   per mode j: f64 omega, zeta, gamma, a00, a01, a10, a11, g0[0], g0[1], g1[0], g1[1],
//   f64 phi[i][j] for each floor i, mode j (floor-major).
inline constexpr std::uint8_t kHybridMagic[4] = {'V', 'N', 'H', 'F'};
inline constexpr std::uint16_t kHybridVersion = 1;
inline constexpr std::size_t hybrid_image_bytes(int n) {
  return 4 + 2 + 2 + 8 + 11 * 8 * static_cast<std::size_t>(n) + 8 * static_cast<std::size_t>(n) * n;
}
inline bool is_hybrid_image(const std::uint8_t* p, std::size_t n) {
  return p != nullptr && n >= 4 && std::memcmp(p, kHybridMagic, 4) == 0;
}

// Writes the image of modes md stepped by steps[j] at period h; its length, 0
// if it does not fit cap.
inline std::size_t write_hybrid_image(const ModalData& md, const ModeStep* steps, double h, std::uint8_t* out,
                                      std::size_t cap) {
  Writer w(out, cap);
  w.bytes(kHybridMagic, 4);
  w.u16(kHybridVersion);
  w.u16(static_cast<std::uint16_t>(md.n));
  w.f64(h);
  for (int j = 0; j < md.n; ++j) {
    const ModeStep& s = steps[j];
    for (double v : {md.omega[j], md.zeta[j], md.gamma[j], s.a[0][0], s.a[0][1], s.a[1][0], s.a[1][1], s.g0[0],
                     s.g0[1], s.g1[0], s.g1[1]})
      w.f64(v);
  }
  for (int i = 0; i < md.n; ++i)
    for (int j = 0; j < md.n; ++j) w.f64(md.phi[i][j]);
  return w.ok() ? w.size() : 0;
}

template <typename S>
class HybridFrame {
 public:
  // Loads an image (checked whole: magic, version, story count up to
  // max_stories, length, finite numbers, h > 0); nullptr or the reason.
  const char* load(const std::uint8_t* p, std::size_t n, int max_stories) {
    md_ = ModalData{};
    if (!is_hybrid_image(p, n)) return "hybrid frame image: no VNHF magic";
    Reader r(p + 4, n - 4);
    if (r.u16() != kHybridVersion) return "hybrid frame image: unknown version";
    const int stories = r.u16();
    if (stories < 1 || stories > max_stories) return "hybrid frame image: more stories than this node holds";
    if (n != hybrid_image_bytes(stories)) return "hybrid frame image: length does not match its story count";
    h_ = r.f64();
    bool finite = std::isfinite(h_) && h_ > 0;
    for (int j = 0; j < stories; ++j) {
      double v[11];
      for (double& x : v) {
        x = r.f64();
        finite = finite && std::isfinite(x);
      }
      md_.omega[j] = v[0], md_.zeta[j] = v[1], md_.gamma[j] = v[2];
      a_[j][0][0] = static_cast<S>(v[3]), a_[j][0][1] = static_cast<S>(v[4]);
      a_[j][1][0] = static_cast<S>(v[5]), a_[j][1][1] = static_cast<S>(v[6]);
      g0_[j][0] = static_cast<S>(v[7]), g0_[j][1] = static_cast<S>(v[8]);
      g1_[j][0] = static_cast<S>(v[9]), g1_[j][1] = static_cast<S>(v[10]);
    }
    for (int i = 0; i < stories; ++i)
      for (int j = 0; j < stories; ++j) {
        md_.phi[i][j] = r.f64();
        finite = finite && std::isfinite(md_.phi[i][j]);
      }
    if (!r.done()) return "hybrid frame image: malformed";
    if (!finite) return "hybrid frame image: a number is not finite (or h <= 0)";
    md_.n = stories;
    return nullptr;
  }

  void init(double a0, double f0) {
    for (int j = 0; j < md_.n; ++j) q_[j] = qd_[j] = S(0);
    u_prev_a_ = a0;
    u_prev_f_ = f0;
    elastic_energy_ = 0;
    strain_ = 0;
  }

  void step(double a1, double f1) {
    const int n = md_.n, top = n - 1;
    for (int j = 0; j < n; ++j) {
      const S u0 = static_cast<S>(-md_.gamma[j] * u_prev_a_ + md_.phi[top][j] * u_prev_f_);
      const S u1 = static_cast<S>(-md_.gamma[j] * a1 + md_.phi[top][j] * f1);
      const S q = q_[j], qd = qd_[j];
      q_[j] = a_[j][0][0] * q + a_[j][0][1] * qd + g0_[j][0] * u0 + g1_[j][0] * u1;
      qd_[j] = a_[j][1][0] * q + a_[j][1][1] * qd + g0_[j][1] * u0 + g1_[j][1] * u1;
    }
    u_prev_a_ = a1;
    u_prev_f_ = f1;
    // E_e by the trapezoidal rule on the strain energy (1/2) sum w^2 q^2.
    double strain = 0;
    for (int j = 0; j < n; ++j) strain += 0.5 * md_.omega[j] * md_.omega[j] * static_cast<double>(q_[j] * q_[j]);
    elastic_energy_ += 0.5 * h_ * (strain + strain_);
    strain_ = strain;
  }

  // Floor displacement i [m] relative to the ground.
  double x(int i) const {
    double v = 0;
    for (int j = 0; j < md_.n; ++j) v += md_.phi[i][j] * static_cast<double>(q_[j]);
    return v;
  }
  // Absolute acceleration of floor i [m/s^2] now.
  double abs_acc(int i) const {
    double v = u_prev_a_;
    for (int j = 0; j < md_.n; ++j) {
      const double w = md_.omega[j];
      const double u = -md_.gamma[j] * u_prev_a_ + md_.phi[md_.n - 1][j] * u_prev_f_;
      v += md_.phi[i][j] * (u - 2 * md_.zeta[j] * w * static_cast<double>(qd_[j]) - w * w * static_cast<double>(q_[j]));
    }
    return v;
  }
  double elastic_energy() const { return elastic_energy_; }
  int stories() const { return md_.n; }
  double period() const { return h_; }

 private:
  ModalData md_;
  S a_[kMaxStories][2][2] = {}, g0_[kMaxStories][2] = {}, g1_[kMaxStories][2] = {};
  S q_[kMaxStories] = {}, qd_[kMaxStories] = {};
  double u_prev_a_ = 0, u_prev_f_ = 0, elastic_energy_ = 0, strain_ = 0, h_ = 0;
};

}  // namespace vines::link
