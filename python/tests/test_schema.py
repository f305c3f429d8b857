"""One run per model through its binary and through Python (same parameters and seed), both
checked against the output schema the libraries declare (``aggsim._schema``, the tables of
docs/outputs.md) and against each other: the CSV headers, the ``.npy`` dtypes and shapes and
the Python keys, attributes and dtypes are the schema's, and the values are equal (all but
wall-clock measurements)."""

import csv
import re

import numpy as np
import pytest

import aggsim

INTEGER = re.compile(r"-?[0-9]+")


def read_csv(path):
    """The header and the columns (as text) of a CSV file."""
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    header, body = rows[0], rows[1:]
    return header, {name: [r[k] for r in body] for k, name in enumerate(header)}


def parse(text, column):
    """A CSV column's text as the schema's dtype; coded columns are written as their names."""
    dtype = np.dtype(column["dtype"])
    if column["labels"] is not None:
        names = column["labels"]
        assert set(text) <= set(names), (column["name"], set(text))
        return np.array([names.index(t) for t in text], dtype=dtype)
    if dtype == np.bool_:
        assert set(text) <= {"true", "false"}, column["name"]
        return np.array([t == "true" for t in text])
    if dtype.kind in "iu":
        bad = [t for t in text if not INTEGER.fullmatch(t)]
        assert not bad, f"{column['name']}: {bad[:3]} are not integers"
        return np.array([int(t) for t in text], dtype=dtype)
    # An empty field is a value that does not exist (NaN in Python).
    return np.array([float(t) if t else np.nan for t in text], dtype=dtype)


def axes(form, dim):
    if form["axes"] == "numbered":
        return [f"x{a + 1}" for a in range(dim)]
    return ["x", "y", "z", "w", "v"][:dim]


def check_csv(out, output, result):
    """A CSV file and the Python dict of arrays holding the same columns."""
    columns = output["columns"]
    names = [c["name"] for c in columns]
    header, text = read_csv(out / output["file"])
    assert header == names, output["file"]
    table = getattr(result, output["python"])
    assert table is not None, output["python"]
    assert list(table) == names, output["python"]
    for c in columns:
        py = table[c["name"]]
        assert py.dtype == np.dtype(c["dtype"]), (output["python"], c["name"], py.dtype)
        values = parse(text[c["name"]], c)
        assert py.shape == values.shape, c["name"]
        if not c["measured"]:
            np.testing.assert_array_equal(py, values, err_msg=c["name"])


def check_points_csv(out, output, result):
    """A positions set written as CSV: coordinates, then the attributes."""
    form, columns = output["form"], output["columns"]
    x = getattr(result, output["python"])
    assert x.dtype == np.dtype(form["dtype"]) and x.ndim == 2
    names = axes(form, x.shape[1])
    header, text = read_csv(out / f"{output['file']}.csv")
    assert header == names + [c["name"] for c in columns]
    coordinate = {"dtype": form["dtype"], "labels": None}
    for k, a in enumerate(names):
        np.testing.assert_array_equal(x[:, k], parse(text[a], {**coordinate, "name": a}))
    for c in columns:
        py = getattr(result, c["name"])
        assert py.dtype == np.dtype(c["dtype"]), (c["name"], py.dtype)
        np.testing.assert_array_equal(py, parse(text[c["name"]], c), err_msg=c["name"])


def check_points_npy(out, output, result):
    """A positions set written as .npy: one file for the coordinates, one per attribute."""
    form = output["form"]
    x = getattr(result, output["python"])
    npy = np.load(out / f"{output['file']}.npy")
    assert npy.dtype == np.dtype(form["dtype"]) == x.dtype, (npy.dtype, x.dtype)
    np.testing.assert_array_equal(npy, x)
    for c in output["columns"]:
        a = np.load(out / f"{output['file']}_{c['name']}.npy")
        py = getattr(result, c["name"])
        assert a.dtype == np.dtype(c["dtype"]) == py.dtype, (c["name"], a.dtype, py.dtype)
        np.testing.assert_array_equal(a, py, err_msg=c["name"])


# One small run per model with every optional output on: flags of the binary, keywords of
# Python, the same run.
RUNS = {
    "dla": (["--particles", 600, "--seed", 3], dict(particles=600, seed=3)),
    # The outputs only a deposit writes.
    "dla-deposit": (
        ["--particles", 600, "--seed", 3, "--substrate-width", 32],
        dict(particles=600, seed=3, substrate_width=32.0),
    ),
    "dlca": (
        ["--size", 40, "--fill", 0.08, "--seed", 3, "--timing", "--histogram",
         "--gyration", "--fit-min-size", 2],
        dict(size=40, fill=0.08, seed=3, timing=True, histogram=True, gyration=True,
             fit_min_size=2),
    ),
    "animat": (
        ["--steps", 20, "--seed", 5, "--foxes", 30, "--rabbits", 200, "--start-radius", 30,
         "--timing"],
        dict(steps=20, seed=5, foxes=30, rabbits=200, start_radius=30, timing=True),
    ),
}


def written(output, name):
    """Whether run `name` of RUNS writes `output`: a deposit's outputs only with a substrate."""
    deposit = output.get("when") == "--substrate-width"
    return deposit == name.endswith("-deposit") or not deposit


@pytest.mark.parametrize("name", sorted(RUNS))
def test_cli_and_python_outputs_follow_the_schema(cli, name):
    flags, kwargs = RUNS[name]
    model = name.split("-")[0]
    schema = [o for o in aggsim._schema(model) if written(o, name)]
    assert schema, model
    result = getattr(aggsim, model)(**kwargs)
    by_format = {f: cli.run(model, "--positions", f, *flags) for f in ("csv", "npy")}
    for out, run in by_format.values():
        # The same run: the state, and every result of run.json a Python attribute.
        assert run["results"]["state_hash"] == result.state_hash
        assert set(run["results"]) <= set(vars(result))
    checked = set()
    for output in schema:
        if output["form"]["kind"] == "csv":
            check_csv(by_format["csv"][0], output, result)
        else:
            check_points_csv(by_format["csv"][0], output, result)
            check_points_npy(by_format["npy"][0], output, result)
        checked.add(output["file"])
    assert checked == {o["file"] for o in schema}


def test_the_schema_names_numpy_dtypes_and_its_attributes_exist():
    for model in {name.split("-")[0] for name in RUNS}:
        for output in aggsim._schema(model):
            for c in output["columns"]:
                np.dtype(c["dtype"])
                assert c["unit"], (model, c["name"])
    with pytest.raises(ValueError, match="unknown model"):
        aggsim._schema("ising")
    assert aggsim.SPECIES == ["fox", "rabbit"]
    assert aggsim.SPECIES[aggsim.FOX] == "fox" and aggsim.SPECIES[aggsim.RABBIT] == "rabbit"
