"""Type stubs of aggsim (the compiled module aggsim._aggsim). Defaults shown as ``...`` are
the binaries' defaults, taken from the libraries: ``aggsim.defaults(model)`` lists them."""

from os import PathLike
from typing import Any, Callable, Dict, List, Literal, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str

FOX: int
"""Species code of foxes in ``species`` arrays (0)."""
RABBIT: int
"""Species code of rabbits in ``species`` arrays (1)."""
SPECIES: List[str]
"""Species names by code (``["fox", "rabbit"]``): the names ``positions.csv`` writes."""

Count = Union[int, float]
"""A count: an int, or a float holding a whole number (``1e4``, ``2.5e5``); ``1.5``, ``nan``
and values beyond the parameter's range raise ``ValueError`` naming the parameter."""

Progress = Union[None, bool, Callable[[int, int], Any]]
"""``True``: progress on ``sys.stderr``; a callable: called as ``progress(done, total)``."""

def defaults(model: Literal["dla", "dlca", "animat"]) -> Dict[str, Any]:
    """The defaults of ``model``'s keyword arguments: the binary's, from the library."""

def _schema(model: Literal["dla", "dlca", "animat"]) -> List[Dict[str, Any]]:
    """The library's output schema of ``model``: each file with its columns' names, dtypes
    and units, and the result attribute holding them (docs/outputs.md)."""

def _params(model: Literal["dla", "dlca", "animat"]) -> List[Dict[str, Any]]:
    """The library's parameter table of ``model``: name, flag, unit, doc, range, choices and
    default of each parameter (the consistency tests check the keywords against it)."""

def _declared(model: Literal["dla", "dlca", "animat"]) -> Dict[str, Any]:
    """The declared parameters of ``model`` that ``aggsim`` makes keyword arguments of:
    ``params`` (name, type, help, why, optional of each) and ``positional`` (the names the
    function takes as its own arguments)."""

class DlaResult:
    """A grown DLA/PDLA cluster: :func:`dla`'s result."""

    positions: npt.NDArray[np.float64]
    """float64 (N, D): centres in arrival order, seed particle first."""
    parent: Optional[npt.NDArray[np.int64]]
    """int64 (N,): the arrival index of the particle each one stuck to, -1 for the seed."""
    branches: Optional[Dict[str, npt.NDArray[Any]]]
    """``branches.csv``'s columns per Horton-Strahler order: ``order``, ``branches``,
    ``particles`` (uint64), ``mean_length``, ``bifurcation_ratio``, ``length_ratio`` (float64,
    NaN at the highest order)."""
    strahler_order: int
    trees: int
    bifurcation_ratio: Optional[float]
    """R_B fitted over the middle orders (None when the cluster has too few)."""
    length_ratio: Optional[float]
    ratio_fit_orders: Optional[List[int]]
    deposit: Optional[Dict[str, npt.NDArray[Any]]]
    """A deposit's (``substrate_width`` > 0) ``deposit.csv`` columns per layer of one
    diameter: ``height``, ``particles`` (uint64), ``density``, ``trees`` (uint64); None for
    radial growth."""
    deposit_growth: Optional[Dict[str, npt.NDArray[Any]]]
    """A deposit's ``deposit_growth.csv`` columns per block of W^(d-1) particles: ``n``,
    ``height``, ``mean_height``, ``active_zone_width``, ``growing_trees``."""
    density_dimension: Optional[float]
    """A deposit's trees' fractal dimension from its density profile (None without a fit)."""
    growth: Dict[str, npt.NDArray[Any]]
    """``growth.csv``'s columns: ``n`` (uint64), ``radius_of_gyration``, ``r_ext``,
    ``seconds`` (float64) per growth sample."""
    state_hash: str
    particles: int
    radius_of_gyration: float
    r_ext: float
    fractal_dimension: Optional[float]
    fractal_dimension_stderr: Optional[float]
    fit_points: int
    """Samples in the fit (absent when ``fit_error`` is set)."""
    fit_error: str
    """Why no fractal dimension was fitted (present only then)."""
    discarded_walkers: int
    pdla_parallel_seconds: float
    pdla_lock_wait_seconds: float
    pdla_phases: int
    tree_memory_bytes: int
    tree_point_slots: int
    distance_map_bytes: int
    walk_counts: Dict[str, int]
    """Software counts of the walk (walkers, moves, map reads, tree queries, ...), summed over
    PDLA threads."""
    bytes_per_particle: Optional[float]
    """Peak resident memory of the process during the simulation, per particle."""
    simulation_peak_rss_bytes: Optional[int]
    """Peak resident memory of the process during the simulation."""
    output_peak_rss_bytes: Optional[int]
    """Peak through the output stage (the binary's files and figure); None here, where the
    run writes no files."""
    model: str
    version: str
    seed: int
    threads: int
    wall_seconds: float
    cpu_seconds: Optional[float]
    peak_rss_bytes: Optional[int]
    #: run.json's provenance: date_utc, version, git_commit, command_line, host, cpu, threads, cpus.
    provenance: Dict[str, Any]
    params: Dict[str, Any]
    run_json: Dict[str, Any]

    def save_png(self, path: Union[str, PathLike[str]], size: Optional[Count] = None) -> None:
        """Write the ``dla`` binary's ``dla.png`` of this cluster, byte for byte the binary's
        (the same Rust renderer); ``size`` is ``--png-size`` (16..=65536, default one pixel per
        diameter, 512 to 4096)."""

    def save_gif(
        self,
        path: Union[str, PathLike[str]],
        size: Optional[Count] = None,
        every: Optional[Count] = None,
    ) -> int:
        """Write the ``dla`` binary's ``dla.gif`` (the growth, a frame every ``every``
        particles), byte for byte the binary's; ``size`` is ``--png-size`` (16..=16384,
        default 512), ``every`` ``--animate-every`` (default a hundredth of N). Returns the
        number of frames."""

