// The groups layer: exp, log, compose, inverse, Ad, the right Jacobian and
// the membership test over a batch, one loop in C++ with the GIL released.
// Broadcasting and shape checks are numpy's, in bireg/groups.py.
#include <cmath>
#include <string>
#include <vector>

#include "common.hpp"

#include "bireg/groups/capabilities.hpp"
#include "bireg/groups/tolerance.hpp"

namespace bireg_python {
namespace {

template <class G>
using TangentMap = Eigen::Map<const typename G::Tangent>;

// The first index whose entries are not all finite, or -1.
inline std::ptrdiff_t first_non_finite(const double* data, std::size_t count, std::size_t stride) {
  for (std::size_t i = 0; i < count; ++i)
    for (std::size_t k = 0; k < stride; ++k)
      if (!std::isfinite(data[i * stride + k])) return std::ptrdiff_t(i);
  return -1;
}

[[noreturn]] void refuse_at(const std::string& what, std::ptrdiff_t index) {
  throw nb::value_error((what + " " + std::to_string(index)).c_str());
}

// f of each row of x (a tangent vector), written row-major into an array
// of shape (count, rows, cols); refuses the first row that is not finite.
template <class G, class F>
Output map_tangents(const Matrix& x, std::size_t rows, std::size_t cols, const char* what, F f) {
  const std::size_t count = x.shape(0), d = std::size_t(G::dof);
  NewArray out({count, rows, cols});
  std::ptrdiff_t bad = -1;
  {
    nb::gil_scoped_release release;
    bad = first_non_finite(x.data(), count, d);
    for (std::size_t i = 0; i < count && bad < 0; ++i)
      write_row_major(f(TangentMap<G>(x.data() + i * d)), out.data() + i * rows * cols);
  }
  if (bad >= 0) refuse_at(std::string(what) + ": the tangent vector is not finite at index", bad);
  return out.release();
}

// f of each element of the stack, written row-major into an array of shape
// `shape` (count first); refuses, with `refusal` and the index, the first
// matrix that is not an element of G or whose f is not finite.
template <class G, class F>
Output map_elements(const Stack& g, std::vector<std::size_t> shape, const std::string& refusal,
                    F f) {
  const std::size_t count = g.shape(0);
  std::size_t stride = 1;
  for (std::size_t k = 1; k < shape.size(); ++k)
    stride *= shape[k];
  const StackView<G> elements(g);
  NewArray out(std::move(shape));
  std::ptrdiff_t bad = -1;
  {
    nb::gil_scoped_release release;
    for (std::size_t i = 0; i < count && bad < 0; ++i) {
      const typename G::Element e = elements[i];
      if (!e.allFinite() || !G::is_element(e, bireg::default_element_tolerance<double>())) {
        bad = std::ptrdiff_t(i);
        break;
      }
      const auto value = f(e);
      if (!value.allFinite()) bad = std::ptrdiff_t(i);
      write_row_major(value, out.data() + i * stride);
    }
  }
  if (bad >= 0) refuse_at(refusal, bad);
  return out.release();
}

template <class G>
Output exp_batch(const Matrix& x) {
  const std::size_t n = std::size_t(side<G>());
  return map_tangents<G>(x, n, n, "exp", [](const auto& v) { return G::exp(v); });
}

template <class G>
Output right_jacobian_batch(const Matrix& x) {
  const std::size_t d = std::size_t(G::dof);
  return map_tangents<G>(x, d, d, "right_jacobian",
                         [](const auto& v) { return bireg::right_jacobian<G>(v); });
}

template <class G>
Output log_batch(const Stack& g) {
  return map_elements<G>(g, {g.shape(0), std::size_t(G::dof)},
                         std::string("log: no principal logarithm in ") + G::name +
                             " (not an element, or beyond the log's domain) at index",
                         [](const typename G::Element& e) { return G::log(e); });
}

template <class G>
Output inverse_batch(const Stack& g) {
  const std::size_t n = std::size_t(side<G>());
  return map_elements<G>(g, {g.shape(0), n, n},
                         std::string("inverse: not an element of ") + G::name + " at index",
                         [](const typename G::Element& e) { return G::inverse(e); });
}

template <class G>
Output adjoint_batch(const Stack& g) {
  const std::size_t d = std::size_t(G::dof);
  return map_elements<G>(g, {g.shape(0), d, d},
                         std::string("Ad: not an element of ") + G::name + " at index",
                         [](const typename G::Element& e) { return G::Ad(e); });
}

template <class G>
Output compose_batch(const Stack& a, const Stack& b) {
  const std::size_t count = a.shape(0), n = std::size_t(side<G>());
  const StackView<G> left(a), right(b);
  NewArray out({count, n, n});
  std::ptrdiff_t bad = -1;
  {
    nb::gil_scoped_release release;
    for (std::size_t i = 0; i < count && bad < 0; ++i) {
      const typename G::Element c = G::compose(left[i], right[i]);
      if (!c.allFinite()) bad = std::ptrdiff_t(i);
      write_row_major(c, out.data() + i * n * n);
    }
  }
  if (bad >= 0) refuse_at("compose: the product is not finite at index", bad);
  return out.release();
}

template <class G>
nb::ndarray<nb::numpy, bool> is_element_batch(const Stack& g, double tolerance) {
  if (!(tolerance >= 0) || !std::isfinite(tolerance))
    throw nb::value_error("is_element: tol must be a finite non-negative number");
  const std::size_t count = g.shape(0);
  const StackView<G> elements(g);
  bool* flags = new bool[count > 0 ? count : 1]();
  {
    nb::gil_scoped_release release;
    for (std::size_t i = 0; i < count; ++i) {
      const typename G::Element e = elements[i];
      flags[i] = e.allFinite() && G::is_element(e, tolerance);
    }
  }
  nb::capsule owner(flags, [](void* p) noexcept { delete[] static_cast<bool*>(p); });
  const std::size_t shape[1] = {count};
  return nb::ndarray<nb::numpy, bool>(flags, 1, shape, owner);
}

template <class G>
void check_side(const Stack& g, const char* what) {
  const std::size_t n = std::size_t(side<G>());
  if (g.shape(1) != n || g.shape(2) != n)
    throw nb::value_error((std::string(what) + ": expected matrices of shape (" +
                           std::to_string(n) + ", " + std::to_string(n) + ") for " + G::name)
                              .c_str());
}

template <class G>
void check_dof(const Matrix& x, const char* what) {
  if (x.shape(1) != std::size_t(G::dof))
    throw nb::value_error((std::string(what) + ": expected tangent vectors of length " +
                           std::to_string(G::dof) + " for " + G::name)
                              .c_str());
}

}  // namespace

void bind_groups(nb::module_& m) {
  m.def(
      "group_info",
      [](const std::string& group) {
        return with_group(group, [](auto tag) {
          using G = typename decltype(tag)::type;
          return std::make_pair(int(G::dof), side<G>());
        });
      },
      nb::arg("group"), "The group's (algebra dimension, matrix size).");
  m.def(
      "group_exp",
      [](const std::string& group, const Matrix& x) {
        return with_group(group, [&](auto tag) {
          using G = typename decltype(tag)::type;
          check_dof<G>(x, "exp");
          return exp_batch<G>(x);
        });
      },
      nb::arg("group"), nb::arg("x"), "exp of each row of x: (M, d) -> (M, n, n).");
  m.def(
      "group_log",
      [](const std::string& group, const Stack& g) {
        return with_group(group, [&](auto tag) {
          using G = typename decltype(tag)::type;
          check_side<G>(g, "log");
          return log_batch<G>(g);
        });
      },
      nb::arg("group"), nb::arg("g"), "The principal log of each element: (M, n, n) -> (M, d).");
  m.def(
      "group_compose",
      [](const std::string& group, const Stack& a, const Stack& b) {
        return with_group(group, [&](auto tag) {
          using G = typename decltype(tag)::type;
          check_side<G>(a, "compose");
          check_side<G>(b, "compose");
          if (a.shape(0) != b.shape(0)) throw nb::value_error("compose: batches differ in length");
          return compose_batch<G>(a, b);
        });
      },
      nb::arg("group"), nb::arg("a"), nb::arg("b"), "a[i] b[i]: (M, n, n) twice -> (M, n, n).");
  m.def(
      "group_inverse",
      [](const std::string& group, const Stack& g) {
        return with_group(group, [&](auto tag) {
          using G = typename decltype(tag)::type;
          check_side<G>(g, "inverse");
          return inverse_batch<G>(g);
        });
      },
      nb::arg("group"), nb::arg("g"), "The inverse of each element.");
  m.def(
      "group_Ad",
      [](const std::string& group, const Stack& g) {
        return with_group(group, [&](auto tag) {
          using G = typename decltype(tag)::type;
          check_side<G>(g, "Ad");
          return adjoint_batch<G>(g);
        });
      },
      nb::arg("group"), nb::arg("g"),
      "The adjoint matrix of each element: (M, n, n) -> (M, d, d).");
  m.def(
      "group_right_jacobian",
      [](const std::string& group, const Matrix& x) {
        return with_group(group, [&](auto tag) {
          using G = typename decltype(tag)::type;
          check_dof<G>(x, "right_jacobian");
          return right_jacobian_batch<G>(x);
        });
      },
      nb::arg("group"), nb::arg("x"), "J_r(x) of each row of x: (M, d) -> (M, d, d).");
  m.def(
      "group_is_element",
      [](const std::string& group, const Stack& g, double tolerance) {
        return with_group(group, [&](auto tag) {
          using G = typename decltype(tag)::type;
          check_side<G>(g, "is_element");
          return is_element_batch<G>(g, tolerance);
        });
      },
      nb::arg("group"), nb::arg("g"), nb::arg("tol"),
      "Whether each matrix is an element to tol: (M, n, n) -> (M,).");
}

}  // namespace bireg_python
