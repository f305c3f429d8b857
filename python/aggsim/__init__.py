"""aggsim: aggregation and artificial life at native speed, results as NumPy arrays.

Three models, each as a function that runs to the end and returns a result object, and two
of them also as objects to step forward and look at between steps:

- :func:`dla`: off-lattice diffusion-limited aggregation (DLA), or parallel DLA (PDLA) with
  ``threads`` > 1, in 2D to 5D (Sosa-Herrera & Rodriguez-Romo, "Variable precision distance
  search for random fractal cluster simulations").
- :func:`dlca`, :class:`DlcaLattice`: diffusion-limited cluster-cluster aggregation on
  lattices of 1 to 5 dimensions (Hawick, James & Scogings 2006, "Grid-Boxing for Spatial
  Simulation Performance Optimisation").
- :func:`animat`, :class:`AnimatWorld`: foxes and rabbits running prioritised rule lists
  (Hawick, James & Scogings 2006, section II.B).

Parameters are the command-line flags of the ``dla``, ``dlca`` and ``animat`` binaries with
dashes as underscores, with their defaults (:func:`defaults`), validated by the same code:
a bad value raises ``ValueError`` with the binary's message. Runs release the GIL, stop on
Ctrl-C with ``KeyboardInterrupt`` and show progress with ``progress=True``. The same seed and
parameters give the binary's ``state_hash``. See docs/python.md in the repository.
"""

import functools as _functools
import inspect as _inspect
import textwrap as _textwrap

from . import _aggsim
from ._aggsim import (
    FOX,
    RABBIT,
    SPECIES,
    AnimatResult,
    AnimatWorld,
    DlaResult,
    DlcaLattice,
    DlcaResult,
    __version__,
    _declared,
    _params,
    _schema,
    defaults,
    dlca_pooled_fit,
)


def _declared_keywords(model):
    """The declared keyword arguments of ``model``, in declaration order: one dict per
    parameter with the rows of ``_params`` and ``_declared`` merged (name, type, help, unit,
    range, choices, default, optional), without those the function takes by position."""
    table = {row["name"]: row for row in _params(model)}
    declared = _declared(model)
    return [
        {**table[row["name"]], **row}
        for row in declared["params"]
        if row["name"] not in declared["positional"]
    ]


def _annotation(row):
    """The type of a declared parameter as the stubs write it."""
    if row.get("annotation"):
        kind = row["annotation"]
    elif row["choices"]:
        names = ", ".join(repr(c) for c in row["choices"])
        kind = f"Literal[{names}]"
    else:
        kind = {"int": "Count"}.get(row["type"], row["type"])
    return f"Optional[{kind}]" if row["optional"] else kind


def _signature(obj, model):
    """``obj``'s signature with the defaults the compiled module shows as ``...`` filled in
    from the library (``defaults(model)``, and the binaries' checkpoint interval), and with
    the model's declared parameters as keyword arguments in place of ``**params`` (before the
    parameter ``_declared(model)["before"]``, else at the end), so that ``help()`` shows every
    keyword and its value."""
    values = {**defaults(model), "checkpoint_interval": _aggsim._CHECKPOINT_INTERVAL}
    before = _declared(model)["before"]
    sig = _inspect.signature(obj)
    params = []
    declared = [
        _inspect.Parameter(
            row["name"],
            _inspect.Parameter.KEYWORD_ONLY,
            default=None if row["optional"] else values[row["name"]],
            annotation=_annotation(row),
        )
        for row in _declared_keywords(model)
    ]
    for p in sig.parameters.values():
        if p.kind is p.VAR_KEYWORD:
            continue
        if p.name == before and declared:
            params += declared
            declared = []
        if p.default is Ellipsis and p.name in values:
            p = p.replace(default=values[p.name])
        params.append(p)
    return sig.replace(parameters=params + declared)


def _doc_entry(row, default):
    """A declared parameter in a docstring's numpydoc ``Parameters`` list."""
    facts = []
    if row["unit"]:
        facts.append(f"in {row['unit']}")
    if row["choices"]:
        facts.append("one of " + ", ".join(f'``"{c}"``' for c in row["choices"]))
    elif row["range"] != "any":
        facts.append(f"accepted {row['range']}")
    shown = f"default {default!r}"
    if row.get("text") and not isinstance(default, list) and row["text"] != str(default):
        shown += f" ({row['text']})"
    facts.append(shown + (", None: not given" if row["optional"] else ""))
    text = f"{row['help']} ({'; '.join(facts)})."
    return f"{row['name']} : {_annotation(row)}\n" + "\n".join(
        "    " + line for line in _textwrap.wrap(text, 88)
    )


def _doc(fn, model):
    """``fn``'s docstring with the declared keyword arguments listed before ``Returns``."""
    doc = fn.__doc__ or ""
    values = defaults(model)
    entries = "\n".join(_doc_entry(row, values[row["name"]]) for row in _declared_keywords(model))
    if not entries:
        return doc
    head, sep, tail = doc.partition("\nReturns\n-------")
    return f"{head.rstrip()}\n{entries}\n{sep}{tail}" if sep else f"{doc}\n{entries}"


def _shown_with_defaults(fn, model):
    """``fn`` (compiled) behind a Python function of the same name, doc and arguments, whose
    signature shows the real defaults and whose docstring lists the declared keywords."""

    @_functools.wraps(fn)
    def call(*args, **kwargs):
        return fn(*args, **kwargs)

    call.__signature__ = _signature(fn, model)
    call.__doc__ = _doc(fn, model)
    return call


dla = _shown_with_defaults(_aggsim.dla, "dla")
dlca = _shown_with_defaults(_aggsim.dlca, "dlca")
animat = _shown_with_defaults(_aggsim.animat, "animat")
for _cls, _model in ((DlcaLattice, "dlca"), (AnimatWorld, "animat")):
    _cls.__signature__ = _signature(_cls, _model)
del _cls, _model

__all__ = [
    "FOX",
    "RABBIT",
    "SPECIES",
    "AnimatResult",
    "AnimatWorld",
    "DlaResult",
    "DlcaLattice",
    "DlcaResult",
    "__version__",
    "animat",
    "defaults",
    "dla",
    "dlca",
    "dlca_pooled_fit",
]
