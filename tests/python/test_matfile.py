"""MATLAB files in and out (docs/matlab.md), written and read by SciPy.

A dataset's sweeps CSV saved as a .mat by scipy.io.savemat (v5) is identified
by the identify tool to the CSV run's result.yaml, byte for byte once the data
file's path is replaced: Python's float() and the CSV reader's from_chars both
round the CSV's decimal text correctly, so the .mat holds the same doubles,
the MAT reader hands them over as round-trip text, and the fit is
deterministic. result.mat, read back by scipy.io.loadmat, holds the numbers
of result.yaml and of the CSVs, exactly (result.yaml prints 17 digits).

Run by CTest (matfile_scipy, and python_module when the module is built) with
DWELLFIT_IDENTIFY naming the identify tool and DWELLFIT_SOURCE_DIR the source.
"""
import csv
import math
import os
import re
import subprocess

import numpy as np
import pytest
import scipy.io
import yaml

SOURCE = os.environ["DWELLFIT_SOURCE_DIR"]
IDENTIFY = os.environ["DWELLFIT_IDENTIFY"]
DATASETS = {
    "thesis-numerical": "beam.yaml",
    "clamped-beam-27C": "beam-selected.yaml",
}
TEXT_COLUMNS = ("sweep", "direction")


def save_sweeps_mat(csv_path, mat_path):
    """The CSV's columns as MAT variables: cell arrays of text, double columns."""
    with open(csv_path, newline="") as f:
        rows = list(csv.DictReader(f))
    variables = {}
    for name in rows[0]:
        if name in TEXT_COLUMNS:
            cells = np.empty((len(rows), 1), dtype=object)
            for i, row in enumerate(rows):
                cells[i, 0] = row[name]
            variables[name] = cells
        else:
            variables[name] = np.array([[float(row[name])] for row in rows])
    scipy.io.savemat(mat_path, variables)


def identify(config, out_dir, *flags):
    return subprocess.run([IDENTIFY, "--config", config, "--output_dir", str(out_dir),
                           "--figures=false", *flags], capture_output=True, text=True)


def valid_name(name, taken):
    """estimator/matfile/result_mat.h: a key as a MATLAB identifier."""
    valid = re.sub(r"[^A-Za-z0-9]", "_", name)
    if not valid or not valid[0].isalpha():
        valid = "x" + valid
    valid = valid[:63]
    unique, n = valid, 2
    while unique in taken:
        unique, n = f"{valid}_{n}", n + 1
    taken.add(unique)
    return unique


def as_list(value):
    """A loadmat cell or vector as a list (simplify_cells squeezes one element)."""
    if isinstance(value, np.ndarray):
        return list(value.ravel()) if value.dtype != object else list(value.ravel())
    return value if isinstance(value, list) else [value]


def same_number(expected, actual):
    expected = float(expected)
    actual = float(actual)
    return expected == actual or (math.isnan(expected) and math.isnan(actual))


def assert_same(expected, actual, where):
    """result.yaml's value `expected` equals result.mat's `actual`."""
    if isinstance(expected, dict):
        taken = set()
        assert isinstance(actual, dict), where
        names = {valid_name(str(key), taken): key for key in expected}
        assert set(names) == set(actual), where
        for name, key in names.items():
            assert_same(expected[key], actual[name], f"{where}.{key}")
    elif isinstance(expected, list):
        actual = as_list(actual)
        assert len(actual) == len(expected), where
        for i, (e, a) in enumerate(zip(expected, actual)):
            assert_same(e, a, f"{where}[{i}]")
    elif expected is None:
        assert isinstance(actual, np.ndarray) and actual.size == 0, where
    elif isinstance(expected, bool):  # a logical, which loadmat reads as uint8
        assert np.asarray(actual).dtype.kind in "iu" and int(actual) == int(expected), where
    elif isinstance(expected, (int, float)):
        assert same_number(expected, actual), (where, expected, actual)
    else:  # text; PyYAML reads 1e+20 (no '.') as text, the MAT file as a number
        if isinstance(actual, str):
            assert actual == expected, where
        else:
            assert same_number(expected, actual), (where, expected, actual)


