#!/usr/bin/env python3
"""Mutation check for bireg: plants known bugs one at a time and checks that
the named tests catch each of them (docs/mutation.md has the table and the
results of the last run).

Run from anywhere inside the repository:

    python3 tools/mutation_check.py                 # every mutant
    python3 tools/mutation_check.py SA1 EE1         # only these
    python3 tools/mutation_check.py --list          # the table, no build
    python3 tools/mutation_check.py --check         # every edit applies? no build

Environment: MUT_DIR (scratch directory, default /tmp/bireg-mutation),
MUT_JOBS (ninja -j, default 1), MUT_BUILD_TYPE (default Release).

How it works: the tracked files of the working tree (git ls-files, with
their current contents) are copied to $MUT_DIR/src, configured once into
$MUT_DIR/build (kept between runs). For each mutant the one edit is applied
to the scratch copy, only the test targets named for that mutant are built,
their tests are run through ctest -R, the result is recorded (killed: a
build that succeeds and at least one test that fails; survived: all pass;
error: the mutant did not compile, which is no evidence), and the file is
restored. The repository itself is never modified.

Every edit must match its file exactly once: a pattern that is missing or
ambiguous stops the run with an error before anything is built, so the
table cannot rot silently when the code changes.

Time: each mutant recompiles its 1-2 test translation units (Eigen-heavy:
about 1-1.5 min each with -j1 on the 2-core CI-sized machine) and runs their
tests (seconds to a minute); the whole table takes about 30 minutes with
-j1 on an idle machine, and took 35 minutes for 15 mutants on 2026-11-23
with other builds sharing the 2 cores. The first run also configures the
scratch build (seconds).
"""

import fcntl
import os
import shutil
import subprocess
import sys
import time
from dataclasses import dataclass, field
from typing import List


@dataclass
class Mutant:
    name: str
    path: str  # relative to the repository root
    old: str  # must occur exactly once in the file
    new: str
    targets: List[str]  # test executables (ctest prefix "<target>: ")
    why: str  # the bug it stands for
    regex: str = ""  # optional ctest -R regex; default: every test of targets
    # (ctest names are "<target>:<TEST_CASE name>"; no test matched is an error)
    tags: List[str] = field(default_factory=list)


