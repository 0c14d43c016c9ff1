// bireg: the direct product G1 x G2 x ... of groups. Product<G1, G2, G3>
// is Product<G1, Product<G2, G3>>: its elements nest the same way
// (g.second.first is the G2 component).
//
// Everything acts component-wise: (a1, a2)(b1, b2) = (a1 b1, a2 b2), exp and
// log per component, tangent vectors concatenated (G1's coordinates first),
// ad and Ad block diagonal. Geodesics of the product are pairs of geodesics,
// each with its own one-parameter subgroup. So Product<SO3<>, Rn<3>> differs
// from SE3 exactly where SE(3) couples rotation and translation: its
// composition adds translations without rotating them, and its geodesics
// move the translation along a straight line instead of a screw.
#pragma once

#include <algorithm>
#include <type_traits>

#include <Eigen/Core>

#include "bireg/groups/capabilities.hpp"

namespace bireg {

// An element of G1 x G2: a pair of the factors' elements.
template <class E1, class E2>
struct ProductElement {
  E1 first;
  E2 second;
  bool allFinite() const { return first.allFinite() && second.allFinite(); }
  bool operator==(const ProductElement& other) const {
    return first == other.first && second == other.second;
  }
};

// The algebra of G1 x G2 as a pair of the factors' algebras.
template <class A1, class A2>
struct ProductAlgebra {
  A1 first;
  A2 second;
};

template <class G1, class G2, class... More>
struct Product : Product<G1, Product<G2, More...>> {};

template <class G1, class G2>
struct Product<G1, G2> {
  static_assert(std::is_same_v<typename G1::Scalar, typename G2::Scalar>,
                "Product<G1, G2>: both factors need the same Scalar");
  using Scalar = typename G1::Scalar;
  static constexpr int dof1 = G1::dof, dof2 = G2::dof;
  static constexpr int dof = dof1 + dof2;
  static constexpr const char* name = "Product";
  using Element = ProductElement<typename G1::Element, typename G2::Element>;
  using Algebra = ProductAlgebra<typename G1::Algebra, typename G2::Algebra>;
  using Tangent = Eigen::Matrix<Scalar, dof, 1>;
  using AdMatrix = Eigen::Matrix<Scalar, dof, dof>;

  static typename G1::Tangent head(const Tangent& x) { return x.template head<dof1>(); }
  static typename G2::Tangent tail(const Tangent& x) { return x.template tail<dof2>(); }
  static Tangent join(const typename G1::Tangent& a, const typename G2::Tangent& b) {
    Tangent x;
    x.template head<dof1>() = a;
    x.template tail<dof2>() = b;
    return x;
  }
  static AdMatrix block_diagonal(const typename G1::AdMatrix& a, const typename G2::AdMatrix& b) {
    AdMatrix m = AdMatrix::Zero();
    m.template topLeftCorner<dof1, dof1>() = a;
    m.template bottomRightCorner<dof2, dof2>() = b;
    return m;
  }

  static Element identity() { return {G1::identity(), G2::identity()}; }
  static Element compose(const Element& a, const Element& b) {
    return {G1::compose(a.first, b.first), G2::compose(a.second, b.second)};
  }
  static Element inverse(const Element& g) { return {G1::inverse(g.first), G2::inverse(g.second)}; }
  static Element exp(const Tangent& x) { return {G1::exp(head(x)), G2::exp(tail(x))}; }
  static Tangent log(const Element& g) { return join(G1::log(g.first), G2::log(g.second)); }
  static Algebra hat(const Tangent& x) { return {G1::hat(head(x)), G2::hat(tail(x))}; }
  static Tangent vee(const Algebra& m) { return join(G1::vee(m.first), G2::vee(m.second)); }
  static AdMatrix ad(const Tangent& x) { return block_diagonal(G1::ad(head(x)), G2::ad(tail(x))); }
  static AdMatrix Ad(const Element& g) { return block_diagonal(G1::Ad(g.first), G2::Ad(g.second)); }
  static Scalar ad_spectral_radius(const Tangent& x) {
    return std::max(bireg::ad_spectral_radius<G1>(head(x)), bireg::ad_spectral_radius<G2>(tail(x)));
  }
  static AdMatrix right_jacobian(const Tangent& x) {
    return block_diagonal(bireg::right_jacobian<G1>(head(x)), bireg::right_jacobian<G2>(tail(x)));
  }
  static AdMatrix right_jacobian_inverse(const Tangent& x) {
    return block_diagonal(bireg::right_jacobian_inverse<G1>(head(x)),
                          bireg::right_jacobian_inverse<G2>(tail(x)));
  }
  static bool is_element(const Element& g, Scalar tol) {
    return G1::is_element(g.first, tol) && G2::is_element(g.second, tol);
  }
};

}  // namespace bireg
