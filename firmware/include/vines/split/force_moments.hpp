// The frame's response to a contact force inside a sensor step, from the
// force's moments (issue 34: the split contact step, docs/fixed_point.md).
// Over a step of length h with the modal form z' = A z + bg a_g + bf F(t),
//   z(h) = Phi z(0) + Gam [a0, a1] + int_0^h e^{A (h - s)} bf F(s) ds,
// and e^{A (h - s)} = sum_k A^k (h - s)^k / k!, so the force's part is
//   sum_{k < K} (A^k bf) mu_k,   mu_k = int_0^h F(s) (h - s)^k / k! ds,
// with a tail of relative order (omega_max h)^K in the velocities and
// (omega_max h)^(K-1) in the positions (whose leading term is A bf mu_1):
// measured 2.5e-7 for K = 4 at 1 kHz on the paper's frame, third order in h
// (tests/core/test_force_moments.cpp). The contact integration
// accumulates the mu_k; the coefficients A^k bf come per mode from A's 2x2
// block [0 1; ak ac] and bf's velocity entry bfv.
#pragma once

#include <Eigen/Core>

#include "vines/model/lti.hpp"

namespace vines::fixed {

template <typename S, int P, int K = 4>
struct ForceMoments {
  using VecP = Eigen::Matrix<S, P, 1>;
  static constexpr int kMoments = K;
  VecP x[K], v[K];  // the position and velocity parts of A^k bf

  // z += sum_k (A^k bf) mu_k.
  void apply(Eigen::Matrix<S, 2 * P, 1>& z, const S (&mu)[K]) const {
    for (int k = 0; k < K; ++k) {
      z.template head<P>() += x[k] * mu[k];
      z.template tail<P>() += v[k] * mu[k];
    }
  }
};

// A^k bf for each mode of l, k = 0..K-1.
template <int K = 4, typename S, int P>
ForceMoments<S, P, K> force_moments(const ModalLti<S, P>& l) {
  ForceMoments<S, P, K> out;
  for (int j = 0; j < P; ++j) {
    S px = S(0), pv = l.bfv(j);  // A^0 bf = [0; bfv]
    for (int k = 0; k < K; ++k) {
      out.x[k](j) = px;
      out.v[k](j) = pv;
      const S nx = pv, nv = l.ak(j) * px + l.ac(j) * pv;  // A [px; pv]
      px = nx;
      pv = nv;
    }
  }
  return out;
}

}  // namespace vines::fixed
