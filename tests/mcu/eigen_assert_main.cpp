// eigen_assert stays active in the release MCU images (eigen_assert.h): an
// out-of-range coefficient access must stop the run with Eigen's message.
#include <Eigen/Core>

#include "semihost.h"

int main() {
  Eigen::Matrix<float, 3, 1> v = Eigen::Matrix<float, 3, 1>::Zero();
  volatile int index = 3;  // one past the end, unknown to the compiler
  v(index) = 1.0f;
  vines_semihost_puts("vines mcu: out-of-range access not caught\n");
  return static_cast<int>(v.sum());
}
