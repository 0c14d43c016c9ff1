// A complete two-parameter group for the compile-fail tests: positive 2 x 2
// diagonal matrices under multiplication (abelian, so ad = 0 and Ad = I),
// with Element and Tangent of different types. Each test defines one
// BIREG_TOY_* macro before including this header to break exactly one piece
// of the concept; toy_group_ok.cpp checks, in the normal build, that the
// unbroken group satisfies the concept, so that each test fails for its own
// reason only.
//
// Includes bireg/regression.hpp (and with it bireg/concept.hpp), so the
// regression's own static_assert is exercised too.
#pragma once

#include <cmath>

#include <Eigen/Core>

#include "bireg/regression.hpp"

struct Toy {
  using Scalar = double;
  static constexpr int dof = 2;
  static constexpr const char* name = "Toy";
  using Element = Eigen::Matrix<double, 2, 2>;
#ifdef BIREG_TOY_ROW_TANGENT
  using Tangent = Eigen::Matrix<double, 1, 2>;  // a row: the wrong shape
#else
  using Tangent = Eigen::Matrix<double, 2, 1>;
#endif
#ifdef BIREG_TOY_WIDE_ADMATRIX
  using AdMatrix = Eigen::Matrix<double, 2, 3>;
#elif !defined(BIREG_TOY_NO_ADMATRIX)
  using AdMatrix = Eigen::Matrix<double, 2, 2>;
#endif
  using Algebra = Eigen::Matrix<double, 2, 2>;

  static Element identity() {
    return Element::Identity();
  }
  static Element compose(const Element& a, const Element& b) {
    return a * b;
  }
#ifndef BIREG_TOY_NO_INVERSE
  static Element inverse(const Element& g) {
    return g.diagonal().cwiseInverse().asDiagonal();
  }
#endif
  static Element exp(const Tangent& x) {
    return Eigen::Vector2d(std::exp(x(0)), std::exp(x(1))).asDiagonal();
  }
#ifndef BIREG_TOY_NO_LOG
  static Tangent log(const Element& g) {
    Tangent x;
    x << std::log(g(0, 0)), std::log(g(1, 1));
    return x;
  }
#endif
  static Algebra hat(const Tangent& x) {
    return Eigen::Vector2d(x(0), x(1)).asDiagonal();
  }
  static Tangent vee(const Algebra& m) {
    Tangent x;
    x << m(0, 0), m(1, 1);
    return x;
  }
#if !defined(BIREG_TOY_NO_ADMATRIX) && !defined(BIREG_TOY_WIDE_ADMATRIX)
  static AdMatrix ad(const Tangent&) {
    return AdMatrix::Zero();
  }
#ifndef BIREG_TOY_NO_AD_OF_ELEMENT
  static AdMatrix Ad(const Element&) {
    return AdMatrix::Identity();
  }
#endif
#endif
#ifndef BIREG_TOY_NO_IS_ELEMENT
  static bool is_element(const Element& g, Scalar tol) {
    return g.allFinite() && std::abs(g(0, 1)) <= tol && std::abs(g(1, 0)) <= tol && g(0, 0) > 0 &&
           g(1, 1) > 0;
  }
#endif
};
