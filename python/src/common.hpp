// What every binding file shares: the groups Python can name, the view of a
// numpy stack of matrices as the library's observations, and the array
// conversions. No statistics here: the binding files call the library.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdlib>
#include <new>
#include <string>
#include <utility>
#include <vector>

#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/pair.h>
#include <nanobind/stl/string.h>
#include <Eigen/Core>

#if defined(__linux__)
#include <sys/mman.h>
#endif

#include "bireg/groups/matrix_group.hpp"
#include "bireg/groups/se2.hpp"
#include "bireg/groups/se3.hpp"
#include "bireg/groups/sim3.hpp"
#include "bireg/groups/so2.hpp"
#include "bireg/groups/so3.hpp"

namespace bireg_python {

namespace nb = nanobind;

// Inputs arrive C-contiguous float64 (the Python layer converts once, with
// numpy, and checks the shapes; see bireg/_arrays.py).
using Stack = nb::ndarray<const double, nb::ndim<3>, nb::c_contig, nb::device::cpu>;
using Matrix = nb::ndarray<const double, nb::ndim<2>, nb::c_contig, nb::device::cpu>;
using Vector = nb::ndarray<const double, nb::ndim<1>, nb::c_contig, nb::device::cpu>;
using Output = nb::ndarray<nb::numpy, double>;

template <class G>
struct Tag {
  using type = G;
};

// The groups of the Python package, by the names Python uses.
inline const char* const kGroupNames = "SO2, SO3, SE2, SE3, Sim3, SL3, GLp3";

// Calls f(Tag<G>{}) for the group named `name`; ValueError for another name.
template <class F>
decltype(auto) with_group(const std::string& name, F&& f) {
  if (name == "SO2") return f(Tag<bireg::SO2d>{});
  if (name == "SO3") return f(Tag<bireg::SO3d>{});
  if (name == "SE2") return f(Tag<bireg::SE2d>{});
  if (name == "SE3") return f(Tag<bireg::SE3d>{});
  if (name == "Sim3") return f(Tag<bireg::Sim3d>{});
  if (name == "SL3") return f(Tag<bireg::SL3<double>>{});
  if (name == "GLp3") return f(Tag<bireg::GLp<3, double>>{});
  throw nb::value_error(("unknown group '" + name + "': expected one of " + kGroupNames).c_str());
}

template <class G>
constexpr int side() {
  return int(G::Element::RowsAtCompileTime);
}

// A stack of row-major n x n matrices (numpy's (N, n, n) in C order) seen
// as the library's observations: indexable, with size(); element i is
// converted to the group's (column-major) Element when it is read, so the
// data are never copied whole.
template <class G>
class StackView {
 public:
  using Element = typename G::Element;
  using RowMajor = Eigen::Matrix<double, side<G>(), side<G>(), Eigen::RowMajor>;

  StackView() = default;
  StackView(const double* data, std::size_t size) : data_(data), size_(size) {}
  explicit StackView(const Stack& stack) : data_(stack.data()), size_(stack.shape(0)) {}

  std::size_t size() const { return size_; }
  Element operator[](std::size_t i) const {
    return Eigen::Map<const RowMajor>(data_ + i * std::size_t(side<G>() * side<G>()));
  }

 private:
  const double* data_ = nullptr;
  std::size_t size_ = 0;
};

// A refusal as Python's ValueError, carrying the library's message (which
// names the observation where there is one).
[[noreturn]] inline void refuse(const std::string& message) {
  throw nb::value_error(message.c_str());
}

// Refuses the first covariate of t that is not finite, naming `what` and
// its index.
inline void check_covariates(const Vector& t, const char* what) {
  for (std::size_t i = 0; i < t.shape(0); ++i)
    if (!std::isfinite(t.data()[i]))
      refuse(std::string(what) + ": covariate " + std::to_string(i) + " is not finite");
}

inline std::vector<double> to_vector(const Vector& v) {
  return std::vector<double>(v.data(), v.data() + v.shape(0));
}

// Memory for a result array. Large ones (at least kHugeThreshold bytes)
// are aligned to 2 MiB and, on Linux, advised as transparent huge pages,
// as numpy does for its own large arrays: a fresh 128 MB result is then
// 64 page faults instead of 32,768, which on this project's VM cost more
// than computing SE(3) exp of its 1e6 elements (bench/README.md). Without
// the advice (another system, THP off) it is ordinary memory.
class ResultMemory {
 public:
  static constexpr std::size_t kHugePage = std::size_t(2) << 20;
  static constexpr std::size_t kHugeThreshold = std::size_t(4) << 20;

