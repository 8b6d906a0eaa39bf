// The two 10-story frames of docs/model.md section 2 (Sadek et al. 1997 benchmark).
#pragma once

#include "vines/model/params.hpp"

namespace vines {

enum class FramePreset : std::uint8_t {
  kTable1,     // the paper's Table 1 (default: reproduces its results)
  kSadek1997,  // Sadek's original, k2 = 59.26 MN/m
};

// Fills masses, stiffnesses and the paper's damping rule (C = 0.0129 s * K).
inline void apply_frame_preset(FramePreset preset, FrameParams* f) {
  constexpr double kMassT[10] = {179, 170, 161, 152, 143, 134, 125, 116, 107, 98};
  constexpr double kStiffMN[10] = {62.47, 52.26, 56.14, 53.02, 49.91,
                                   46.79, 43.67, 40.55, 37.43, 34.31};
  f->stories = 10;
  for (int i = 0; i < 10; ++i) {
    f->mass_kg[i] = kMassT[i] * 1e3;
    f->stiffness_n_per_m[i] = kStiffMN[i] * 1e6;
  }
  if (preset == FramePreset::kSadek1997) f->stiffness_n_per_m[1] = 59.26e6;
  f->damping = DampingRule::kStiffnessProportional;
  f->stiffness_damping_s = 0.0129;
}

}  // namespace vines