MUTANTS = [
    Mutant("SA1", "include/bireg/math/small_angle.hpp",
           "if (abs(x) < tiny_angle<Scalar>()) return Scalar(1) - x * x / Scalar(12);",
           "if (abs(x) < tiny_angle<Scalar>()) return Scalar(1) - x * x / Scalar(6);",
           ["test_group_accuracy"],
           "wrong series coefficient of (x/2)cot(x/2) near 0 (1/6 for 1/12)"),
    Mutant("SA2", "include/bireg/math/small_angle.hpp",
           "if (abs(x) < Scalar(2)) return polynomial(kSeries, x * x);\n  return (x - sin(x))",
           "if (abs(x) < Scalar(0.5)) return polynomial(kSeries, x * x);\n  return (x - sin(x))",
           ["test_group_accuracy"],
           "series/direct threshold of (x - sin x)/x^3 moved from 2 to 0.5"),
    Mutant("GR1", "include/bireg/groups/so3.hpp",
           "return AdMatrix::Identity() + w / Scalar(2) +",
           "return AdMatrix::Identity() - w / Scalar(2) +",
           ["test_groups"],
           "sign of the W/2 term of SO(3)'s inverse right Jacobian"),
    Mutant("EE1", "include/bireg/regression/estimating_equations.hpp",
           "v1_sums[k] += (w * c1[k]) * r;",
           "v1_sums[k] += c1[k] * r;",
           ["test_regression"],
           "weights dropped from the v1 term of the exact (closed-form) force"),
    Mutant("EE2", "include/bireg/regression/estimating_equations.hpp",
           "Scalar one_minus_t_power = problem.w[i];",
           "Scalar one_minus_t_power = Scalar(1);",
           ["test_regression"],
           "weights dropped from the Q moments of the series force"),
    Mutant("GN1", "include/bireg/regression/step_rules/gauss_newton.hpp",
           "SmallLU<KMatrix>(matrix(state.a)).solve(v);",
           "SmallLU<KMatrix>(matrix(state.a)).solve(-v);",
           ["test_regression"],
           "sign flip of the Gauss-Newton step"),
    Mutant("IT1", "include/bireg/regression/iteration.hpp",
           "(step_norm > kDivergenceGrowth * smallest_step && step_norm > divergence_floor)",
           "(false && step_norm > divergence_floor)",
           ["test_regression", "test_stability"],
           "divergence check disabled (only non-finite steps stop the loop)"),
    Mutant("IT2", "include/bireg/regression/iteration.hpp",
           "if (rule.convergence_norm(step_norm, state) <= control.tolerance) {",
           "if (rule.convergence_norm(step_norm, state) <= 100 * control.tolerance) {",
           ["test_regression"],
           "convergence declared at 100 x the tolerance"),
    Mutant("DG1", "include/bireg/regression/diagnostics.hpp",
           "d.explained_variance = spread > 0 ? 1 - residual_sum / spread : Scalar(1);",
           "d.explained_variance = spread > 0 ? 1 - sqrt(residual_sum / spread) : Scalar(1);",
           ["test_regression"],
           "explained variance from the RMS ratio instead of the variance ratio"),
    Mutant("DG2", "include/bireg/regression/diagnostics.hpp",
           "constexpr Scalar kBeyondDomainAngle = Scalar(0.75L *",
           "constexpr Scalar kBeyondDomainAngle = Scalar(0.95L *",
           ["test_regression", "test_stability"],
           "beyond_domain threshold moved from 3 pi/4 to 0.95 pi"),
    Mutant("CV1", "include/bireg/statistics/inference/covariance.hpp",
           "const Scalar nu = problem.weight_sum - h_inverse.cwiseProduct(h2.transpose()).sum();",
           "const Scalar nu = problem.weight_sum - 2;",
           ["test_statistics"],
           "degrees of freedom N - 2 regardless of the weights"),
    Mutant("CV2", "include/bireg/statistics/inference/covariance.hpp",
           "return 1 - 2 * w * l.dot(in.h_inverse * l) + l.dot(in.leverage_matrix * l);",
           "return 1 - w * l.dot(in.h_inverse * l) + l.dot(in.leverage_matrix * l);",
           ["test_statistics"],
           "HC2 residual variance factor with the cross term halved"),
    Mutant("TT1", "include/bireg/statistics/inference/trend_test.hpp",
           "Scalar(1 + result.at_least_as_extreme) / Scalar(1 + options.permutations);",
           "Scalar(result.at_least_as_extreme) / Scalar(options.permutations);",
           ["test_statistics"],
           "permutation p-value without the +1 (can be 0)"),
    Mutant("RL1", "include/bireg/statistics/robust/loss.hpp",
           "      return one_minus * one_minus;",
           "      return one_minus;",
           ["test_robust"],
           "Tukey weight (1 - u^2) instead of (1 - u^2)^2"),
    Mutant("IO1", "include/bireg/io/formats.hpp",
           "if (tokens.size() != 8) return found(",
           "if (tokens.size() < 8) return found(",
           ["test_io"],
           "TUM column-count check accepts extra columns"),
    Mutant("IO2", "include/bireg/io/line_reader.hpp",
           "begin_ = scanned_ = filled_;\n        ++line_number_;",
           "begin_ = scanned_ = filled_;",
           ["test_io"],
           "a last line without newline is not counted (wrong line numbers)"),
    Mutant("IO3", "include/bireg/io/numbers.hpp",
           "if (errno == ERANGE && std::abs(value) > 1.0) {",
           "if (errno == ERANGE && std::abs(value) < 1.0) {",
           ["test_io"],
           "range check inverted: underflow refused, overflow not named"),
    Mutant("CL1", "tools/fit_run.hpp",
           "if (!result.ok() || (robust && !robust->ok())) {",
           "if (!result.ok() && (robust && !robust->ok())) {",
           ["test_fit_tool"],
           "exit code 0 for a fit that did not converge"),
    Mutant("CO1", "include/bireg/statistics/cohorts/two_sample.hpp",
           "G::Ad(G::exp(split.c / 2));",
           "G::Ad(G::exp(-split.c / 2));",
           ["test_cohorts"],
           "parallel transport from m_B to m_A with the wrong sign, Ad(exp(-c/2))"),
    Mutant("CO2", "include/bireg/statistics/cohorts/two_sample.hpp",
           "return Scalar(1 + at_least_as_extreme) / Scalar(1 + permutations);",
           "return Scalar(at_least_as_extreme) / Scalar(1 + permutations);",
           ["test_cohorts"],
           "the invalid permutation p-value #{T_b >= T} / (B + 1), which can be 0"),
    Mutant("CO3", "include/bireg/statistics/cohorts/elementwise.hpp",
           "const Scalar candidate = p[order[r]] * Scalar(k) / Scalar(r + 1);",
           "const Scalar candidate = p[order[r]] * Scalar(k) / Scalar(k);",
           ["test_cohort_maps"],
           "Benjamini-Hochberg without the rank (Bonferroni's K p instead)"),
    Mutant("CO4", "include/bireg/statistics/cohorts/two_sample.hpp",
           "permutation(options.seed, options.first_permutation + b, m + n, order);",
           "permutation(options.seed, b, m + n, order);",
           ["test_cohorts"],
           "every share of a test runs the first relabellings, not its own"),
    Mutant("CO5", "include/bireg/statistics/cohorts/elementwise.hpp",
           "std::max(result.relabelling_maximum[r], slice.relabelling_maximum[r]);",
           "std::min(result.relabelling_maximum[r], slice.relabelling_maximum[r]);",
           ["test_cohort_maps"],
           "joined slices keep the smallest maximum: family-wise p-values too small"),
    Mutant("SP1", "include/bireg/regression/spline/differentials.hpp",
           "b[0] * (first.left * right_jacobian_inverse<G>(anchor_scaled)) * G::Ad(product.suffix[1]);",
           "b[0] * (first.right * right_jacobian_inverse<G>(anchor_scaled)) * G::Ad(product.suffix[1]);",
           ["test_spline"],
           "the anchor's closed-form weight with J_r(Omega_1) for J_l(Omega_1)"),
    Mutant("SP2", "include/bireg/spline_regression.hpp",
           "partial.force[row + std::size_t(j)] += w * (differentials.weight[j] * residuals[i]);",
           "partial.force[row + std::size_t(j)] += differentials.weight[j] * residuals[i];",
           ["test_spline"],
           "weights dropped from the spline's estimating equations"),
    Mutant("SP3", "include/bireg/spline_regression.hpp",
           "blocks[std::size_t(l - j + k)].noalias() -= weighted * differentials.derivative[l];",
           "blocks[std::size_t(l - j + k)].noalias() -= weighted;",
           ["test_spline"],
           "the Gauss-Newton matrix without D_l (B_c B_l H kron I only at the identity)"),
    Mutant("SP4", "include/bireg/regression/spline/differentials.hpp",
           "g[m] = basis.cumulative_d1[m] * carry + G::ad(earlier) * e;",
           "g[m] = basis.cumulative_d1[m] * carry - G::ad(earlier) * e;",
           ["test_spline_inference"],
           "the suffixes' motion with the wrong sign in the velocity's differential (splines.md (11))"),
    Mutant("SP5", "include/bireg/statistics/inference/spline_covariance.hpp",
           "const Scalar nu = problem.weight_sum - trace;",
           "const Scalar nu = problem.weight_sum;",
           ["test_spline_inference"],
           "the noise covariance divided by W, not W - tr(H^{-1} H_2)"),
    Mutant("SP6", "include/bireg/statistics/inference/spline_covariance.hpp",
           "c.block(segment + std::size_t(j), segment + std::size_t(l)) *\n                       maps[std::size_t(l)].transpose();",
           "c.block(segment + std::size_t(j), segment + std::size_t(l)) *\n                       maps[std::size_t(j)].transpose();",
           ["test_spline_inference"],
           "a pointwise covariance with one control point's map on both sides"),
    Mutant("SD1", "include/bireg/math/symmetric_eigen.hpp",
           "v[at(k, q)] = s * vkp + c * vkq;",
           "v[at(k, q)] = s * vkp - c * vkq;",
           ["test_small_dense"],
           "an eigenvector rotation with the wrong sign (vectors no longer orthogonal)"),
    Mutant("SD2", "include/bireg/math/small_lu.hpp",
           "if (pivot[k] != k) std::swap(x[k], x[pivot[k]]);",
           "if (pivot[k] == k) std::swap(x[k], x[pivot[k]]);",
           ["test_small_dense"],
           "the right-hand side not permuted like the rows: a wrong solve whenever LU pivots"),
]


