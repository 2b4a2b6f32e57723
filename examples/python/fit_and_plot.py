#!/usr/bin/env python3
"""Fit a bundled dataset from Python and draw its fitted sweeps with matplotlib.

    PYTHONPATH=build/python python3 examples/python/fit_and_plot.py \
        datasets/thesis-numerical/beam.yaml fit.png

Prints the estimates with their 95 % intervals and writes the figure: each
fitted sweep's measured dwells (up and down) and the model's amplitude beside
every dwell.
"""
import sys

import matplotlib
import matplotlib.pyplot as plt
import numpy as np

import dwellfit


def main(config, figure):
    result = dwellfit.identify(config)
    u = result["uncertainty"]
    print(f"status: {result['status']}; 95 % intervals: {u['interval_kind']}")
    for name, value in result["parameters"].items():
        print(f"  {name:6s} {value:14.8g}  [{u['ci95_low'][name]:.6g}, {u['ci95_high'][name]:.6g}]")

    p = result["predictions"]
    sweeps = np.array(p["sweep"])
    directions = np.array(p["direction"])
    fitted = sorted(set(sweeps[np.array(p["role"]) == "fitted"]))
    fig, axes = plt.subplots(1, len(fitted), figsize=(6 * len(fitted), 4.5), squeeze=False)
    for ax, sweep in zip(axes[0], fitted):
        frequency = len(set(p["freq_hz"][sweeps == sweep])) > 1
        x_name = "freq_hz" if frequency else "a_base"
        for direction, marker in (("up", "^"), ("down", "v")):
            rows = (sweeps == sweep) & (directions == direction)
            ax.plot(p[x_name][rows], p["a"][rows], marker, ms=4, ls="none",
                    label=f"{direction} dwells")
            ax.plot(p[x_name][rows], p["a_model"][rows], "-", lw=1, label=f"model, {direction}")
        ax.set_xlabel("drive frequency [Hz]" if frequency else "base level a_base")
        ax.set_ylabel("a")
        ax.set_title(sweep)
        ax.legend()
    fig.tight_layout()
    fig.savefig(figure, dpi=100)
    print(f"wrote {figure} (matplotlib {matplotlib.__version__})")
    return 0 if result["status"] == "converged" else 3


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    sys.exit(main(sys.argv[1], sys.argv[2]))
