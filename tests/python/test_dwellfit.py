"""The Python module against the command-line tool and the model's equations.

Run by CTest (python_module) with PYTHONPATH at <build>/python and
DWELLFIT_IDENTIFY naming the identify tool of the same build.
"""
import math
import os
import subprocess
import threading

import numpy as np
import pytest

import dwellfit

SOURCE = os.environ["DWELLFIT_SOURCE_DIR"]
IDENTIFY = os.environ["DWELLFIT_IDENTIFY"]
THESIS = os.path.join(SOURCE, "datasets", "thesis-numerical", "beam.yaml")
BEAM = os.path.join(SOURCE, "datasets", "clamped-beam-27C", "beam-selected.yaml")


def tool_files(config, out_dir):
    subprocess.run([IDENTIFY, "--config", config, "--output_dir", str(out_dir),
                    "--figures=false"], check=True, capture_output=True)
    return {name: open(os.path.join(out_dir, name), "rb").read()
            for name in ("result.yaml", "predictions.csv", "curves.csv")}


@pytest.mark.parametrize("config", [THESIS, BEAM], ids=["thesis-numerical", "clamped-beam-27C"])
def test_identify_equals_the_tool_to_the_last_bit(config, tmp_path):
    expected = tool_files(config, tmp_path / "tool")
    result = dwellfit.identify(config)
    for name, content in expected.items():
        assert result["files"][name] == content, name
    assert result["status"] == "converged"
    # The numbers returned are those of result.yaml (round-trip text).
    text = expected["result.yaml"].decode()
    for name, value in result["parameters"].items():
        assert repr(value) in text or f"{value:.17g}" in text, name


def test_identify_writes_what_the_tool_writes(tmp_path):
    expected = tool_files(THESIS, tmp_path / "tool")
    dwellfit.identify(THESIS, output_dir=tmp_path / "module")
    for name, content in expected.items():
        assert (tmp_path / "module" / name).read_bytes() == content, name
    assert (tmp_path / "module" / "report.html").exists()


THESIS_DICT = {
    "data": "sweeps.csv",
    "fit": ["F0.01", "A41.5"],
    "validate": ["A41.2", "A41.8"],
    "residual": {"error": "relative"},
}


def test_a_dict_config_fits_as_the_same_yaml_file(tmp_path):
    base = os.path.join(SOURCE, "datasets", "thesis-numerical")
    yaml = tmp_path / "same.yaml"
    yaml.write_text("data: " + os.path.join(base, "sweeps.csv") + "\n"
                    "fit: [F0.01, A41.5]\nvalidate: [A41.2, A41.8]\n"
                    "residual: {error: relative}\noutput_dir: out\n")
    from_dict = dwellfit.identify(THESIS_DICT, base_dir=base)
    from_file = dwellfit.identify(yaml)
    assert from_dict["status"] == "converged"
    assert from_dict["parameters"] == from_file["parameters"]
    assert from_dict["uncertainty"]["ci95_low"] == from_file["uncertainty"]["ci95_low"]


def test_a_bad_config_raises_naming_the_field():
    config = dict(THESIS_DICT, solver={"max_iterations": -3})
    base = os.path.join(SOURCE, "datasets", "thesis-numerical")
    with pytest.raises(dwellfit.InputError, match="max_iterations"):
        dwellfit.identify(config, base_dir=base)
    with pytest.raises(ValueError, match="no_such_key"):
        dwellfit.identify(dict(THESIS_DICT, no_such_key=1), base_dir=base)
    with pytest.raises(dwellfit.InputError, match="solver.max_iterations"):
        dwellfit.identify(THESIS, overrides={"solver.max_iterations": -1})


def test_the_fit_releases_the_gil():
    counts = []
    done = threading.Event()

    def count():
        n = 0
        while not done.is_set():
            n += 1
        counts.append(n)

    thread = threading.Thread(target=count)
    thread.start()
    dwellfit.identify(BEAM)
    done.set()
    thread.join()
    assert counts[0] > 100000


