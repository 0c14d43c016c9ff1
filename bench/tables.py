#!/usr/bin/env python3
"""Turns the JSON of bench/run_all.sh into the markdown tables of
bench/README.md and, if matplotlib is available, bench/tradeoff.png."""
import json
import os
import re
import sys


def medians(path):
    with open(path) as f:
        data = json.load(f)
    out = {}
    for b in data["benchmarks"]:
        if b.get("aggregate_name") == "median":
            out[b["run_name"]] = b
    return out


def fmt_time(seconds):
    for unit, scale in (("s", 1), ("ms", 1e-3), ("us", 1e-6), ("ns", 1e-9)):
        if seconds >= scale:
            return f"{seconds / scale:.3g} {unit}"
    return f"{seconds / 1e-9:.3g} ns"


def seconds(b):
    scale = {"ns": 1e-9, "us": 1e-6, "ms": 1e-3, "s": 1.0}[b["time_unit"]]
    return b["real_time"] * scale


def main(folder):
    groups = medians(os.path.join(folder, "groups.json"))
    runs = medians(os.path.join(folder, "regression.json"))

    floor = {}
    print("### Floor: one exp + one log + two compositions\n")
    print("| group | time |\n|---|---|")
    for name, b in groups.items():
        m = re.match(r"BM_ExpLogTwoCompositions<bireg::(\w+)<", name)
        if not m:  # the primitive benchmarks (SO3 exp, SE3 log, references)
            continue
        g = m.group(1)
        floor[g] = seconds(b)
        print(f"| {g} | {fmt_time(seconds(b))} |")

    print("\n### B1: time per observation and iteration (paper solver, N = 1000)\n")
    print("| group | method | time | x floor |\n|---|---|---|---|")
    for name, b in runs.items():
        m = re.match(r"BM_Cost<bireg::(\w+)<double>\s*>/(-?\d+)", name)
        if m:
            g, order = m.group(1), int(m.group(2))
            method = "exact" if order < 0 else ("series_adaptive" if order == 0 else f"series M={order}")
            t = b["time_per_obs_iter"]
            print(f"| {g} | {method} | {fmt_time(t)} | {t / floor[g]:.2f} |")

    print("\n### B3: solvers, SE(3), N = 100, noise 0.1, tolerance 1e-10\n")
    print("| length (rad) | solver | iterations | time | speed-up over paper |\n|---|---|---|---|---|")
    paper = {}
    for name, b in runs.items():
        m = re.match(r"BM_Solver/(\d)/(\d+)", name)
        if m:
            solver, length = int(m.group(1)), int(m.group(2)) / 10
            if solver == 0:
                paper[length] = seconds(b)
    for name, b in runs.items():
        m = re.match(r"BM_Solver/(\d)/(\d+)", name)
        if m:
            solver, length = int(m.group(1)), int(m.group(2)) / 10
            label = b.get("label", str(solver))
            print(f"| {length} | {label} | {int(b['iterations'])} | {fmt_time(seconds(b))} | "
                  f"{paper[length] / seconds(b):.1f}x |")

    print("\n### B4: scaling in N (SE(3), default options)\n")
    print("| N | time per fit | iterations | time per observation-iteration |\n|---|---|---|---|")
    for name, b in runs.items():
        m = re.match(r"BM_Scaling/(\d+)", name)
        if m:
            print(f"| {int(m.group(1)):.0e} | {fmt_time(seconds(b))} | {int(b['iterations'])} | "
                  f"{fmt_time(b['time_per_obs_iter'])} |")

    print("\n### B5: float against double (SE(3), N = 1000, length 1.5, noise 0.05)\n")
    print("| scalar | time per fit | iterations | endpoint error vs long double |\n|---|---|---|---|")
    for name, b in runs.items():
        m = re.match(r"BM_Precision<(\w+)>", name)
        if m:
            print(f"| {m.group(1)} | {fmt_time(seconds(b))} | {int(b['iterations'])} | {b['endpoint_error']:.2e} |")

    print("\n### B6: every group, per observation and iteration (paper solver, N = 1000, length 1)\n")
    print("| group | time per observation-iteration | vs SE3 |\n|---|---|---|")
    scene = {}
    for name, b in runs.items():
        if name.startswith("BM_Scene<"):
            scene[b.get("label", name)] = b["time_per_obs_iter"]
    for label, t in scene.items():
        print(f"| {label} | {fmt_time(t)} | {t / scene['SE3']:.2f} |")

    print("\n### B2: accuracy against time (N = 100, noise 0.05, gauss_newton)\n")
    print("| group | length | method | tolerance | endpoint error | time |\n|---|---|---|---|---|---|")
    points = []
    for name, b in runs.items():
        m = re.match(r"BM_Tradeoff/(\w+)/len([\d.]+)/(\w+)/tol([\de+-]+)", name)
        if m:
            g, length, method, tol = m.group(1), float(m.group(2)), m.group(3), m.group(4)
            points.append((g, length, method, tol, b["endpoint_error"], seconds(b)))
            print(f"| {g} | {length} | {method} | {tol} | {b['endpoint_error']:.1e} | {fmt_time(seconds(b))} |")

    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("\n(matplotlib not available: no plot)")
        return
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2), sharey=True)
    markers = {0.5: "o", 1.5: "s", 3.0: "^"}
    methods = sorted({p[2] for p in points})
    colours = dict(zip(methods, plt.rcParams["axes.prop_cycle"].by_key()["color"]))
    for ax, g in zip(axes, ("SO3", "SE3")):
        for p in points:
            if p[0] != g:
                continue
            ax.scatter(p[5] * 1e6, max(p[4], 1e-17), marker=markers[p[1]], color=colours[p[2]], s=28)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_title(f"{g}: endpoint error vs fit time (N = 100)")
        ax.set_xlabel("time per fit [us]")
        ax.grid(True, which="both", alpha=0.3)
    axes[0].set_ylabel("max |endpoint - long double reference|")
    for m in methods:
        axes[1].scatter([], [], color=colours[m], label=m)
    for length, marker in markers.items():
        axes[1].scatter([], [], color="grey", marker=marker, label=f"length {length} rad")
    axes[1].legend(fontsize=8, loc="upper right")
    fig.tight_layout()
    out = os.path.join(os.path.dirname(os.path.abspath(__file__)), "tradeoff.png")
    fig.savefig(out, dpi=110)
    print(f"\nplot: {out}")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "bench/results")
