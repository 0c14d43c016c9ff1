// The noisy geodesic bench_regression and bench_batched fit: n observations
// g0 exp(s_i x) exp(e_i) at s_i = i / (n - 1), from a random start
// g0 = exp(start), start and x's direction drawn uniform in [-1, 1] per
// tangent coordinate, x scaled to norm `length`, noise e_i's coordinates
// uniform in [-noise, noise]. Drawn and composed in double and rounded to
// G's scalar, so that a float group fits the same data as its double one;
// for a double group the observations are the double ones as they are.
#pragma once

#include <cstddef>
#include <random>
#include <type_traits>
#include <vector>

namespace bench {

template <class G>
struct Problem {
  std::vector<typename G::Element> f;
  std::vector<double> t;
};

// G's group in double precision: a one-parameter group template (SO3<float>)
// at double, or G itself when its scalar is double already.
template <class G>
struct InDouble {
  static_assert(std::is_same_v<typename G::Scalar, double>, "no double counterpart of G");
  using type = G;
};
template <template <class> class Group, class Scalar>
struct InDouble<Group<Scalar>> {
  using type = Group<double>;
};

template <class G>
Problem<G> make_problem(int n, double length, double noise, unsigned seed) {
  using D = typename InDouble<G>::type;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uniform(-1, 1);
  typename D::Tangent start, x;
  for (int k = 0; k < D::dof; ++k) {
    start[k] = uniform(rng);
    x[k] = uniform(rng);
  }
  x *= length / x.norm();
  const typename D::Element g0 = D::exp(start);
  Problem<G> problem;
  problem.f.reserve(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    const double s = static_cast<double>(i) / (n - 1);
    typename D::Tangent e;
    for (int k = 0; k < D::dof; ++k)
      e[k] = noise * uniform(rng);
    const typename D::Element f = D::compose(D::compose(g0, D::exp(s * x)), D::exp(e));
    if constexpr (std::is_same_v<D, G>) {
      problem.f.push_back(f);
    } else {
      problem.f.push_back(f.template cast<typename G::Scalar>());
    }
    problem.t.push_back(s);
  }
  return problem;
}

}  // namespace bench