def dla(
    dim: int = ...,
    particles: Count = ...,
    seed: int = 1,
    threads: Count = ...,
    *,
    # BEGIN GENERATED dla-keywords: written by `cargo xtask generate` from the declaration; do not edit
    birth_gap: float = ...,
    far_field: Literal["return", "jump"] = ...,
    death_ratio: Optional[float] = None,
    step_min: float = ...,
    precision: float = ...,
    leaf_side: float = ...,
    near_cache: bool = ...,
    distance_map: bool = ...,
    serial_until: Count = ...,
    fit_from: Count = ...,
    sticking_probability: float = ...,
    noise_reduction: float = ...,
    substrate_width: float = ...,
    drift: float = ...,
    ballistic: bool = ...,
    seed_set: Optional[str] = None,
    # END GENERATED dla-keywords
    paper_settings: bool = False,
    progress: Progress = None,
    checkpoint: Union[None, str, PathLike[str]] = None,
    checkpoint_interval: Optional[float] = 300.0,
) -> DlaResult:
    """Grow an off-lattice DLA cluster (PDLA with ``threads`` > 1); see ``help(aggsim.dla)``."""

class DlcaResult:
    """The final state of a DLCA run: :func:`dlca`'s result."""

    positions: npt.NDArray[np.int64]
    """int64 (N, D): lattice sites, clusters by increasing id."""
    cluster: npt.NDArray[np.int64]
    """int64 (N,): cluster id of each particle (``particles.csv``'s ``cluster``)."""
    per_sweep: Dict[str, npt.NDArray[Any]]
    """``sweep``, ``clusters``, ``largest`` (uint64), ``seconds`` with ``timing``."""
    sizes: Dict[str, npt.NDArray[np.uint64]]
    """``size``, ``count``: the final size distribution."""
    gyration: Optional[Dict[str, npt.NDArray[Any]]]
    histogram: Optional[Dict[str, npt.NDArray[np.uint64]]]
    state_hash: str
    particles: int
    clusters: int
    largest_cluster: int
    sweeps: int
    strategy: str
    strategy_requested: str
    strategy_reason: str
    moves: int
    mean_candidates_examined: float
    search_events: List[Dict[str, Any]]
    fractal_dimension: Optional[float]
    """With ``gyration=True`` only."""
    fractal_dimension_stderr: Optional[float]
    fit_clusters: int
    fit_r2: float
    fit_error: str
    wrapping_clusters: int
    model: str
    version: str
    seed: int
    threads: int
    wall_seconds: float
    cpu_seconds: Optional[float]
    peak_rss_bytes: Optional[int]
    #: run.json's provenance: date_utc, version, git_commit, command_line, host, cpu, threads, cpus.
    provenance: Dict[str, Any]
    params: Dict[str, Any]
    run_json: Dict[str, Any]

    def save_png(self, path: Union[str, PathLike[str]], size: Optional[Count] = None) -> None:
        """Write the ``dlca`` binary's ``dlca.png`` of this state, byte for byte the binary's
        (the same Rust renderer); ``size`` is ``--png-size``, the raster's longer side
        (16..=65536, default a whole number of pixels per site, at least 512)."""

Size = Union[Count, str, Sequence[Count]]
Boundary = Union[str, Sequence[str]]

