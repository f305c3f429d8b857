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
    _params,
    _schema,
    defaults,
    dlca_pooled_fit,
)


def _signature(obj, model):
    """``obj``'s signature with the defaults the compiled module shows as ``...`` filled in
    from the library (``defaults(model)``, and the binaries' checkpoint interval), so that
    ``help()`` shows the values."""
    values = {**defaults(model), "checkpoint_interval": _aggsim._CHECKPOINT_INTERVAL}
    sig = _inspect.signature(obj)
    params = [
        p.replace(default=values[p.name])
        if p.default is Ellipsis and p.name in values
        else p
        for p in sig.parameters.values()
    ]
    return sig.replace(parameters=params)


def _shown_with_defaults(fn, model):
    """``fn`` (compiled) behind a Python function of the same name, doc and arguments, whose
    signature shows the real defaults."""

    @_functools.wraps(fn)
    def call(*args, **kwargs):
        return fn(*args, **kwargs)

    call.__signature__ = _signature(fn, model)
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
