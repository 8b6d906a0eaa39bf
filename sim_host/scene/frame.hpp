// The shear frame at run-time size, for host code that cannot take the story
// count as a template argument (the scene limits, the reference integrators, the
// twin's design). Same construction as the firmware's build_frame<N>
// (vines/model/frame.hpp), in double.
#pragma once

#include <vector>

#include "vines/model/params.hpp"

namespace vines::host {

struct HostFrame {
  int n = 0;
  std::vector<double> m, k;  // floor masses, story stiffnesses (damage applied)
  std::vector<double> K, C;  // n x n, row-major
  double K_at(int i, int j) const { return K[static_cast<std::size_t>(i * n + j)]; }
  double C_at(int i, int j) const { return C[static_cast<std::size_t>(i * n + j)]; }
};

// Undamped modes of (K, M), ascending: circular frequencies and effective
// modal masses (phi_j^T M 1)^2 with mass-normalised shapes.
struct HostModes {
  std::vector<double> omega, m_eff;
};

// The parameters must have passed vines::validate.
HostFrame build_host_frame(const FrameParams& p);
HostModes host_modes(const HostFrame& f);

}  // namespace vines::host
