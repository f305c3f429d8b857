"""The keyword arguments, their defaults and the stubs against the libraries' parameter tables
(``aggsim._params(model)``, from ``PARAMS`` and ``Params::default()`` of each model crate): a
parameter missing from a signature or stub, another default or other choices fail here."""

import ast
import inspect
import math
from pathlib import Path

import numpy as np
import pytest

import aggsim

STUBS = ast.parse((Path(aggsim.__file__).parent / "__init__.pyi").read_text())

# The entry points of each model: (object, stub function, stub class or None).
ENTRY_POINTS = {
    "dla": [(aggsim.dla, "dla", None)],
    "dlca": [(aggsim.dlca, "dlca", None), (aggsim.DlcaLattice, "__init__", "DlcaLattice")],
    "animat": [(aggsim.animat, "animat", None), (aggsim.AnimatWorld, "__init__", "AnimatWorld")],
}

# Keyword arguments that are not model parameters.
PYTHON_ONLY = {"seed", "progress", "paper_settings", "config", "steps", "timing"}
# The animation a run writes: the binaries' figure flags (--animate, --animate-every,
# --png-size, --frame-radius), which are outputs, not model parameters.
PYTHON_ONLY |= {"animate", "animate_every", "animate_size", "frame_radius"}
# Where a run keeps its checkpoint and how often (the binaries' --out, --resume and
# --checkpoint-interval): how the run is kept, not a model parameter.
PYTHON_ONLY |= {"checkpoint", "checkpoint_interval"}
# animat's start density (the binary's --density): sets the declared start_radius.
PYTHON_ONLY |= {"density"}

# Documented differences from the library default: ``aggsim.dla`` grows 1e5 particles when
# none are given (the binary requires ``--particles``); ``aggsim.dlca``'s ``dim`` defaults to
# the number of lengths given.
DIFFER = {("dla", "particles"): 100_000, ("dlca", "dim"): None}


def stub(name, within=None):
    body = STUBS.body
    if within:
        body = next(n for n in body if isinstance(n, ast.ClassDef) and n.name == within).body
    return next(n for n in body if isinstance(n, ast.FunctionDef) and n.name == name)


def stub_defaults(fn):
    """``{name: (default node or None, annotation node)}`` of a stub function."""
    a = fn.args
    positional = a.posonlyargs + a.args
    pos_defaults = [None] * (len(positional) - len(a.defaults)) + list(a.defaults)
    out = {x.arg: (d, x.annotation) for x, d in zip(positional, pos_defaults)}
    out.update({x.arg: (d, x.annotation) for x, d in zip(a.kwonlyargs, a.kw_defaults)})
    out.pop("self", None)
    return out


def literals(annotation):
    """The strings of every ``Literal[...]`` in an annotation."""
    found = []
    for node in ast.walk(annotation):
        if isinstance(node, ast.Subscript) and getattr(node.value, "id", "") == "Literal":
            found += [c.value for c in ast.walk(node.slice) if isinstance(c, ast.Constant)]
    return found


def same(a, b):
    if isinstance(a, float) or isinstance(b, float):
        return a == b or (math.isinf(a) and math.isinf(b))
    return a == b


def table(model):
    return aggsim._params(model)


@pytest.mark.parametrize("model", ENTRY_POINTS)
def test_every_parameter_is_a_keyword_with_the_library_default(model):
    rows = table(model)
    names = {r["name"] for r in rows}
    defaults = aggsim.defaults(model)
    for obj, _, _ in ENTRY_POINTS[model]:
        sig = inspect.signature(obj).parameters
        for r in rows:
            name = r["name"]
            assert name in sig, f"{obj.__name__} has no keyword {name}"
            shown = sig[name].default
            expected = DIFFER.get((model, name), r["default"])
            if shown is inspect.Parameter.empty:
                # Required, as the library has no default (`size`).
                assert expected is None, f"{obj.__name__}: {name} required, library {expected!r}"
            elif shown is None and expected is not None:
                # None takes the library's default, which aggsim.defaults() reports.
                assert same(defaults[name], expected), (name, defaults[name], expected)
            else:
                where = f"{obj.__name__}({name}={shown!r})"
                assert same(shown, expected), f"{where}, library {expected!r}"
        extra = set(sig) - names - PYTHON_ONLY
        assert not extra, f"{obj.__name__}: {extra} not in the library's table"


@pytest.mark.parametrize("model", ENTRY_POINTS)
def test_the_stubs_name_every_parameter_its_default_and_choices(model):
    rows = table(model)
    for _, fn, cls in ENTRY_POINTS[model]:
        args = stub_defaults(stub(fn, cls))
        for r in rows:
            name = r["name"]
            assert name in args, f"the stub of {cls or fn} has no {name}"
            default, annotation = args[name]
            expected = DIFFER.get((model, name), r["default"])
            if default is None:
                assert expected is None, f"{fn}: {name} required in the stub, library {expected!r}"
                continue
            value = default.value if isinstance(default, ast.Constant) else default
            # `...` stands for the library's default; None for "the library's" too.
            assert value is Ellipsis or value is None or same(value, expected), (fn, name, value)
            shown = literals(annotation)
            if shown and r["choices"]:
                assert shown == r["choices"], (fn, name, shown, r["choices"])


