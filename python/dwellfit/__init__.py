"""dwellfit from Python: identify the parameters of a nonlinear single-mode
model from sine-dwell sweeps, with the same pipeline and the same results as
the `identify` command-line tool (docs/python.md).

    import dwellfit
    result = dwellfit.identify("datasets/thesis-numerical/beam.yaml")
    result["parameters"]["eta_e"], result["uncertainty"]["ci95_low"]["eta_e"]

A config is a YAML file or a dict with the same keys; a bad one raises
dwellfit.InputError naming the field. The computation releases the GIL.
"""
import json
import os

from ._dwellfit import InputError, __version__
from . import _dwellfit

__all__ = ["InputError", "identify", "load_sweeps", "next_dwell", "curve", "simulate",
           "__version__"]


def _overrides(overrides):
    """{"solver.max_iterations": 50} or [("key", "value")] as (key, YAML text) pairs."""
    items = overrides.items() if isinstance(overrides, dict) else (overrides or [])
    return [(str(key), value if isinstance(value, str) else json.dumps(value))
            for key, value in items]


def identify(config, *, overrides=None, output_dir=None, figures=False, base_dir="."):
    """Runs identify on `config` (a path, or a dict of the config's keys whose
    relative paths are taken from `base_dir`).

    Returns a dict: status and message, parameters (omega in rad/s), fixed,
    final_cost, uncertainty (standard errors, 95 % intervals and their kind,
    warnings, alpha_e), predictions (columns: sweep, direction, role, freq_hz,
    a_base, a, a_model, branch), printed (identify's summary) and files (the
    run's files by name, as bytes: result.yaml, predictions.csv, curves.csv,
    figures.gp, report.html and, with figures=True, the images). With
    `output_dir` the files are also written there, as identify writes them.
    """
    pairs = _overrides(overrides)
    write = output_dir is not None
    if write:
        pairs.append(("output_dir", json.dumps(os.fspath(output_dir))))
    if isinstance(config, dict):
        config = dict(config)
        config.setdefault("output_dir", "dwellfit-output")
        text = json.dumps(config, indent=2)
        return _dwellfit.identify("<dict>", text, os.fspath(base_dir), pairs, write, figures)
    return _dwellfit.identify(os.fspath(config), "", "", pairs, write, figures)


def load_sweeps(path):
    """The dwells of a sweeps CSV or .mat file (docs/matlab.md) as columns (sweep, direction, kind: lists;
    freq_hz, a_base, a, and the optional sigma, a_base_sigma, phase_rad: NumPy arrays, NaN where the
    file gives none), checked as identify checks them."""
    return _dwellfit.load_sweeps(os.fspath(path))


def _key_values(value):
    """{"f_hz": 41.5, "branch": "upper"} as "f_hz=41.5,branch=upper"; text as is."""
    if isinstance(value, dict):
        return ",".join(f"{key}={item}" for key, item in value.items())
    return value or ""


def next_dwell(config, state, *, limits=None, target="d_optimal", noise_sigma=0.0,
               segment_dwells=1, settle_time_constants=5.0, recording_seconds=2.0,
               overrides=None, base_dir="."):
    """Where to dwell next (docs/next-dwell.md), as the next_dwell tool: fits
    `config` (a path or a dict, as identify) and ranks the candidate dwells
    from `state` (dict or text: f_hz, level, branch) within `limits` (dict or
    text: f_min_hz, f_max_hz, f_step_min_hz, f_step_max_hz, level_min,
    level_max, level_step_min, level_step_max; the rest from the fitted
    sweeps) by the expected gain in `target` per second of test time.

    Returns a dict: status, message, parameters, target, printed (the tool's
    summary) and candidates, best first (columns: freq_hz, level, dwells,
    branch, jumps, a, settle_seconds, record_seconds, gain, gain_per_second).
    """
    args = (_key_values(state), _key_values(limits), target, float(noise_sigma),
            int(segment_dwells), float(settle_time_constants), float(recording_seconds))
    pairs = _overrides(overrides)
    if isinstance(config, dict):
        config = dict(config)
        config.setdefault("output_dir", "dwellfit-output")
        return _dwellfit.next_dwell("<dict>", json.dumps(config, indent=2), os.fspath(base_dir),
                                    pairs, *args)
    return _dwellfit.next_dwell(os.fspath(config), "", "", pairs, *args)


def curve(parameters, kind, held, low, high, points_per_side=400, averaging="first_order"):
    """The model's response curve at `parameters` (a dict of eta_e, mu1, mu2,
    delta, alpha, omega; omega in rad/s; mu3 for mu2 or alpha5 for delta choose
    a member of the family, docs/model.md): kind="frequency" at base level
    `held` from `low` to `high` Hz, or kind="amplitude" at `held` Hz from
    base level `low` to `high`. `averaging`: "first_order" (the chapter's
    model) or "second_order" (docs/model.md). Columns: freq_hz, a_base, a,
    phase_rad, stable, fold (NumPy arrays), in tracing order."""
    return _dwellfit.curve(dict(parameters), kind, float(held), float(low), float(high),
                           int(points_per_side), str(averaging))


def simulate(plan):
    """The dwells a dwell plan makes (a plan YAML file, or a dict of its keys),
    as load_sweeps returns them."""
    if isinstance(plan, dict):
        return _dwellfit.simulate("<dict>", json.dumps(plan, indent=2))
    return _dwellfit.simulate(os.fspath(plan), "")
