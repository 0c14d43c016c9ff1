// The groups layer: exp, log, compose, inverse, Ad, the right Jacobian and
// the membership test over a batch, one loop in C++ with the GIL released.
// Broadcasting and shape checks are numpy's, in bireg/groups.py.
#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include <nanobind/stl/optional.h>

#include "common.hpp"

#include "bireg/groups/capabilities.hpp"
#include "bireg/groups/element_check.hpp"
#include "bireg/groups/tolerance.hpp"

namespace bireg_python {
namespace {

template <class G>
using TangentMap = Eigen::Map<const typename G::Tangent>;

// Results the caller allocates (numpy's out=): C-contiguous float64.
using Out2 = nb::ndarray<double, nb::ndim<2>, nb::c_contig, nb::device::cpu>;
using Out3 = nb::ndarray<double, nb::ndim<3>, nb::c_contig, nb::device::cpu>;

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

// f of each row of x (a tangent vector), written row-major at `out`, rows x
// cols per row; refuses the first row that is not finite.
template <class G, class F>
void map_tangents(const Matrix& x, std::size_t rows, std::size_t cols, double* out,
                  const char* what, F f) {
  const std::size_t count = x.shape(0), d = std::size_t(G::dof);
  std::ptrdiff_t bad = -1;
  {
    nb::gil_scoped_release release;
    bad = first_non_finite(x.data(), count, d);
    for (std::size_t i = 0; i < count && bad < 0; ++i)
      write_row_major(f(TangentMap<G>(x.data() + i * d)), out + i * rows * cols);
  }
  if (bad >= 0) refuse_at(std::string(what) + ": the tangent vector is not finite at index", bad);
}

// Asks the cache for the `count` > 0 numbers of an array from `p` on: one
// hint per 64-byte line they touch (a hint; nothing is read).
inline void prefetch(const double* p, std::size_t count) {
  constexpr std::size_t kLine = 64 / sizeof(double);
  for (std::size_t k = 0; k < count; k += kLine)
    __builtin_prefetch(p + k);
  if ((count - 1) % kLine != 0) __builtin_prefetch(p + count - 1);
}

// bireg::first_non_element for the CPU this runs on. SO(3)'s and SE(3)'s
// check vectorizes across matrices where the target can gather, and the
// module is built for the baseline, so with GCC on x86-64 and glibc these
// two are compiled for AVX-512, AVX2 and the baseline and the loader picks
// one by the CPU's features (target_clones, an ifunc; clones named arch=...
// are chosen by the CPU's model, and no AMD CPU is a "skylake-avx512").
// Over 1e6 SE(3) logs into out= the AVX-512 clone took 69.3 ms where the
// baseline's took 72.5 (bench/README.md, "Python against C++"). Raw numbers
// in, an index out: no Eigen object crosses between code built for
// different vector widths.
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__GLIBC__)
__attribute__((target_clones("avx512f", "avx2", "default"), flatten))
#endif
std::size_t
first_non_rotation(const double* data, std::size_t count, double tol) {
  return bireg::first_non_element<bireg::SO3d>(data, count, tol);
}

#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__GLIBC__)
__attribute__((target_clones("avx512f", "avx2", "default"), flatten))
#endif
std::size_t
first_non_pose(const double* data, std::size_t count, double tol) {
  return bireg::first_non_element<bireg::SE3d>(data, count, tol);
}

template <class G>
std::size_t first_non_element(const double* data, std::size_t count, double tol) {
  if constexpr (std::is_same_v<G, bireg::SO3d>) {
    return first_non_rotation(data, count, tol);
  } else if constexpr (std::is_same_v<G, bireg::SE3d>) {
    return first_non_pose(data, count, tol);
  } else {
    return bireg::first_non_element<G>(data, count, tol);
  }
}

// f of each element of the stack, written row-major at `out`, `stride` numbers
// per element; refuses, with `refusal` and the index, the first matrix that is
// not an element of G (is_element: finite, and in G to the default tolerance)
// or whose f is not finite. A block (first_non_element's own,
// bireg::kElementCheckBlock = 256 matrices: 32 KiB of SE(3), still in cache
// when f reads it) is checked in a loop of its own, then mapped: over 1e6 SE(3)
// logs this took 10 ms less than checking each element just before its log, and
// reading each matrix twice (row-major into the group's Element) was faster
// than keeping the block's Elements for the second loop. While a block is
// mapped the next one is fetched, so that its check reads the cache: the check
// alone is too light to hide memory's latency (3.5 ms of 73 over 1e6 SE(3)
// logs; bench/README.md, "Python against C++").
template <class G, class F>
void map_elements(const Stack& g, std::size_t stride, double* out, const std::string& refusal,
                  F f) {
  const std::size_t count = g.shape(0), entries = std::size_t(side<G>() * side<G>());
  const StackView<G> elements(g);
  const double tolerance = bireg::default_element_tolerance<double>();
  std::ptrdiff_t bad = -1;
  {
    nb::gil_scoped_release release;
    for (std::size_t begin = 0; begin < count && bad < 0; begin += bireg::kElementCheckBlock) {
      // The block's elements up to the first that is not one; those are
      // mapped first, so that an earlier f that is not finite is named.
      const std::size_t end = std::min(count, begin + bireg::kElementCheckBlock);
      const std::size_t members =
          begin + first_non_element<G>(g.data() + begin * entries, end - begin, tolerance);
      for (std::size_t i = begin; i < members && bad < 0; ++i) {
        if (i + bireg::kElementCheckBlock < count)
          prefetch(g.data() + (i + bireg::kElementCheckBlock) * entries, entries);
        const auto value = f(elements[i]);
        if (!value.allFinite()) bad = std::ptrdiff_t(i);
        write_row_major(value, out + i * stride);
      }
      if (bad < 0 && members < end) bad = std::ptrdiff_t(members);
    }
  }
  if (bad >= 0) refuse_at(refusal, bad);
}

// A new (count, rows, cols) array filled by map_elements.
template <class G, class F>
Output map_elements_new(const Stack& g, std::size_t rows, std::size_t cols,
                        const std::string& refusal, F f) {
  NewArray out({g.shape(0), rows, cols});
  map_elements<G>(g, rows * cols, out.data(), refusal, f);
  return out.release();
}

// The result of a batch of shape[0] items of shape[1] x ... numbers each:
// the caller's `out` (numpy's out=: bound with noconvert, so nanobind
// refuses an array it would have to copy; the Python layer checks its
// shape, dtype and overlap, this its size), or a new array of `shape` when
// there is none.
template <class Array>
class BatchResult {
 public:
  BatchResult(std::optional<Array>& out, std::vector<std::size_t> shape, const char* what) {
    if (!out) {
      fresh_.emplace(std::move(shape));
      data_ = fresh_->data();
      return;
    }
    std::size_t size = 1;
    for (const std::size_t extent : shape)
      size *= extent;
    if (out->shape(0) != shape[0] || out->size() != size)
      throw nb::value_error((std::string(what) + ": out has the wrong shape").c_str());
    data_ = out->data();
  }
  double* data() { return data_; }
  // The new array, or None when the result went to the caller's.
  nb::object release() { return fresh_ ? nb::cast(fresh_->release()) : nb::none(); }