def test_load_sweeps_reads_every_dwell():
    path = os.path.join(SOURCE, "datasets", "thesis-numerical", "sweeps.csv")
    sweeps = dwellfit.load_sweeps(path)
    rows = sum(1 for line in open(path) if line.strip()) - 1
    assert len(sweeps["sweep"]) == rows == sweeps["a"].shape[0]
    assert set(sweeps["direction"]) == {"up", "down"}
    with pytest.raises(dwellfit.InputError, match="no_such.csv"):
        dwellfit.load_sweeps("no_such.csv")


TRUTH = {"eta_e": 100.0, "mu1": 0.2, "mu2": 300.0, "delta": 1e4, "alpha": 9e8,
         "omega": 2 * math.pi * 40}


def test_the_curve_solves_the_frequency_response_equation():
    """Every point satisfies P(a)^2 + Q(a)^2 = a_b^2 (docs/model.md, eqs. 3.1-3.3, 3.11)."""
    a_base = 0.01
    curve = dwellfit.curve(TRUTH, "frequency", a_base, 38.0, 45.0)
    p = TRUTH
    for f, a in zip(curve["freq_hz"], curve["a"]):
        omega = 2 * math.pi * f
        k1 = omega * p["mu1"] / p["eta_e"]
        k2 = 4 * p["mu2"] * omega / (3 * math.pi * p["eta_e"])
        k3 = -(omega ** 2 - p["omega"] ** 2) / (2 * p["eta_e"])
        k4 = (3 * p["alpha"] - 2 * p["delta"] * omega ** 2) / (8 * p["eta_e"])
        g = (k1 * a + k2 * a * a) ** 2 + (k3 * a + k4 * a ** 3) ** 2
        assert g == pytest.approx(a_base ** 2, rel=1e-8)
    # Two folds (each ends one run of stability and starts the next).
    assert len(set(np.round(curve["freq_hz"][curve["fold"]], 9))) == 2
    assert curve["stable"].any() and not curve["stable"].all()
    assert curve["stable"].dtype == curve["fold"].dtype == np.bool_
    assert all(len(curve[name]) == len(curve["a"]) for name in ("freq_hz", "a_base", "phase_rad"))


def test_a_members_curve_solves_its_frequency_response_equation():
    """mu3 and alpha5 choose the member (docs/model.md, "Terms beyond the chapter's"):
    P = k1 a + k5 a^3, Q = k3 a + k4 a^3 + k6 a^5, k5 = Omega mu3 / (4 eta_e),
    k6 = 5 alpha5 / (16 eta_e)."""
    member = {"eta_e": 100.0, "mu1": 0.2, "mu3": 1e5, "alpha5": 2e13, "alpha": 9e8,
              "omega": 2 * math.pi * 40}
    a_base = 0.01
    curve = dwellfit.curve(member, "frequency", a_base, 38.0, 60.0)
    p = member
    for f, a in zip(curve["freq_hz"], curve["a"]):
        omega = 2 * math.pi * f
        k1 = omega * p["mu1"] / p["eta_e"]
        k5 = omega * p["mu3"] / (4 * p["eta_e"])
        k3 = -(omega ** 2 - p["omega"] ** 2) / (2 * p["eta_e"])
        k4 = 3 * p["alpha"] / (8 * p["eta_e"])
        k6 = 5 * p["alpha5"] / (16 * p["eta_e"])
        g = (k1 * a + k5 * a ** 3) ** 2 + (k3 * a + k4 * a ** 3 + k6 * a ** 5) ** 2
        assert g == pytest.approx(a_base ** 2, rel=1e-8)
    assert len(set(np.round(curve["freq_hz"][curve["fold"]], 9))) == 2
    with pytest.raises(dwellfit.InputError, match="alternatives"):
        dwellfit.curve(dict(member, mu2=300.0), "frequency", a_base, 38.0, 46.0)


def test_simulate_makes_the_plans_dwells():
    plan = os.path.join(SOURCE, "datasets", "thesis-numerical", "plan.yaml")
    sweeps = dwellfit.simulate(plan)
    assert len(sweeps["sweep"]) == sweeps["freq_hz"].shape[0] > 100
    assert np.all(sweeps["a"] > 0)