class DlcaLattice:
    """A DLCA lattice to sweep forward and look at between sweeps."""

    def __init__(
        self,
        size: Size,
        fill: Optional[float] = None,
        particles: Optional[Count] = None,
        *,
        dim: Optional[int] = None,
        seed: int = 1,
        # BEGIN GENERATED dlca-lattice-keywords: written by `cargo xtask generate` from the declaration; do not edit
        boundary: Optional[Boundary] = None,
        temperature: float = ...,
        gravity: float = ...,
        mobility_exponent: float = ...,
        target_clusters: Count = ...,
        max_sweeps: Optional[Count] = None,
        search: Literal["auto", "all-pairs", "grid", "grid-doubling", "lattice"] = ...,
        grid_box: Optional[Count] = None,
        max_memory: Optional[Union[Count, str]] = None,
        timing: bool = ...,
        histogram: bool = ...,
        histogram_sweeps: Optional[Sequence[Count]] = None,
        gyration: bool = ...,
        fit_min_size: Count = ...,
        # END GENERATED dlca-lattice-keywords
    ) -> None: ...
    def step(self, n: Count = 1, progress: Progress = None) -> int:
        """Run up to ``n`` sweeps (fewer once done); return how many ran."""
    def run(self, progress: Progress = None) -> int:
        """Sweep until done; return how many sweeps ran."""
    def result(self) -> DlcaResult:
        """The state now, as :func:`dlca` returns it."""
    @property
    def done(self) -> bool: ...
    @property
    def sweeps(self) -> int: ...
    @property
    def clusters(self) -> int: ...
    @property
    def largest(self) -> int: ...
    @property
    def particles(self) -> int: ...
    @property
    def size(self) -> Tuple[int, ...]: ...
    @property
    def strategy(self) -> str: ...
    @property
    def state_hash(self) -> str: ...
    @property
    def params(self) -> Dict[str, Any]: ...
    @property
    def positions(self) -> npt.NDArray[np.int64]: ...
    @property
    def cluster(self) -> npt.NDArray[np.int64]: ...
    @property
    def per_sweep(self) -> Dict[str, npt.NDArray[Any]]: ...
    @property
    def sizes(self) -> Dict[str, npt.NDArray[np.uint64]]: ...

def dlca(
    size: Size,
    fill: Optional[float] = None,
    particles: Optional[Count] = None,
    *,
    dim: Optional[int] = None,
    seed: int = 1,
    # BEGIN GENERATED dlca-keywords: written by `cargo xtask generate` from the declaration; do not edit
    boundary: Optional[Boundary] = None,
    temperature: float = ...,
    gravity: float = ...,
    mobility_exponent: float = ...,
    target_clusters: Count = ...,
    max_sweeps: Optional[Count] = None,
    search: Literal["auto", "all-pairs", "grid", "grid-doubling", "lattice"] = ...,
    grid_box: Optional[Count] = None,
    max_memory: Optional[Union[Count, str]] = None,
    timing: bool = ...,
    histogram: bool = ...,
    histogram_sweeps: Optional[Sequence[Count]] = None,
    gyration: bool = ...,
    fit_min_size: Count = ...,
    # END GENERATED dlca-keywords
    progress: Progress = None,
    animate: Union[None, str, PathLike[str]] = None,
    animate_every: Optional[Count] = None,
    animate_size: Optional[Count] = None,
    checkpoint: Union[None, str, PathLike[str]] = None,
    checkpoint_interval: Optional[float] = 300.0,
) -> DlcaResult:
    """Run DLCA to the end; see ``help(aggsim.dlca)``."""

class AnimatResult:
    """The populations and final animats of an animat run: :func:`animat`'s result."""

    populations: Dict[str, npt.NDArray[Any]]
    """``step``, ``foxes``, ``rabbits`` (uint64); with ``timing`` also ``search_seconds``,
    ``distance_evaluations``."""
    positions: npt.NDArray[np.int64]
    """int64 (M, 2): cells of the live animats, by increasing id."""
    id: npt.NDArray[np.int64]
    """int64 (M,): each live animat's id."""
    species: npt.NDArray[np.int64]
    """int64 (M,): :data:`FOX` or :data:`RABBIT` (names by code: :data:`SPECIES`)."""
    age: npt.NDArray[np.int64]
    """int64 (M,): steps lived."""
    hunger: npt.NDArray[np.int64]
    """int64 (M,): steps since the last meal (0 for rabbits)."""
    state_hash: str
    steps: int
    foxes: int
    rabbits: int
    distance_evaluations: int
    grid_box: str
    queries: Dict[str, int]
    model: str
    version: str
    seed: int
    threads: int
    wall_seconds: float
    cpu_seconds: Optional[float]
    peak_rss_bytes: Optional[int]
    #: run.json's provenance: date_utc, version, git_commit, command_line, host, cpu, threads, cpus.
    provenance: Dict[str, Any]
    params: Dict[str, Any]
    run_json: Dict[str, Any]

    def save_png(
        self,
        path: Union[str, PathLike[str]],
        size: Optional[Count] = None,
        frame_radius: Optional[Count] = None,
    ) -> None:
        """Write the ``animat`` binary's snapshot of this world (its last
        ``snapshot_NNNNNN.png``), byte for byte the binary's (the same Rust renderer), on the
        run's fixed frame; ``size`` is ``--png-size`` (16..=65536), ``frame_radius``
        ``--frame-radius`` (default three start radii)."""

