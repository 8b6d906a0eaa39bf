// Matrix exponential of a square matrix: Pade(13) with scaling and squaring
// (Higham 2005, the algorithm behind MATLAB's expm). Used only when a model is
// built, to discretise the linear part exactly; no heap with a fixed-size
// matrix (the firmware's only use; the host's twin design passes dynamic
// ones), any scalar with std::ldexp/ceil/log2 (double, long double).
#pragma once

#include <cmath>

#include <Eigen/Core>
#include <Eigen/LU>

namespace vines::numeric {

template <typename Mat>
Mat expm(const Mat& a) {
  using T = typename Mat::Scalar;
  static_assert(Mat::RowsAtCompileTime == Mat::ColsAtCompileTime, "square matrix");
  // Pade(13) coefficients and the 1-norm bound below which it is accurate.
  constexpr T b[14] = {T(64764752532480000.0), T(32382376266240000.0), T(7771770303897600.0),
                       T(1187353796428800.0),  T(129060195264000.0),   T(10559470521600.0),
                       T(670442572800.0),      T(33522128640.0),       T(1323241920.0),
                       T(40840800.0),          T(960960.0),            T(16380.0),
                       T(182.0),               T(1.0)};
  constexpr T kTheta13 = T(5.371920351148152);

  // Scale A by 2^-s so that its 1-norm is below theta13.
  const T norm1 = a.cwiseAbs().colwise().sum().maxCoeff();
  int s = 0;
  if (norm1 > kTheta13) s = static_cast<int>(std::ceil(std::log2(norm1 / kTheta13)));
  const Mat as = a * std::ldexp(T(1), -s);

  const Mat ident = Mat::Identity(a.rows(), a.cols());
  const Mat a2 = as * as, a4 = a2 * a2, a6 = a4 * a2;
  const Mat u_inner = a6 * (b[13] * a6 + b[11] * a4 + b[9] * a2) + b[7] * a6 + b[5] * a4 +
                      b[3] * a2 + b[1] * ident;
  const Mat u = as * u_inner;
  const Mat v = a6 * (b[12] * a6 + b[10] * a4 + b[8] * a2) + b[6] * a6 + b[4] * a4 +
                b[2] * a2 + b[0] * ident;
  // r = (V - U)^-1 (V + U), then square s times.
  Mat r = Eigen::PartialPivLU<Mat>(v - u).solve(v + u);
  for (int i = 0; i < s; ++i) r = r * r;
  return r;
}

}  // namespace vines::numeric