  static double* allocate(std::size_t count) {
    const std::size_t bytes = std::max<std::size_t>(count, 1) * sizeof(double);
    if (bytes < kHugeThreshold) return static_cast<double*>(checked(std::malloc(bytes)));
    const std::size_t rounded = (bytes + kHugePage - 1) / kHugePage * kHugePage;
    void* memory = checked(std::aligned_alloc(kHugePage, rounded));
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    madvise(memory, rounded, MADV_HUGEPAGE);  // advice only: ignored where unsupported
#endif
    return static_cast<double*>(memory);
  }

  static void release(void* memory) noexcept {
    std::free(memory);
  }

 private:
  static void* checked(void* memory) {
    if (!memory) throw std::bad_alloc();
    return memory;
  }
};

// A new float64 numpy array of the given shape, owned by Python, and its
// data to fill (before it is handed over; no other reference exists).
class NewArray {
 public:
  explicit NewArray(std::vector<std::size_t> shape) : shape_(std::move(shape)) {
    std::size_t count = 1;
    for (std::size_t s : shape_)
      count *= s;
    // Not value-initialised: every caller writes each entry before release()
    // (a refusal frees the array instead), and zeroing a 128 MB result
    // would be a second pass over fresh pages.
    data_ = ResultMemory::allocate(count);
  }
  NewArray(const NewArray&) = delete;
  NewArray& operator=(const NewArray&) = delete;
  ~NewArray() { ResultMemory::release(data_); }

  double* data() { return data_; }

  // Hands the buffer to a numpy array (needs the GIL).
  Output release() {
    double* data = data_;
    data_ = nullptr;
    nb::capsule owner(data, [](void* p) noexcept { ResultMemory::release(p); });
    return Output(data, shape_.size(), shape_.data(), owner);
  }

 private:
  std::vector<std::size_t> shape_;
  double* data_ = nullptr;
};

// Writes an Eigen matrix row-major at `out` (numpy's C order).
template <class M>
void write_row_major(const M& m, double* out) {
  for (Eigen::Index r = 0; r < m.rows(); ++r)
    for (Eigen::Index c = 0; c < m.cols(); ++c)
      *out++ = m(r, c);
}

template <class M>
Output matrix_array(const M& m) {
  NewArray a({std::size_t(m.rows()), std::size_t(m.cols())});
  write_row_major(m, a.data());
  return a.release();
}

// A vector as a 1-D array: an Eigen vector or a std::vector<double>.
template <class V>
Output vector_array(const V& v) {
  const std::size_t size = static_cast<std::size_t>(v.size());
  NewArray a({size});
  for (std::size_t k = 0; k < size; ++k)
    a.data()[k] = v[static_cast<decltype(v.size())>(k)];
  return a.release();
}

// Tangent vectors, one row each: (N, d).
template <class G>
Output tangent_rows(const std::vector<typename G::Tangent>& rows) {
  NewArray a({rows.size(), std::size_t(G::dof)});
  for (std::size_t i = 0; i < rows.size(); ++i)
    for (int k = 0; k < G::dof; ++k)
      a.data()[i * G::dof + k] = rows[i][k];
  return a.release();
}

void bind_groups(nb::module_& m);
void bind_regression(nb::module_& m);
void bind_spline(nb::module_& m);
void bind_statistics(nb::module_& m);
void bind_io(nb::module_& m);
void bind_cohorts(nb::module_& m);
void bind_selection(nb::module_& m);

}  // namespace bireg_python