GridBox = Union[int, Literal["vision", "none"]]

class AnimatWorld:
    """An animat world to step forward and look at between steps."""

    def __init__(
        self,
        seed: int = 1,
        *,
        config: Union[None, str, PathLike[str]] = None,
        density: Optional[float] = None,
        # BEGIN GENERATED animat-world-keywords: written by `cargo xtask generate` from the declaration; do not edit
        foxes: Count = ...,
        rabbits: Count = ...,
        start_radius: Count = ...,
        vision: Count = ...,
        grid_box: Optional[GridBox] = None,
        hungry_at: Count = ...,
        starve: Count = ...,
        fox_max_age: Count = ...,
        rabbit_max_age: Count = ...,
        fox_breed_p: float = ...,
        rabbit_breed_p: float = ...,
        prey_needed: Count = ...,
        crowd_max: Count = ...,
        crowd_radius: Count = ...,
        fox_rules: Optional[Sequence[str]] = None,
        rabbit_rules: Optional[Sequence[str]] = None,
        # END GENERATED animat-world-keywords
        timing: bool = False,
    ) -> None: ...
    def step(self, n: Count = 1, progress: Progress = None) -> int:
        """Run up to ``n`` steps (fewer once every animat has died); return how many ran."""
    def result(self) -> AnimatResult:
        """The state now, as :func:`animat` returns it."""
    @property
    def steps(self) -> int: ...
    @property
    def foxes(self) -> int: ...
    @property
    def rabbits(self) -> int: ...
    @property
    def state_hash(self) -> str: ...
    @property
    def params(self) -> Dict[str, Any]: ...
    @property
    def positions(self) -> npt.NDArray[np.int64]: ...
    @property
    def id(self) -> npt.NDArray[np.int64]: ...
    @property
    def species(self) -> npt.NDArray[np.int64]: ...
    @property
    def age(self) -> npt.NDArray[np.int64]: ...
    @property
    def hunger(self) -> npt.NDArray[np.int64]: ...
    @property
    def populations(self) -> Dict[str, npt.NDArray[Any]]: ...

def animat(
    steps: Count = ...,
    seed: int = 1,
    *,
    config: Union[None, str, PathLike[str]] = None,
    density: Optional[float] = None,
    # BEGIN GENERATED animat-keywords: written by `cargo xtask generate` from the declaration; do not edit
    foxes: Count = ...,
    rabbits: Count = ...,
    start_radius: Count = ...,
    vision: Count = ...,
    grid_box: Optional[GridBox] = None,
    hungry_at: Count = ...,
    starve: Count = ...,
    fox_max_age: Count = ...,
    rabbit_max_age: Count = ...,
    fox_breed_p: float = ...,
    rabbit_breed_p: float = ...,
    prey_needed: Count = ...,
    crowd_max: Count = ...,
    crowd_radius: Count = ...,
    fox_rules: Optional[Sequence[str]] = None,
    rabbit_rules: Optional[Sequence[str]] = None,
    # END GENERATED animat-keywords
    timing: bool = False,
    progress: Progress = None,
    animate: Union[None, str, PathLike[str]] = None,
    animate_every: Optional[Count] = None,
    animate_size: Optional[Count] = None,
    frame_radius: Optional[Count] = None,
    checkpoint: Union[None, str, PathLike[str]] = None,
    checkpoint_interval: Optional[float] = 300.0,
) -> AnimatResult:
    """Run the animat model; see ``help(aggsim.animat)``."""

def dlca_pooled_fit(
    results: Sequence[DlcaResult], fit_min_size: Optional[Count] = None
) -> Dict[str, Any]:
    """The fractal dimension pooled over the clusters of every run (jackknife error over runs),
    beside the mean of the runs' own fits: ``ensemble.json``'s ``pooled.fractal_dimension``."""
