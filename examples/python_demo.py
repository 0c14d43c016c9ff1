"""The Python face of bireg_demo: the geodesic fitted to the two real
trajectories shipped in examples/data, with the same figures.

    python examples/python_demo.py [DATA_DIR]
"""

import sys
import time

import numpy as np

import bireg

DEGREES = 180.0 / np.pi


def report(title, group, path):
    data = bireg.read_trajectory(path, group=group)
    t, Y = data["t"], data["Y"]
    start = time.perf_counter()
    reg = bireg.GeodesicRegression(group=group).fit(t, Y)
    milliseconds = 1e3 * (time.perf_counter() - start)
    d = reg.diagnostics_
    w = reg.body_velocity_[-3:]  # the rotation part: last three coordinates
    print(f"{title} ({group}, {len(t)} samples over {t.max() - t.min():.2f} s)")
    if group == "SE3":
        print(f"  fitted linear velocity    {np.linalg.norm(reg.body_velocity_[:3]):.3f} m/s "
              "(body frame)")
    print(f"  fitted angular velocity   {np.linalg.norm(w) * DEGREES:.1f} deg/s")
    print(f"  residual RMS              {d['residual_rms_about_mean']:.4f} before (about the "
          f"mean), {d['residual_rms']:.4f} after (tangent norm)")
    print(f"  explained variance        {d['explained_variance']:.4f}")
    print(f"  iterations                {reg.n_iter_} (status {reg.status_})")
    print(f"  time                      {milliseconds:.3f} ms for the first fit")
    band = reg.confidence_band(np.linspace(*reg.interval_, 50), level=0.95)
    se = reg.covariance("robust")["velocity_standard_errors"]
    print(f"  95% confidence band       +-{band[:, -3:].max() * DEGREES:.2f} deg at most; "
          f"angular velocity s.e. {se[-3:].max() * DEGREES:.2f} deg/s at most")
    print()


def main():
    data = sys.argv[1] if len(sys.argv) > 1 else "examples/data"
    report("x-IMU orientation", "SO3", f"{data}/so3_xio_imu_window.csv")
    report("DeepMimic walk, pelvis pose", "SE3", f"{data}/se3_deepmimic_walk.tum")


if __name__ == "__main__":
    main()