def run(cmd, cwd, log, check=True):
    """Runs cmd with its output appended to log; returns (exit code, output)."""
    proc = subprocess.run(cmd, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                          text=True, errors="replace")
    with open(log, "a") as out:
        out.write("\n$ " + " ".join(cmd) + "\n" + proc.stdout)
    if check and proc.returncode != 0:
        sys.exit(f"command failed ({proc.returncode}): {' '.join(cmd)}; see {log}")
    return proc.returncode, proc.stdout


def check_edits(root, mutants):
    """Every edit applies exactly once, or the run stops here."""
    bad = []
    for m in mutants:
        with open(os.path.join(root, m.path)) as f:
            text = f.read()
        count = text.count(m.old)
        if count != 1:
            bad.append(f"{m.name}: pattern found {count} times in {m.path}: {m.old!r}")
    if bad:
        sys.exit("mutation table out of date:\n  " + "\n  ".join(bad))


def main(argv):
    root = subprocess.check_output(["git", "rev-parse", "--show-toplevel"], text=True).strip()
    names = [a for a in argv if not a.startswith("--")]
    by_name = {m.name: m for m in MUTANTS}
    mutants = [by_name[n] for n in names if n in by_name] if names else list(MUTANTS)
    unknown = set(names) - {m.name for m in MUTANTS}
    if unknown:
        sys.exit(f"unknown mutants: {sorted(unknown)}")
    if "--list" in argv:
        for m in MUTANTS:
            print(f"{m.name}\t{m.path}\t{' '.join(m.targets)}\t{m.why}")
        return 0
    check_edits(root, mutants)
    if "--check" in argv:
        print(f"all {len(mutants)} edits apply")
        return 0

    scratch = os.environ.get("MUT_DIR", "/tmp/bireg-mutation")
    jobs = os.environ.get("MUT_JOBS", "1")
    build_type = os.environ.get("MUT_BUILD_TYPE", "Release")
    src, build = os.path.join(scratch, "src"), os.path.join(scratch, "build")
    log = os.path.join(scratch, "mutation.log")
    os.makedirs(src, exist_ok=True)
    # One run at a time per scratch directory: two would mutate each other's tree.
    lock = open(os.path.join(scratch, "lock"), "w")
    try:
        fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        sys.exit(f"another mutation check is running in {scratch}")
    open(log, "w").close()
    # The working tree's tracked files, as they are now (uncommitted edits
    # included); copy2 only where the content differs, so that an unchanged
    # scratch copy keeps its build.
    files = subprocess.check_output(["git", "ls-files", "-z"], cwd=root).decode().split("\0")
    for rel in filter(None, files):
        source, target = os.path.join(root, rel), os.path.join(src, rel)
        if not os.path.isfile(source):
            continue
        os.makedirs(os.path.dirname(target), exist_ok=True)
        if os.path.exists(target):
            with open(source, "rb") as a, open(target, "rb") as b:
                if a.read() == b.read():
                    continue
        shutil.copy2(source, target)
    if not os.path.exists(os.path.join(build, "build.ninja")):
        run(["cmake", "-S", src, "-B", build, "-G", "Ninja", f"-DCMAKE_BUILD_TYPE={build_type}",
             "-DBIREG_WERROR=ON", "-DBIREG_BUILD_BENCHMARKS=OFF", "-DBIREG_BUILD_EXAMPLES=OFF"],
            scratch, log)

    results = []
    for m in mutants:
        path = os.path.join(src, m.path)
        with open(path) as f:
            original = f.read()
        start = time.time()
        try:
            with open(path, "w") as f:
                f.write(original.replace(m.old, m.new, 1))
            built = run(["ninja", "-C", build, f"-j{jobs}"] + m.targets, scratch, log,
                        check=False)[0] == 0
            if not built:
                outcome = "error (did not build)"
            else:
                regex = m.regex or "^(" + "|".join(m.targets) + "):"
                rc, output = run(["ctest", "--test-dir", build, "-R", regex,
                                  "--output-on-failure", "-j", jobs, "--timeout", "600"],
                                 scratch, log, check=False)
                if "tests passed" not in output:  # none matched, or ctest itself failed
                    outcome = "error (no tests ran)"
                else:
                    outcome = "killed" if rc != 0 else "SURVIVED"
        finally:
            with open(path, "w") as f:
                f.write(original)
        minutes = (time.time() - start) / 60
        results.append((m, outcome, minutes))
        print(f"{m.name:5s} {outcome:22s} {minutes:5.1f} min  {m.path}: {m.why}", flush=True)

    killed = sum(1 for _, o, _ in results if o == "killed")
    survived = [m.name for m, o, _ in results if o == "SURVIVED"]
    errors = [m.name for m, o, _ in results if o.startswith("error")]
    print(f"\n{killed} killed, {len(survived)} survived {survived}, "
          f"{len(errors)} did not build {errors}; log: {log}")
    return 0 if not survived and not errors else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
