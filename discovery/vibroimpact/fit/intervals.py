"""Coefficient intervals by a bootstrap through the full processing (a refit per replicate)."""

from dataclasses import dataclass, replace

import numpy as np

from ..._api._result import Result
from ..._api._settings import Settings, option, takes
from ..._api._validate import Choice, Real
from ...errors import IntegrationError, NoContactError
from ...numerics.distributions import normal_quantile, t_quantile
from ...numerics.executor import map_on
from ..dynamics import Tolerances
from ..model.scenario import scale_bounds
from ..verify.criteria import CRITERIA
from .optimise import _checked, _fitted
from .problem import _Objective
from .records import as_records, model_parts

__all__ = [
    "Intervals",
    "bootstrap_intervals",
    "cycle_spread",
    "cycle_widening",
    "INTERVAL_REFITS",
    "INTERVAL_NOISE",
]

# how a bootstrap replicate of the intervals is refitted (see bootstrap_intervals)
INTERVAL_REFITS = ("two-step", "full")
#: the bootstrap replicates' noise: the record's own residuals, each cycle's multiplied by
#: one weight (``"cycles"``, the default), or white noise of the record's level (``"white"``)
INTERVAL_NOISE = ("cycles", "white")


# ------------------------------------------------------------------ bootstrap intervals
# The Jacobian standard errors of an output-error fit assume white residuals.  A record
# compared over its span has two more sources of error that they miss: the machine's state
# at the start of each block is itself estimated from noisy positions (its error moves
# every later impact of the block), and the record's own sampling.  The bootstrap repeats
# the whole experiment under the fitted model: for each replicate, every block is simulated
# from a state drawn from that block's state-fit covariance, sampled at the record's own
# sample times with noise, folded like the record, and refitted from the fitted model; the
# spread of the refitted coefficients gives the intervals.  Seeds are explicit.
#
# The noise is the record's own residual against the fitted model, force and penetration,
# each cycle's multiplied by one weight drawn from Webb's six-point distribution (a wild
# bootstrap with the cycles as clusters: Cameron, Gelbach & Miller 2008; Webb 2023).  White
# noise of the record's level (``noise="white"``) misses what repeats within a cycle: an
# onset's timing, a force sensor's own structure, a misfit the model leaves; the cycles'
# residuals carry it.
#
# The refit is two Gauss-Newton steps from the fitted model by default (the k-step
# bootstrap of Davidson & MacKinnon 1999 and Andrews 2002, k = 2: the replicate's estimate
# lies within a standard error of the fit, where Newton's steps converge fast): each step is
# the replicate's residuals and their exact Jacobian, one plain and one sensitivity run per
# block, where a least-squares refit takes about five of each; two steps keep the
# bootstrap's standard deviations close to the full refits' (one step does not; the
# numbers: CHANGELOG).  ``refit="full"`` keeps the full refit.
#
# A record has few cycles (a dozen, six for a period-two orbit) against two to four
# parameters, and a cluster bootstrap's spread, like the cluster-robust variance it mimics,
# is then too small by about ``(G - p) / G`` and itself uncertain.  The spread is scaled by
# ``sqrt(G / (G - p))`` and the interval takes Student's t with ``G - p`` degrees of freedom
# (Cameron & Miller 2015, section VI), as a regression's does with ``N - p``.


@dataclass(frozen=True, eq=False)
class Intervals(Result):
    """Bootstrap intervals of a fitted law's coefficients.

    Attributes
    ----------
    bounds : dict
        ``{name: (low, high)}`` at ``level``: the estimate +- q * sd, ``q`` the quantile of
        Student's t with ``dof`` degrees of freedom (the normal's when ``dof`` is 0).
    sd : dict
        ``{name: standard error}``: the bootstrap's standard deviation, scaled by
        ``sqrt(G / (G - p))`` for ``G`` resampled cycles and ``p`` parameters.
    level : float
    n_boot : int
        Replicates whose refit succeeded.
    seed : int
    method : str
    dof : int
        ``G - p`` (0: white noise, the normal quantile).
    """

    KIND = "intervals"
    _LOAD = {"bounds": lambda d: {k: tuple(v) for k, v in d["bounds"].items()}}

    bounds: dict
    sd: dict
    level: float
    n_boot: int
    seed: int
    method: str = "parametric bootstrap through the record-span processing"
    dof: int = 0

    def with_machine_scale(self, low, high, names, moves=None):
        """These intervals with the parameters ``names`` widened by a machine scale known
        only to ``[low, high]`` (see :func:`bootstrap_intervals`), and each parameter of
        ``moves`` (``{name: (move at low, move at high)}``) by how far it moves there."""
        lo_s, hi_s = scale_bounds((low, high))
        moves = moves or {}
        bounds = {}
        for k, (a, b) in self.bounds.items():
            if k in names:
                ends = (a / lo_s, a / hi_s, b / lo_s, b / hi_s)
                a, b = min(ends), max(ends)
            elif k in moves:
                a, b = a + min(0.0, *moves[k]), b + max(0.0, *moves[k])
            bounds[k] = (a, b)
        others = (
            f"; the other parameters by their refit's move at the range's ends ({', '.join(moves)})"
            if moves
            else ""
        )
        return replace(
            self,
            bounds=bounds,
            method=f"{self.method}; forces widened by the machine's scale, known to "
            f"[{lo_s:.4f}, {hi_s:.4f}] (calibration){others}",
        )

    def as_dict(self):
        return {
            "bounds": {k: list(v) for k, v in self.bounds.items()},
            "sd": dict(self.sd),
            "level": self.level,
            "n_boot": self.n_boot,
            "seed": self.seed,
            "method": self.method,
            "dof": self.dof,
        }