 private:
  std::optional<NewArray> fresh_;
  double* data_ = nullptr;
};

template <class G>
nb::object exp_batch(const Matrix& x, std::optional<Out3>& out) {
  const std::size_t n = std::size_t(side<G>());
  BatchResult<Out3> result(out, {x.shape(0), n, n}, "exp");
  map_tangents<G>(x, n, n, result.data(), "exp", [](const auto& v) { return G::exp(v); });
  return result.release();
}

template <class G>
Output right_jacobian_batch(const Matrix& x) {
  const std::size_t d = std::size_t(G::dof);
  NewArray out({x.shape(0), d, d});
  map_tangents<G>(x, d, d, out.data(), "right_jacobian",
                  [](const auto& v) { return bireg::right_jacobian<G>(v); });
  return out.release();
}

template <class G>
nb::object log_batch(const Stack& g, std::optional<Out2>& out) {
  const std::size_t d = std::size_t(G::dof);
  BatchResult<Out2> result(out, {g.shape(0), d}, "log");
  map_elements<G>(g, d, result.data(),
                  std::string("log: no principal logarithm in ") + G::name +
                      " (not an element, or beyond the log's domain) at index",
                  [](const typename G::Element& e) { return G::log(e); });
  return result.release();
}

template <class G>
Output inverse_batch(const Stack& g) {
  const std::size_t n = std::size_t(side<G>());
  return map_elements_new<G>(g, n, n,
                             std::string("inverse: not an element of ") + G::name + " at index",
                             [](const typename G::Element& e) { return G::inverse(e); });
}

template <class G>
Output adjoint_batch(const Stack& g) {
  const std::size_t d = std::size_t(G::dof);
  return map_elements_new<G>(g, d, d, std::string("Ad: not an element of ") + G::name + " at index",
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
      flags[i] = G::is_element(e, tolerance);
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
      [](const std::string& group, const Matrix& x, std::optional<Out3> out) {
        return with_group(group, [&](auto tag) {
          using G = typename decltype(tag)::type;
          check_dof<G>(x, "exp");
          return exp_batch<G>(x, out);
        });
      },
      nb::arg("group"), nb::arg("x"), nb::arg("out").none().noconvert(),
      "exp of each row of x: (M, d) -> (M, n, n), a new array, or written to out (None "
      "returned).");
  m.def(
      "group_log",
      [](const std::string& group, const Stack& g, std::optional<Out2> out) {
        return with_group(group, [&](auto tag) {
          using G = typename decltype(tag)::type;
          check_side<G>(g, "log");
          return log_batch<G>(g, out);
        });
      },
      nb::arg("group"), nb::arg("g"), nb::arg("out").none().noconvert(),
      "The principal log of each element: (M, n, n) -> (M, d), a new array, or written to out "
      "(None returned).");
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