@pytest.mark.parametrize(
    "call, name",
    [
        (lambda v: aggsim.dla(particles=10, far_field=v), ("dla", "far_field")),
        (lambda v: aggsim.dlca(size=16, fill=0.1, search=v), ("dlca", "search")),
    ],
)
def test_every_choice_is_accepted_and_named_in_the_error(call, name):
    row = next(r for r in table(name[0]) if r["name"] == name[1])
    assert row["choices"]
    for choice in row["choices"]:
        call(choice)
    with pytest.raises(ValueError) as e:
        call("nonsense")
    assert str(e.value).endswith(", ".join(row["choices"]))


def parameter_docs(doc):
    """``{name: paragraph}`` of a numpydoc Parameters section (``a, b : type`` names several)."""
    section = doc.split("Parameters\n----------\n", 1)[1].split("\n\n", 1)[0]
    out, names = {}, []
    for line in section.splitlines():
        if " : " in line and not line.startswith(" "):
            names = [n.strip() for n in line.split(" : ")[0].split(",")]
            for n in names:
                out[n] = line
        else:
            for n in names:
                out[n] += " " + line.strip()
    return out


@pytest.mark.parametrize("model", ENTRY_POINTS)
def test_the_docstrings_state_each_range(model):
    docs = parameter_docs(getattr(aggsim, model).__doc__)
    for r in table(model):
        if r["range"] == "any" or r["choices"] or "`" in r["range"]:
            continue
        assert r["range"] in docs[r["name"]], (model, r["name"], r["range"], docs[r["name"]])


def test_the_tables_state_units_ranges_and_docs():
    for model in ENTRY_POINTS:
        for r in table(model):
            assert r["doc"] and "[`" not in r["doc"], r
            assert r["range"], r
    with pytest.raises(ValueError, match="unknown model"):
        aggsim._params("ising")


@pytest.mark.parametrize(
    "name", ["hungry_at", "starve", "fox_max_age", "rabbit_max_age", "prey_needed", "crowd_max"]
)
def test_a_negative_count_names_the_tables_range(name):
    row = next(r for r in table("animat") if r["name"] == name)
    with pytest.raises(ValueError) as e:
        aggsim.AnimatWorld(**{name: -1})
    assert str(e.value) == f"{name} = -1 is outside the accepted range {row['range']}"


def test_declared_keywords_come_from_the_declaration():
    """``aggsim.dla``'s model keywords are made from the library's declaration: the signature,
    the docstring's list and the checks of unknown keywords and wrong types."""
    declared = aggsim._declared("dla")
    names = [r["name"] for r in declared["params"] if r["name"] not in declared["positional"]]
    sig = inspect.signature(aggsim.dla).parameters
    for name in names:
        assert sig[name].kind is inspect.Parameter.KEYWORD_ONLY, name
    doc = inspect.getdoc(aggsim.dla)
    for row in table("dla"):
        if row["name"] in names:
            assert f"\n{row['name']} : " in doc, row["name"]
            if row["range"] not in ("any",) and not row["choices"]:
                assert f"accepted {row['range']}" in doc, row["name"]
    with pytest.raises(TypeError, match="unexpected keyword argument 'birth_gapp'"):
        aggsim.dla(particles=10, birth_gapp=5)
    with pytest.raises(TypeError, match="birth_gap = fast: expected float, not str"):
        aggsim.dla(particles=10, birth_gap="fast")
    with pytest.raises(TypeError, match="near_cache = 1: expected bool"):
        aggsim.dla(particles=10, near_cache=1)
    with pytest.raises(TypeError, match="step_min = None"):
        aggsim.dla(particles=10, step_min=None)
    # An optional parameter given as None is not given.
    assert aggsim.dla(particles=10, death_ratio=None).particles == 10
    with pytest.raises(ValueError, match="--death-ratio is used by --far-field jump only"):
        aggsim.dla(particles=10, death_ratio=100)
    # A real parameter takes an int; a count takes a whole float.
    r = aggsim.dla(particles=10, birth_gap=7, fit_from=2e3, far_field="jump", death_ratio=50)
    assert r.params["birth_gap"] == 7.0 and r.params["fit_from"] == 2000


def test_the_dla_variants_are_keywords_that_reach_the_run():
    """``sticking_probability`` and ``noise_reduction``, declared in the library only, are
    keywords of ``aggsim.dla`` that change the run, checked as the binary checks them."""
    plain = aggsim.dla(particles=300, seed=4)
    same = aggsim.dla(particles=300, seed=4, sticking_probability=1.0, noise_reduction=1)
    assert same.state_hash == plain.state_hash
    sticky = aggsim.dla(particles=300, seed=4, sticking_probability=0.2)
    assert sticky.state_hash != plain.state_hash
    assert sticky.run_json["results"]["walk_counts"]["refused"] > 0
    reduced = aggsim.dla(particles=300, seed=4, noise_reduction=0.5)
    d = np.linalg.norm(reduced.positions[1:2] - reduced.positions[0:1], axis=1)
    assert abs(d[0] - 0.5) < 1e-8
    with pytest.raises(ValueError, match=r"--noise-reduction 0 is outside the accepted range \(0, 1\]"):
        aggsim.dla(particles=10, noise_reduction=0)