def assert_csv_in_mat(csv_path, struct, where):
    with open(csv_path, newline="") as f:
        rows = list(csv.DictReader(f))
    assert set(struct) == set(rows[0]), where
    for name in rows[0]:
        values = as_list(struct[name])
        assert len(values) == len(rows), (where, name)
        for row, value in zip(rows, values):
            if isinstance(value, np.ndarray) and value.size == 0:  # '' in a text column
                assert row[name] == "", (where, name)
            elif isinstance(value, str):
                assert value == row[name], (where, name)
            elif row[name] == "":
                assert math.isnan(value), (where, name)
            else:
                assert same_number(row[name], value), (where, name, row[name], value)


@pytest.mark.parametrize("dataset", sorted(DATASETS))
def test_a_savemat_file_identifies_as_its_csv(dataset, tmp_path):
    folder = os.path.join(SOURCE, "datasets", dataset)
    config = os.path.join(folder, DATASETS[dataset])
    csv_path = os.path.join(folder, "sweeps.csv")
    mat_path = str(tmp_path / "sweeps.mat")
    save_sweeps_mat(csv_path, mat_path)

    from_csv = identify(config, tmp_path / "csv")
    from_mat = identify(config, tmp_path / "mat", f"--set=data={mat_path}", "--mat")
    assert from_csv.returncode == 0, from_csv.stderr
    assert from_mat.returncode == 0, from_mat.stderr
    for name in ("result.yaml", "predictions.csv", "curves.csv"):
        expected = (tmp_path / "csv" / name).read_text()
        actual = (tmp_path / "mat" / name).read_text().replace(mat_path, csv_path)
        assert actual == expected, name
    assert not (tmp_path / "csv" / "result.mat").exists()

    result_yaml = yaml.safe_load((tmp_path / "mat" / "result.yaml").read_text())
    mat = scipy.io.loadmat(tmp_path / "mat" / "result.mat", simplify_cells=True)
    variables = {key: value for key, value in mat.items() if not key.startswith("__")}
    taken = set()
    for key, value in result_yaml.items():
        assert_same(value, variables[valid_name(key, taken)], key)
    csv_names = sorted(name for name in os.listdir(tmp_path / "mat") if name.endswith(".csv"))
    assert {"predictions.csv", "curves.csv", "modal_properties.csv"} <= set(csv_names)
    for name in csv_names:
        stem = valid_name(name[:-len(".csv")] + "_csv", taken)
        assert_csv_in_mat(tmp_path / "mat" / name, variables[stem], name)
    assert set(variables) == taken
    classes = {name: kind for name, _, kind in scipy.io.whosmat(tmp_path / "mat" / "result.mat")}
    assert classes["converged"] == "logical" and classes["status"] == "char"
    assert "result.mat" in (tmp_path / "mat" / "manifest.yaml").read_text()


def test_the_config_key_writes_result_mat(tmp_path):
    config = os.path.join(SOURCE, "datasets", "thesis-numerical", "beam.yaml")
    run = identify(config, tmp_path, "--set=outputs.mat=true")
    assert run.returncode == 0, run.stderr
    mat = scipy.io.loadmat(tmp_path / "result.mat", simplify_cells=True)
    result_yaml = yaml.safe_load((tmp_path / "result.yaml").read_text())
    assert mat["status"] == result_yaml["status"] == "converged"


def test_a_bad_mat_file_is_named_with_its_variable_and_row(tmp_path):
    csv_path = os.path.join(SOURCE, "datasets", "thesis-numerical", "sweeps.csv")
    mat_path = str(tmp_path / "sweeps.mat")
    save_sweeps_mat(csv_path, mat_path)
    variables = scipy.io.loadmat(mat_path)
    variables["a"][4, 0] = np.inf
    scipy.io.savemat(mat_path, {k: v for k, v in variables.items() if not k.startswith("__")})
    config = os.path.join(SOURCE, "datasets", "thesis-numerical", "beam.yaml")
    run = identify(config, tmp_path / "out", f"--set=data={mat_path}")
    assert run.returncode == 1
    assert f"{mat_path}: variable 'a', row 5: value 'inf' is not finite" in run.stderr
