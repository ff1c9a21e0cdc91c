"""``advise``: the operating point where a next record separates the candidate laws.

candidates (a fit's equivalent models, or laws) + knobs' bounds + safe region + noise ->
coarse grid over amplitude x frequency (x m2) -> every point evaluated
(:mod:`~discovery.vibroimpact.advise.separation`: each candidate to its steady state, every
pair judged by the verdict's rule) -> the best points refined -> :class:`AdviseResult`.
"""

import os
import time
from dataclasses import dataclass, replace

from ..._api._progress import reports_progress, tick
from ..._api._settings import Settings, option, takes
from ..._api._validate import Instance, Real, params
from ...errors import InputError
from ...numerics.executor import make_executor
from ..dynamics import Tolerances
from ..model.scenario import Scenario
from .candidates import (
    MAX_CANDIDATES,
    MAX_RECORD_SAMPLES,
    Knobs,
    NoiseModel,
    SafeRegion,
    unique_laws,
)
from .refit import refitted_separations
from .result import AdviseResult
from .separation import inseparable, point_job, rank_key

__all__ = ["advise"]


@dataclass(frozen=True)
class _Context:
    """What every point's evaluation reads (shared by the executor's workers)."""

    scenario: Scenario
    laws: tuple
    noise: NoiseModel
    safe: SafeRegion
    tolerances: object = None


def _check_size(laws, knobs, noise):
    """Refuse work no run should start: more candidates than :data:`MAX_CANDIDATES` (every
    pair is judged at every point) or predicted records longer than
    :data:`MAX_RECORD_SAMPLES` samples at the lowest frequency of the bounds."""
    if len(laws) > MAX_CANDIDATES:
        raise InputError(
            f"{len(laws)} candidate laws: at most {MAX_CANDIDATES} (each pair is judged at every "
            "point); keep the fit's equivalent models that matter, or advise on a few at a time"
        )
    samples = noise.periods / (knobs.frequency[0] * noise.dt)
    if samples > MAX_RECORD_SAMPLES:
        raise InputError(
            f"a predicted record would hold {samples:.3g} samples ({noise.periods:g} periods at "
            f"{1 / noise.dt:.3g} Hz down to {knobs.frequency[0]:g} Hz); at most "
            f"{MAX_RECORD_SAMPLES:.0e}: lower --sample-rate or --periods"
        )


def _refined(knobs, coarse, done):
    """Jobs of a 3 x 3 grid at half the coarse spacing around the best usable points."""
    a, f, _ = knobs.axes()
    da = (a[1] - a[0]) / 2 if a.size > 1 else 0.0
    df = (f[1] - f[0]) / 2 if f.size > 1 else 0.0
    ignore = inseparable(coarse)
    best = sorted((p for p in coarse if p.usable), key=lambda p: rank_key(p, ignore))
    jobs, seen = [], set(done)
    for p in best[: knobs.refine]:
        for sa in (-1, 0, 1):
            for sf in (-1, 0, 1):
                q = (float(p.amplitude + sa * da), float(p.frequency + sf * df), p.m2)
                if q in seen or not knobs.contains(*q):
                    continue
                seen.add(q)
                jobs.append((*q, "refine"))
    return jobs


def _run(ex, context, jobs, progress, stage):
    out = [None] * len(jobs)
    for done, (i, point) in enumerate(ex.run(point_job, jobs, context), start=1):
        out[i] = point
        tick(progress, stage, done, len(jobs))
    return out


@dataclass(frozen=True, repr=False)
class AdviseSettings(Settings):
    """The options of :func:`advise` (each is also a keyword of it)."""

    workers: object = option(None, (None, Real(1, integer=True)))
    tolerances: object = option(None, (Tolerances, None))
    refit_simulations: int = option(40, Real(0, 10_000, integer=True))


