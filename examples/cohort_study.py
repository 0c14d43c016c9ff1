"""Writes examples/data/cohort_study/: a simulated longitudinal study for
bireg_compare (README "Comparing cohorts"). Two cohorts of 10 subjects,
each seen at 6 visits a year apart (times in years since a common
baseline, each subject's first visit 0-0.5 years in), its knee orientation
an SO(3) trajectory: the subject's own start, a cohort drift of 0.10 rad
per year about x (grade 3: also 0.015 rad per year about z), and 0.02 rad
of measurement noise per axis. numpy only; seeded, so the files do not
change from run to run.

    python3 examples/cohort_study.py
"""

import pathlib

import numpy as np


def so3_exp(w):
    theta = np.linalg.norm(w)
    k = np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])
    if theta < 1e-12:
        return np.eye(3) + k
    return (np.eye(3) + np.sin(theta) / theta * k
            + (1 - np.cos(theta)) / theta**2 * k @ k)


def main():
    out = pathlib.Path(__file__).parent / "data" / "cohort_study"
    out.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(20261127)
    drift = {"healthy": np.array([0.10, 0.0, 0.0]), "grade 3": np.array([0.10, 0.0, 0.015])}
    rows = ["path,cohort,subject"]
    for cohort, rate in drift.items():
        for s in range(10):
            subject = f"{cohort.replace(' ', '')}_{s:02d}"
            start = so3_exp(0.15 * rng.standard_normal(3))
            first = rng.uniform(0.0, 0.5)
            lines = []
            for visit in range(6):
                t = first + visit
                r = start @ so3_exp(t * rate + 0.02 * rng.standard_normal(3))
                lines.append(", ".join([f"{t:.4f}"] + [f"{x:.9f}" for x in r.ravel()]))
            (out / f"{subject}.csv").write_text("\n".join(lines) + "\n")
            rows.append(f"{subject}.csv,{cohort},{subject}")
    (out / "manifest.csv").write_text("\n".join(rows) + "\n")


if __name__ == "__main__":
    main()