def test_next_dwell_ranks_as_the_tool(tmp_path):
    tool = os.path.join(os.path.dirname(IDENTIFY), "next_dwell")
    state = "f_hz=41.5,level=0.01,branch=upper"
    limits = "f_step_max_hz=2,level_step_max=0.01"
    subprocess.run([tool, "--config", THESIS, "--state", state, "--limits", limits,
                    "--noise_sigma", "0.01", "--figures=false", "--output_dir", str(tmp_path)],
                   check=True, capture_output=True)
    lines = open(tmp_path / "next_dwell.csv").read().splitlines()
    header = lines[0].split(",")
    rows = [dict(zip(header, line.split(","))) for line in lines[1:]]
    result = dwellfit.next_dwell(THESIS, {"f_hz": 41.5, "level": 0.01, "branch": "upper"},
                                 limits={"f_step_max_hz": 2, "level_step_max": 0.01},
                                 noise_sigma=0.01)
    assert result["status"] == "converged"
    candidates = result["candidates"]
    assert len(candidates["freq_hz"]) == len(rows)
    # Every column, one entry per candidate, as next_dwell.csv has it (10
    # significant digits; settle_s 6).
    numbers = {"freq_hz": ("f_hz", 1e-9), "level": ("level", 1e-9), "a": ("amplitude", 1e-9),
               "settle_seconds": ("settle_s", 1e-5), "record_seconds": ("record_s", 1e-5),
               "gain": ("gain", 1e-9), "gain_per_second": ("gain_per_s", 1e-9)}
    for name, (column, rel) in numbers.items():
        assert candidates[name] == pytest.approx([float(r[column]) for r in rows], rel=rel), name
    assert candidates["branch"] == [r["branch"] for r in rows]
    assert candidates["dwells"].tolist() == [int(r["dwells"]) for r in rows]
    assert candidates["jumps"].tolist() == [r["jumps"] == "1" for r in rows]
    assert np.all(np.diff(candidates["gain_per_second"]) <= 0)
    with pytest.raises(dwellfit.InputError, match="level"):
        dwellfit.next_dwell(THESIS, "f_hz=41.5")


def test_load_sweeps_gives_the_optional_columns_and_nan_where_absent(tmp_path):
    path = tmp_path / "sweeps.csv"
    path.write_text("sweep,direction,freq_hz,a_base,a,sigma,a_base_sigma,phase_rad\n"
                    "F1,up,40.0,0.01,2e-4,3e-6,5e-5,0.25\n"
                    "F1,up,40.5,0.01,3e-4,4e-6,5e-5,0.5\n"
                    "A1,up,41.0,0.02,4e-4,6e-6,1e-4,1.0\n")
    sweeps = dwellfit.load_sweeps(path)
    assert list(sweeps["sigma"]) == [3e-6, 4e-6, 6e-6]
    assert list(sweeps["a_base_sigma"]) == [5e-5, 5e-5, 1e-4]
    assert list(sweeps["phase_rad"]) == [0.25, 0.5, 1.0]
    thesis = dwellfit.load_sweeps(os.path.join(SOURCE, "datasets", "thesis-numerical", "sweeps.csv"))
    for column in ("sigma", "a_base_sigma"):
        assert thesis[column].shape == thesis["a"].shape
        assert np.isnan(thesis[column]).all(), column
    assert np.isfinite(thesis["phase_rad"]).all()


def test_load_sweeps_reads_a_mat_file_as_its_csv(tmp_path):
    scipy_io = pytest.importorskip("scipy.io")
    path = os.path.join(SOURCE, "datasets", "thesis-numerical", "sweeps.csv")
    lines = open(path).read().splitlines()
    header = lines[0].split(",")
    rows = [line.split(",") for line in lines[1:]]
    variables = {}
    for k, name in enumerate(header):
        if name in ("sweep", "direction"):
            cells = np.empty((len(rows), 1), dtype=object)  # a cell array of text
            for i, row in enumerate(rows):
                cells[i, 0] = row[k]
            variables[name] = cells
        else:
            variables[name] = np.array([[float(row[k])] for row in rows])
    scipy_io.savemat(tmp_path / "sweeps.mat", variables)
    from_csv = dwellfit.load_sweeps(path)
    from_mat = dwellfit.load_sweeps(tmp_path / "sweeps.mat")
    assert from_mat["sweep"] == from_csv["sweep"]
    for column in ("freq_hz", "a_base", "a"):
        np.testing.assert_array_equal(from_mat[column], from_csv[column])