# Webb's six-point weights: mean 0, variance 1, and more distinct replicates than signs when
# a record has a dozen cycles
_WEBB = np.array([-np.sqrt(1.5), -1.0, -np.sqrt(0.5), np.sqrt(0.5), 1.0, np.sqrt(1.5)])


def _cycle_weights(fold, rng):
    """One Webb weight per cycle of ``fold``, at each folded sample, ndarray of shape (m,)."""
    c = np.clip(((fold.td - fold.origin) // fold.duration).astype(int), 0, fold.n_cycles - 1)
    return rng.choice(_WEBB, fold.n_cycles)[c]


def _replicate(scenario, law, observe, ref, rng, *, tolerances=None, noise="cycles"):
    """A synthetic copy of ``ref`` made by ``law`` (the same span, states and sample times).

    Every block is simulated from a state drawn from its state fit's covariance (the fit
    with ``scenario``'s machine); its noise
    is, with ``noise="cycles"``, the record's own residual against ``law`` (force and
    penetration) with each cycle's multiplied by one random weight (a wild bootstrap by
    cycles: what repeats within a cycle, correlated noise, an onset's timing, a misfit the
    model leaves, is kept, and only its sign and size vary between cycles), or white noise
    of the record's level (``"white"``)."""
    from ..verify.trajectory import simulated_motion

    span = ref.span
    # the states a run on this machine starts from (re-estimated where it is not the
    # record's: stiffening supports), as the noise floor's replicates draw them
    starts = [b.state_for(scenario).draw(rng) for b in span.blocks]
    hist, zs = simulated_motion(
        scenario, law, span, tolerances=tolerances, starts=starts, observe=observe
    )
    if noise == "cycles":
        fit_F, fit_Z = simulated_motion(scenario, law, span, tolerances=tolerances, observe=observe)
        blocks = []
        for b, h, z, f0, z0 in zip(span.blocks, hist, zs, fit_F, fit_Z, strict=True):
            v = _cycle_weights(b.fold, rng)
            blocks.append(replace(b, F=h + v * (b.F - f0), Z=z + v * (b.Z - z0)))
        blocks = tuple(blocks)
    else:
        blocks = tuple(
            replace(
                b,
                F=h + rng.normal(0.0, span.sigma_f, h.size),
                Z=z + rng.normal(0.0, span.sigma_z, z.size),
            )
            for b, h, z in zip(span.blocks, hist, zs, strict=True)
        )
    span2 = replace(span, blocks=blocks)
    imps = tuple(span2.measured(onset_record_time=ref.impulse.onset))
    return replace(ref, span=span2, blocks=imps, impulse=imps[-1], _source=None)


def _refit_replicate(context, k):
    """The coefficients of one bootstrap replicate's least-squares refit (as
    :func:`~discovery.vibroimpact.fit.identification.identify` without short first, uncertainty or
    check; a task of the executor; the replicates are in the forked context, so no record is
    copied), None when it fails."""
    scenarios, replicates, model, settings = context
    method, xtol, budget = "least-squares", 1e-5, settings["max_simulations"]
    try:
        records = _checked(scenarios, replicates[k], model, max_simulations=budget)
        obj = _Objective(
            records,
            model,
            settings["criterion"],
            settings["tolerances"],
            max(int(budget), 2 * len(records)),
            observe=settings["observe"],
        )
        x, _ = _fitted(obj, method, xtol, budget)
    except (IntegrationError, NoContactError):  # a replicate without contact in a block
        return None
    return np.array(obj.law(x).coefficients, dtype=float)


_GN_STEPS = 2  # the Gauss-Newton steps of a "two-step" replicate


def _step_replicate(context, k):
    """The coefficients after two Gauss-Newton steps from the fitted model on one bootstrap
    replicate (a task of the executor, as :func:`_refit_replicate`), None when it fails."""
    scenarios, replicates, model, settings = context
    records = list(zip(scenarios, replicates[k], strict=True))
    obj = _Objective(
        records,
        model,
        settings["criterion"],
        settings["tolerances"],
        10**9,
        observe=settings["observe"],
    )
    x = np.ones(len(model.coefficients))
    for _ in range(_GN_STEPS):
        try:
            if obj.evaluations(x) is None:
                return None
            r, J = obj.residuals(x), obj.jacobian(x)
        except (IntegrationError, NoContactError):  # a replicate without contact in a block
            return None
        if not (np.all(np.isfinite(r)) and np.all(np.isfinite(J))):
            return None
        x = x + np.linalg.lstsq(J, -r, rcond=None)[0]
    return np.array(model.coefficients, dtype=float) * x


REFITS = {"two-step": _step_replicate, "full": _refit_replicate}

MIN_CYCLE_DOF = 3
"""The fewest resampled cycles beyond the parameters (``G - p``) for the bootstrap by
cycles; below it (a period-four orbit over 12 periods: three cycles) the replicates take
white noise of the record's level."""


@dataclass(frozen=True, repr=False)
class BootstrapIntervalsSettings(Settings):
    """The options of :func:`bootstrap_intervals` (each is also a keyword of it; see its
    parameters)."""

    n_boot: int = option(30, Real(5, integer=True))
    seed: int = option(0, Real(0, integer=True))
    level: float = option(0.95, Real(0, 1, open_low=True, open_high=True))
    max_simulations: int = option(60, Real(2, integer=True))
    criterion: str = option("I2", Choice(*CRITERIA))
    tolerances: object = option(None, (Tolerances, None))
    workers: object = option(1, (None, Real(1, integer=True)))
    refit: str = option("two-step", Choice(*INTERVAL_REFITS))
    noise: str = option("cycles", Choice(*INTERVAL_NOISE))
    machine_scale: object = option(None, (tuple, list, None))
    observe: object = option(None)
    domains: object = option(None, (dict, None))


def force_names(model):
    """The names of ``model``'s parameters that are forces per unit of motion (the law's
    coefficients, and an effect's parameter whose unit is a force's, such as the unloading
    damping's N s/m): they scale with the machine, an offset, a lag or a set do not."""
    law, _, _ = model_parts(model)
    names = set(law.names)
    free = getattr(model, "free_effects", None)
    for effect in free() if free is not None else ():
        p = effect.parameters[0]
        if str(p.unit).startswith("N"):
            names.add(p.name)
    return names


@takes(BootstrapIntervalsSettings)
def bootstrap_intervals(
    scenario, reference, model, *, settings=None, executor=None, progress=None, **options
):
    """Intervals of ``model``'s coefficients by a bootstrap through the record-span
    processing (the comment above).

    Parameters
    ----------
    scenario : Scenario or sequence of Scenario
    reference : Reference or sequence of Reference
        Records prepared with positions (a record span); others have no bootstrap.
    model : ForceLaw or Model
        The fitted law (or a model with effect parameters, :func:`identify.model_parts`).
    settings : BootstrapIntervalsSettings, optional
        The options below in one object; keywords override its fields.
    n_boot : int
        Replicates (>= 5).
    seed : int
        Seed of ``numpy.random.default_rng``.
    level : float
        Two-sided level in (0, 1).
    max_simulations : int
        Budget of each replicate's full refit.
    criterion : str
    tolerances : Tolerances, optional
    workers : int or None
        Processes for the replicates' refits (default 1; ``None``: every core).  The
        replicates are drawn in this process, in order, and only their refits run in
        parallel, so the intervals do not depend on it.
    executor : Executor, optional
        Where the refits run (:mod:`discovery.numerics.executor`); overrides ``workers``
        and is not closed here.
    progress : callable, optional
        ``progress("bootstrap intervals", done, total)`` as the refits finish.
    refit : str
        ``"two-step"`` (default): two Gauss-Newton steps from the fitted model with the
        exact Jacobian (the comment above); ``"full"``: a least-squares refit.
    noise : str
        The replicates' noise (:data:`INTERVAL_NOISE`): ``"cycles"`` (default), the
        record's own residuals with one random weight per cycle (white noise when the
        cycles are too few: :data:`MIN_CYCLE_DOF`); ``"white"``, white noise of the
        record's level (a parametric bootstrap).
    machine_scale : (float, float), optional
        The factors within which the machine's scale is uncertain (a calibration's
        :attr:`~discovery.Calibration.scale_range`).  A machine ``s`` times the true one
        takes a law about ``s`` times the true one to reproduce the record's motions, so
        the intervals of the forces (:func:`force_names`) are widened to every value the
        range allows: ``[low / s_high, high / s_low]`` for a positive coefficient.  Every
        other parameter (a lag, an offset, a set, a mass loss) is widened by how far it
        moves with the machine at the range's two ends (two Gauss-Newton steps from the
        fit on the records themselves: four more simulations and Jacobians per record).
    observe : callable, optional
        The observation model every simulated force is read through (a known sensor lag:
        :func:`~discovery.vibroimpact.verify.sensors.observation`), beside the model's own.
    domains : dict, optional
        ``{name: (low, high)}``: parameters bounded on both sides (an exponent, a
        restitution).  The refits then run in two passes, a third of the replicates first:
        where their interval of one of these already covers its whole domain with a
        domain's width to spare on each side, the record does not tell that parameter, no
        later replicate can narrow it into its domain, and the intervals are the first
        pass's (their ``n_boot`` says how many).

    Returns
    -------
    Intervals or None
        ``None`` when a record has no span (no state to draw), a parameter is 0, or fewer
        than 5 refits succeeded.
    """
    s = BootstrapIntervalsSettings.of("bootstrap_intervals", settings, options)
    records = as_records(scenario, reference)
    if any(getattr(ref, "span", None) is None for _, ref in records):
        return None
    if any(c == 0 for c in model.coefficients):
        return None  # a parameter at 0 sets no scale for the refits
    law, machine, observe = model_parts(model, s.observe)
    # the resampled cycles against the parameters (see the comment above): too few, and the
    # replicates take white noise of the record's level instead
    G = sum(b.fold.n_cycles for _, ref in records for b in ref.span.blocks)
    few = s.noise == "cycles" and G - len(model.names) < MIN_CYCLE_DOF
    noise = "white" if few else s.noise
    rng = np.random.default_rng(s.seed)
    replicates = []  # drawn here, in order: the rng's sequence does not depend on workers
    for _ in range(s.n_boot):
        try:
            replicates.append(
                [
                    _replicate(
                        machine(sc, ref),
                        law,
                        observe,
                        ref,
                        rng,
                        tolerances=s.tolerances,
                        noise=noise,
                    )
                    for sc, ref in records
                ]
            )
        except IntegrationError:
            continue
    context = (
        [sc for sc, _ in records],
        replicates,
        model,
        {
            "criterion": s.criterion,
            "max_simulations": s.max_simulations,
            "tolerances": s.tolerances,
            "observe": s.observe,
        },
    )
    how = _Resampling(cycles=G, noise=noise, few=few, refit=s.refit, level=s.level, seed=s.seed)
    passes = _Passes(len(replicates), s.domains, progress)
    draws, iv = [], None
    for jobs in passes.jobs():
        refits = map_on(
            REFITS[s.refit],
            jobs,
            context,
            workers=s.workers,
            executor=executor,
            done=passes.done(jobs),
        )
        draws += [d for d in refits if d is not None]
        iv = _intervals(np.array(draws), model, how) if len(draws) >= 5 else None
        if iv is not None and passes.spanned(iv):
            break
    if iv is None:
        return None
    if s.machine_scale is not None:
        forces = force_names(model)
        moves = _scale_moves(records, model, s.machine_scale, forces, context[3])
        iv = iv.with_machine_scale(*s.machine_scale, names=forces, moves=moves)
    return iv


def _scale_moves(records, model, scale, forces, settings):
    """How far each parameter of ``model`` other than ``forces`` moves with the machine at
    either end of its scale's range: ``{name: (move at low, move at high)}``, each by two
    Gauss-Newton steps from the fitted model on the records themselves ({} where a step
    fails or the scale is fixed).  A machine ``s`` times the true one with forces ``s``
    times the true ones moves exactly as the true one, so the forces follow the scale in
    closed form; the recorded force is not scaled, though, and what a lag, an offset or a
    mass loss takes up of that misfit is measured here."""
    lo, hi = scale_bounds(scale)
    others = [k for k, n in enumerate(model.names) if n not in forces]
    if not others or hi - lo < 1e-12:
        return {}
    est = np.array(model.coefficients, dtype=float)
    refs = [[ref for _, ref in records]]
    moved = []
    for f in (lo, hi):
        context = ([sc.scaled(f) for sc, _ in records], refs, model, settings)
        theta = _step_replicate(context, 0)
        if theta is None:
            return {}
        moved.append(theta - est)
    return {model.names[k]: (float(moved[0][k]), float(moved[1][k])) for k in others}


@dataclass(frozen=True)
class _Passes:
    """The refits' passes over ``n`` replicates: all at once, or (with ``domains``, see
    :func:`bootstrap_intervals`) a third first and the rest after it unless the first
    pass's intervals already span a bounded parameter's domain."""

    n: int
    domains: object
    progress: object

    def jobs(self):
        """The passes' replicate indices, in order."""
        first = max(5, self.n // 3) if self.domains else self.n
        return [range(first), range(first, self.n)] if first < self.n else [range(self.n)]

    def done(self, jobs):
        """The progress callback of the pass ``jobs`` (counted among all replicates)."""
        if self.progress is None:
            return None
        return lambda k, _n: self.progress("bootstrap intervals", jobs.start + k, self.n)

    def spanned(self, iv):
        """Whether intervals ``iv`` cover a bounded parameter's whole domain with its width
        to spare on each side (never without ``domains``)."""
        for name, (lo, hi) in (self.domains or {}).items():
            b = iv.bounds.get(name)
            if b is not None and b[0] <= lo - (hi - lo) and b[1] >= hi + (hi - lo):
                return True
        return False


@dataclass(frozen=True)
class _Resampling:
    """How the replicates were made: ``G`` cycles, their noise, whether the cycles were too
    few (white noise instead), the refit, the level and the seed."""

    cycles: int
    noise: str
    few: bool
    refit: str
    level: float
    seed: int


def cycle_spread(G, p, level=0.95):
    """``(scale, quantile)`` of a bootstrap over ``G`` resampled cycles fitting ``p``
    parameters (the comment above): its spread scaled by ``sqrt(G / (G - p))`` and the
    ``level`` interval's quantile of Student's t with ``G - p`` degrees of freedom."""
    dof = G - p
    return float(np.sqrt(G / dof)), t_quantile(dof, 0.5 + level / 2)


def cycle_widening(G, p, level=0.95):
    """The factor that turns a percentile interval of a bootstrap over ``G`` resampled
    cycles fitting ``p`` parameters into one with :func:`cycle_spread`'s rule: each side's
    distance from the estimate times ``scale * quantile / z``, ``z`` the normal's quantile
    (the percentile interval's, for a normal spread); 1 where ``G <= p``."""
    if G <= p:
        return 1.0
    scale, q = cycle_spread(G, p, level)
    return scale * q / normal_quantile(0.5 + level / 2)


def _intervals(D, model, how):
    """The :class:`Intervals` of the refitted coefficients ``D`` (replicates x parameters)
    around ``model``'s: normal quantiles on the spread for white noise; for the cycles, the
    spread scaled by ``sqrt(G / (G - p))`` and Student's t with ``G - p`` degrees of freedom
    (the comment above)."""
    names = list(model.names)
    est = np.array(model.coefficients, dtype=float)
    sd = D.std(axis=0, ddof=1)
    dof, G = 0, how.cycles
    z = normal_quantile(0.5 + how.level / 2)
    if how.noise == "cycles":
        dof = G - len(names)
        scale, z = cycle_spread(G, len(names), how.level)
        sd = sd * scale
    method = (
        f"wild bootstrap by cycles (the record's residuals, one weight per cycle; Student t "
        f"with {dof} degrees of freedom)"
        if how.noise == "cycles"
        else "parametric bootstrap"
        + (
            f" (white noise of the record's level: {G} cycles for {len(names)} parameters "
            "are too few to resample)"
            if how.few
            else ""
        )
    )
    step = "two Gauss-Newton steps" if how.refit == "two-step" else "a least-squares refit"
    return Intervals(
        bounds={
            n: (float(e - z * s), float(e + z * s)) for n, e, s in zip(names, est, sd, strict=True)
        },
        sd={n: float(s) for n, s in zip(names, sd, strict=True)},
        level=float(how.level),
        n_boot=len(D),
        seed=int(how.seed),
        method=f"{method} through the record-span processing ({step} per replicate)",
        dof=int(dof),
    )