@takes(AdviseSettings)
@params(
    scenario=Scenario,
    laws=(list, tuple, Instance("discovery.vibroimpact.fit.contact_fit", "ContactModelsResult")),
    knobs=Knobs,
    noise=NoiseModel,
    safe=(SafeRegion, None),
    executor=(None, Instance("discovery.numerics.executor", "Executor")),
)
@reports_progress
def advise(
    scenario,
    laws,
    knobs,
    noise,
    safe=None,
    *,
    settings=None,
    progress=None,
    executor=None,
    **options,
):
    """Find the operating point where the candidates' predicted records differ most.

    Parameters
    ----------
    scenario : Scenario
        The machine; its drive amplitude, frequency (and moulding mass) are varied.
    laws : list of ForceLaw, ContactModel or str, or a ContactModelsResult
        Two or more candidate laws (e.g. a fit's selected law and its equivalent models,
        :func:`~discovery.vibroimpact.advise.candidates.candidates_from_fit`), named
        contact models (:class:`~discovery.vibroimpact.model.contact_models.ContactModel`
        or their text, ``"flores: k=1.4e9, n=1.3, e=0.45"``), or the result of
        :func:`~discovery.fit_contact_models`: its selected model and those it reports
        equivalent (:func:`~discovery.vibroimpact.advise.candidates.contact_candidates`).
    knobs : Knobs
        Bounds of amplitude, frequency (and m2), grid and refinement.
    noise : NoiseModel
        The next record's noise (relative to its peak force), sampling and length.
    safe : SafeRegion, optional
        Peak force and penetration the machine may not exceed (default: no bound).
    settings : AdviseSettings, optional
        The options ``workers``, ``tolerances`` and ``refit_simulations`` in one object;
        keywords override its fields.
    workers : int, optional
        Processes (default: all cores); the result does not depend on it.
    tolerances : Tolerances, optional
    refit_simulations : int
        Simulations of each rival's refit at the advised point
        (:func:`~discovery.vibroimpact.advise.refit.refitted_separations`; 0: none).
    progress : callable or bool, optional
        ``progress(stage, done, total)`` after each point; None: a bar when the session is
        interactive, False: none (:mod:`discovery._api._progress`).
    executor : Executor, optional
        Where the points run (:mod:`discovery.numerics.executor`); not closed here.

    Returns
    -------
    AdviseResult
        ``best`` is the advised point; ``ranked()`` every usable point, best first.
    """
    s = AdviseSettings.of("advise", settings, options)
    t0 = time.perf_counter()
    laws = unique_laws(laws)
    _check_size(laws, knobs, noise)
    for k, law in enumerate(laws):
        # a rival certified on its record's rates may break condition (6) beyond them: it is
        # judged where its orbit stays inside, and a point where it leaves is evidence
        law.check_physical(scenario, f"candidate {k + 1}", dissipative_below=True)
    safe = SafeRegion() if safe is None else safe
    context = _Context(scenario, laws, noise, safe, s.tolerances)
    a, f, m = knobs.axes()
    jobs = [
        (float(x), float(y), None if z is None else float(z), "coarse")
        for x in a
        for y in f
        for z in m
    ]
    own = executor is None
    ex = executor
    if own:
        ex = make_executor(min(int(s.workers or os.cpu_count() or 1), len(jobs)))
    try:
        coarse = _run(ex, context, jobs, progress, "advise: coarse grid")
        more = _refined(knobs, coarse, [j[:3] for j in jobs])
        fine = _run(ex, context, more, progress, "advise: refining the best points") if more else []
        n_workers = getattr(ex, "workers", 1)
    finally:
        if own:
            ex.close()
    result = AdviseResult(
        laws=tuple(law.to_text() for law in laws),
        scenario=scenario.as_dict(),
        knobs=knobs,
        safe=safe,
        noise=noise,
        points=tuple(coarse + fine),
        seconds=time.perf_counter() - t0,
        settings={
            "workers": int(n_workers),
            "evaluated": len(jobs) + len(more),
            "refit_simulations": int(s.refit_simulations),
        },
    )
    best = result.best
    if s.refit_simulations and best is not None and best.pairs:
        tick(progress, "advise: refitting each rival at the advised point", 0, None)
        refit = refitted_separations(context, best, s.refit_simulations)
        result = replace(result, refit=refit, seconds=time.perf_counter() - t0)
    return result
