// bireg: the Lie group traits concept, checked at compile time.
//
// A group is a stateless traits type G with
//
//   types      G::Scalar, G::Element (with allFinite(), as every Eigen matrix
//              has), G::Tangent (Eigen vector of size dof), G::AdMatrix (dof x dof)
//   constants  G::dof (int), G::name (const char*)
//   functions  static G::identity(), compose(a, b), inverse(g), exp(x), log(g),
//              ad(x), Ad(g), is_element(g, tol)
//
// with the left-trivialised conventions of DESIGN.md: ad(x) y = [x, y],
// Ad(g) x = g x g^{-1} in coordinates, log the principal logarithm. That is
// all the algorithms call. The groups shipped with bireg also have hat/vee
// (coordinates to algebra matrices and back) for their users; optional
// capabilities with generic fallbacks (closed-form psi, Jacobians, spectral
// radius of ad) are in groups/capabilities.hpp, included here.
// Every bireg algorithm starts with `static_assert(is_lie_group_v<G>)` through
// check_lie_group<G>(), so a user-written group that misses a piece fails to
// compile with a message that names the piece, not with a template backtrace.
#pragma once

#include <type_traits>
#include <utility>

#include <Eigen/Core>

#include "bireg/groups/capabilities.hpp"

namespace bireg {
namespace concept_detail {

template <class G, class = void>
struct has_types : std::false_type {};
template <class G>
struct has_types<G, std::void_t<typename G::Scalar, typename G::Element, typename G::Tangent,
                                typename G::AdMatrix, decltype(G::dof), decltype(G::name)>>
    : std::true_type {};

// Each check is only instantiated when has_types holds, so a missing type
// produces exactly one message.
template <class G>
struct shapes {
  using Scalar = typename G::Scalar;
  static constexpr bool tangent =
      std::is_same_v<typename G::Tangent, Eigen::Matrix<Scalar, G::dof, 1>>;
  static constexpr bool ad_matrix =
      std::is_same_v<typename G::AdMatrix, Eigen::Matrix<Scalar, G::dof, G::dof>>;
};

template <class G, class = void>
struct has_group_operations : std::false_type {};
template <class G>
struct has_group_operations<
    G, std::void_t<decltype(G::identity()),
                   decltype(G::compose(std::declval<const typename G::Element&>(),
                                       std::declval<const typename G::Element&>())),
                   decltype(G::inverse(std::declval<const typename G::Element&>()))>>
    : std::conjunction<
          std::is_convertible<decltype(G::identity()), typename G::Element>,
          std::is_convertible<decltype(G::compose(std::declval<const typename G::Element&>(),
                                                  std::declval<const typename G::Element&>())),
                              typename G::Element>,
          std::is_convertible<decltype(G::inverse(std::declval<const typename G::Element&>())),
                              typename G::Element>> {};

template <class G, class = void>
struct has_exp_log : std::false_type {};
template <class G>
struct has_exp_log<G, std::void_t<decltype(G::exp(std::declval<const typename G::Tangent&>())),
                                  decltype(G::log(std::declval<const typename G::Element&>()))>>
    : std::conjunction<
          std::is_convertible<decltype(G::exp(std::declval<const typename G::Tangent&>())),
                              typename G::Element>,
          std::is_convertible<decltype(G::log(std::declval<const typename G::Element&>())),
                              typename G::Tangent>> {};

template <class G, class = void>
struct has_finiteness_test : std::false_type {};
template <class G>
struct has_finiteness_test<
    G, std::void_t<decltype(std::declval<const typename G::Element&>().allFinite())>>
    : std::is_convertible<decltype(std::declval<const typename G::Element&>().allFinite()), bool> {
};

template <class G, class = void>
struct has_adjoints : std::false_type {};
template <class G>
struct has_adjoints<G, std::void_t<decltype(G::ad(std::declval<const typename G::Tangent&>())),
                                   decltype(G::Ad(std::declval<const typename G::Element&>()))>>
    : std::conjunction<
          std::is_convertible<decltype(G::ad(std::declval<const typename G::Tangent&>())),
                              typename G::AdMatrix>,
          std::is_convertible<decltype(G::Ad(std::declval<const typename G::Element&>())),
                              typename G::AdMatrix>> {};

template <class G, class = void>
struct has_is_element : std::false_type {};
template <class G>
struct has_is_element<G,
                      std::void_t<decltype(G::is_element(std::declval<const typename G::Element&>(),
                                                         std::declval<typename G::Scalar>()))>>
    : std::is_convertible<decltype(G::is_element(std::declval<const typename G::Element&>(),
                                                 std::declval<typename G::Scalar>())),
                          bool> {};

template <class G, bool = has_types<G>::value>
struct check {
  static constexpr bool value = false;
};
template <class G>
struct check<G, true> {
  static constexpr bool value = shapes<G>::tangent && shapes<G>::ad_matrix &&
                                has_group_operations<G>::value && has_exp_log<G>::value &&
                                has_finiteness_test<G>::value && has_adjoints<G>::value &&
                                has_is_element<G>::value;
};

}  // namespace concept_detail

// True when G satisfies the group traits concept above.
template <class G>
inline constexpr bool is_lie_group_v = concept_detail::check<G>::value;

// Fails compilation with a message naming what G lacks. Call it (or
// static_assert(is_lie_group_v<G>)) at the top of code generic over groups.
template <class G>
constexpr bool check_lie_group() {
  using namespace concept_detail;
  static_assert(has_types<G>::value,
                "bireg group concept: G must define Scalar, Element, Tangent, AdMatrix, "
                "static constexpr int dof and static constexpr const char* name");
  if constexpr (has_types<G>::value) {
    static_assert(shapes<G>::tangent,
                  "bireg group concept: G::Tangent must be Eigen::Matrix<Scalar, dof, 1>");
    static_assert(shapes<G>::ad_matrix,
                  "bireg group concept: G::AdMatrix must be Eigen::Matrix<Scalar, dof, dof>");
    static_assert(has_group_operations<G>::value,
                  "bireg group concept: G needs static identity(), compose(Element, Element) and "
                  "inverse(Element), each returning Element");
    static_assert(has_exp_log<G>::value,
                  "bireg group concept: G needs static exp(Tangent) -> Element and "
                  "log(Element) -> Tangent");
    static_assert(has_finiteness_test<G>::value,
                  "bireg group concept: G::Element needs allFinite() -> bool (every Eigen "
                  "matrix has it; a composite element provides its own)");
    static_assert(has_adjoints<G>::value,
                  "bireg group concept: G needs static ad(Tangent) and Ad(Element) returning "
                  "AdMatrix");
    static_assert(has_is_element<G>::value,
                  "bireg group concept: G needs static is_element(Element, Scalar tol) -> bool");
  }
  return is_lie_group_v<G>;
}

}  // namespace bireg
