// bireg: the kernels of local regression (statistics/smoothing/local_geodesic.hpp)
// and their supports.
#pragma once

#include <cmath>

namespace bireg {

enum class Kernel {
  // exp(-u^2 / 2), truncated at |u| = 4: the omitted mass is
  // erfc(4 / sqrt 2) = 6.3e-5 of the whole, and no weight inside the window
  // is below exp(-8) = 3.4e-4 of the largest.
  gaussian,
  epanechnikov,  // 1 - u^2 on |u| < 1
  tricube,       // (1 - |u|^3)^3 on |u| < 1
};

inline const char* to_string(Kernel kernel) {
  switch (kernel) {
    case Kernel::gaussian:
      return "gaussian";
    case Kernel::epanechnikov:
      return "epanechnikov";
    case Kernel::tricube:
      return "tricube";
  }
  return "unknown";
}

// Half-width of the kernel's support, in bandwidths.
inline double kernel_support(Kernel kernel) {
  return kernel == Kernel::gaussian ? 4.0 : 1.0;
}

// K(u), zero outside the support.
template <class Scalar>
Scalar kernel_weight(Kernel kernel, Scalar u) {
  using std::abs;
  using std::exp;
  const Scalar magnitude = abs(u);
  if (!(magnitude < Scalar(kernel_support(kernel)))) return Scalar(0);
  switch (kernel) {
    case Kernel::gaussian:
      return exp(-u * u / Scalar(2));
    case Kernel::epanechnikov:
      return Scalar(1) - u * u;
    case Kernel::tricube: {
      const Scalar inner = Scalar(1) - magnitude * magnitude * magnitude;
      return inner * inner * inner;
    }
  }
  return Scalar(0);
}

}  // namespace bireg
