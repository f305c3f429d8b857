"""The documented interface is the real one: the stubs (__init__.pyi) name every argument and
result attribute, the docstrings explain every argument and state the libraries' defaults."""

import ast
import inspect
import re
from pathlib import Path

import pytest

import aggsim

STUBS = ast.parse((Path(aggsim.__file__).parent / "__init__.pyi").read_text())


def stub(name, within=None):
    body = STUBS.body
    if within:
        body = next(n for n in body if isinstance(n, ast.ClassDef) and n.name == within).body
    return next(
        n for n in body if isinstance(n, (ast.FunctionDef, ast.ClassDef)) and n.name == name
    )


def stub_args(fn):
    a = fn.args
    return [x.arg for x in a.posonlyargs + a.args + a.kwonlyargs if x.arg != "self"]


def stub_attributes(cls):
    names = {n.target.id for n in cls.body if isinstance(n, ast.AnnAssign)}
    names |= {n.name for n in cls.body if isinstance(n, ast.FunctionDef)}
    return names


CALLABLES = [
    (aggsim.dla, stub("dla")),
    (aggsim.dlca, stub("dlca")),
    (aggsim.animat, stub("animat")),
    (aggsim.DlcaLattice, stub("__init__", "DlcaLattice")),
    (aggsim.DlcaLattice.step, stub("step", "DlcaLattice")),
    (aggsim.DlcaLattice.run, stub("run", "DlcaLattice")),
    (aggsim.AnimatWorld, stub("__init__", "AnimatWorld")),
    (aggsim.AnimatWorld.step, stub("step", "AnimatWorld")),
    (aggsim.defaults, stub("defaults")),
    (aggsim.DlaResult.save_png, stub("save_png", "DlaResult")),
    (aggsim.DlaResult.save_gif, stub("save_gif", "DlaResult")),
    (aggsim.DlcaResult.save_png, stub("save_png", "DlcaResult")),
    (aggsim.AnimatResult.save_png, stub("save_png", "AnimatResult")),
]


@pytest.mark.parametrize("obj, fn", CALLABLES, ids=[s.name for _, s in CALLABLES])
def test_stub_signatures_are_the_real_ones(obj, fn):
    real = [p for p in inspect.signature(obj).parameters if p != "self"]
    assert stub_args(fn) == real


def parameter_docs(doc):
    """``{name: paragraph}`` of a numpydoc Parameters section (``a, b : type`` lines name
    several)."""
    section = doc.split("Parameters\n----------\n", 1)[1].split("\n\n", 1)[0]
    out, names = {}, []
    for line in section.splitlines():
        m = re.match(r"^(\w[\w, ]*) : ", line)
        if m:
            names = [n.strip() for n in m.group(1).split(",")]
            for n in names:
                out[n] = line
        else:
            for n in names:
                out[n] += "\n" + line
    return out


@pytest.mark.parametrize("model", ["dla", "dlca", "animat"])
def test_docstrings_explain_every_argument_and_its_default(model):
    fn = getattr(aggsim, model)
    docs = parameter_docs(fn.__doc__)
    for name in inspect.signature(fn).parameters:
        assert name in docs, f"{model}({name}=...) is not in help({model})"
    for name, value in aggsim.defaults(model).items():
        para = docs.get(name, "")
        if "default" not in para or isinstance(value, (list, dict)) or value is None:
            continue
        if isinstance(value, bool) or isinstance(value, str):
            text = str(value)
        elif name == "max_memory":
            # As the command line writes it: "default 4294967296 (4G)".
            text = f"{value // 2**30}G"
        else:
            text = f"{value:g}"
        t = re.escape(text)
        # "(default 5)", "(default None: 100)" or "``"return"`` (default)".
        stated = re.search(rf"default[^)]*?\b{t}\b", para) or re.search(rf"{t}\W*\(default", para)
        assert stated, (name, value, para)


@pytest.mark.parametrize(
    "result, cls",
    [
        (lambda: aggsim.dla(particles=500), "DlaResult"),
        (lambda: aggsim.dla(particles=5), "DlaResult"),  # too small to fit: fit_error
        (lambda: aggsim.dlca(size=32, fill=0.05, gyration=True, histogram=True), "DlcaResult"),
        (lambda: aggsim.animat(steps=2, foxes=5, rabbits=20, start_radius=10), "AnimatResult"),
    ],
)
def test_stubs_list_every_result_attribute(result, cls):
    r = result()
    missing = set(vars(r)) - stub_attributes(stub(cls))
    assert not missing, f"{cls} attributes missing from __init__.pyi: {missing}"


@pytest.mark.parametrize("cls", ["DlcaLattice", "AnimatWorld"])
def test_stubs_list_every_stepwise_member(cls):
    real = {n for n in dir(getattr(aggsim, cls)) if not n.startswith("_")}
    assert real == stub_attributes(stub(cls)) - {"__init__"}


def test_help_explains_the_functions():
    for obj in (aggsim.dla, aggsim.dlca, aggsim.animat, aggsim.DlcaLattice, aggsim.AnimatWorld):
        assert len(inspect.getdoc(obj)) > 200
    assert "Sosa-Herrera" in aggsim.dla.__doc__
    assert "Hawick, James & Scogings 2006" in aggsim.dlca.__doc__
