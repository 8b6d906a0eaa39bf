// The model builders' heavy double-precision parts: the frame and its modes,
// the exact step and its quadratic integrals, the Lyapunov split, the forms
// (lti.hpp, frame.hpp). Every engine unit of a story count and scalar would
// compile the same ones again (about three quarters of such a unit's compile
// time), so CMake instantiates them once per story count and scalar
// (builders.cpp.in: EXT empty) and each engine unit declares them extern
// (instance.cpp.in, stress_instances.cpp.in: EXT extern).
#pragma once

#include "vines/build/build_model.hpp"

// S-independent: the frame and its modes.
#define VINES_FRAME_BUILDERS(EXT, N)                                                      \
  EXT template ::vines::Frame<N> vines::build_frame<N>(const ::vines::FrameParams&); \
  EXT template ::vines::Modal<N> vines::modal_analysis<N>(const ::vines::Frame<N>&);

// The modal form (no device, VI NES) in scalar S.
#define VINES_MODAL_BUILDERS_P(EXT, S, P)                                                                  \
  EXT template ::vines::ModalLti<S, P> vines::discretise_modal<S, P>(const ::vines::LtiSpec<2 * (P)>&,   \
                                                                       double);                           \
  EXT template ::vines::ModalQuad<S, P> vines::quad_integral_modal<S, P>(                                \
      const ::vines::LtiSpec<2 * (P)>&, const Eigen::Matrix<double, 2 * (P) + 1, 2 * (P) + 1>&, double); \
  EXT template bool vines::lyapunov_split<S, P>(const ::vines::LtiSpec<2 * (P)>&,                         \
                                                const Eigen::Matrix<double, 2 * (P) + 1, 2 * (P) + 1>&,   \
                                                double, ::vines::ModalRows<S, P>*, ::vines::ModalForm<S, P>*); \
  EXT template ::vines::ModalForm<S, P> vines::form_modal<S, P>(                                         \
      const Eigen::Matrix<double, 2 * (P) + 1, 2 * (P) + 1>&);
#define VINES_MODAL_BUILDERS(EXT, S, N) \
  VINES_MODAL_BUILDERS_P(EXT, S, (::vines::Layout<::vines::NoDevice, N>::kP))

// The dense form (TMD, 2N + 2 states) in scalar S.
#define VINES_DENSE_BUILDERS_NX(EXT, S, NX)                                                                  \
  EXT template ::vines::DenseLti<S, NX> vines::discretise_dense<S, NX>(const ::vines::LtiSpec<NX>&, double); \
  EXT template ::vines::DenseQuad<S, NX> vines::quad_integral_dense<S, NX>(                                \
      const ::vines::LtiSpec<NX>&, const Eigen::Matrix<double, (NX) + 1, (NX) + 1>&, double);              \
  EXT template ::vines::DenseForm<S, NX> vines::form_dense<S, NX>(const Eigen::Matrix<double, (NX) + 1, (NX) + 1>&);
#define VINES_DENSE_BUILDERS(EXT, S, N) VINES_DENSE_BUILDERS_NX(EXT, S, (::vines::Layout<::vines::TmdDevice, N>::kNx))
