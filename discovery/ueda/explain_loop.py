"""The missing-effect workflow for Ueda's forced oscillators: from a model missing a
term, name the missing physical effect from this system's catalogue
(:data:`discovery.ueda.effects.EFFECTS`), add it, refit, and show the gap shrink.

One iteration (:func:`explain`):

1. **Fit** the current terms by least squares on the weak form of the equation (the
   regression of :func:`discovery.ueda.equation_discovery.discover`, ``G c = b``, with the
   support fixed: no thresholding) and take the weak-form residual ``r = b - G_S c``.
2. **Score** every applicable catalogue effect (its terms not yet in the model) by a
   Lagrange-multiplier (score) test for an omitted variable: ``z`` the effect's weak-form
   column made orthogonal to the current columns, ``LM = (z^T r)^2 / V``, where ``V``
   estimates ``Var(z^T r)`` under "the effect is absent" from the residual itself
   (heteroskedasticity- and autocorrelation-consistent, Newey-West with Bartlett weights
   over twice the lag at which the overlapping test windows stop sharing samples: the
   rows are correlated, so the plain ``n R^2`` would be too large).  ``LM ~ chi^2(1)``;
   an effect is significant when its p-value is below ``alpha`` / (effects scored)
   (Bonferroni), and eligible when the coefficient it would take
   (``z^T r / z^T z``) is within its physical bounds (a sign).
3. **Name** the eligible effect whose column explains the largest share of the residual
   (the largest drop of the weak-form residual when refitted, not the largest LM: LM says
   how sure the test is that a term is missing, the share how much of the gap it
   closes), add its term, **refit** (least squares on the new support; standard
   errors from the same sandwich), and measure the gap before and after by
   **simulation**: :func:`discovery.ueda.verify`
   (energy distance of strobe points against the noise floor of the record's own block
   halves, regime, Lyapunov exponent), with the weak-form residual beside it.  Other
   significant effects the record cannot tell from the named one (added instead, each
   leaves the named one insignificant, and beside it each is insignificant) are reported
   as ``equivalent``.
4. Stop when no effect is significant (the model is then consistent, or the catalogue
   does not explain what is left), or after ``max_iterations`` additions.

The decision to name an effect rests on the score test (the equation), the simulation
shows the consequence; a start model already consistent with the record has nothing
significant to add (measured false-discovery rates in the README).
"""

import time
from dataclasses import dataclass, replace

import numpy as np

from .._api._settings import Settings, option, takes
from .._api._validate import Array, Real, params
from ..catalogue import select
from ..errors import InputError
from ..numerics.tolerances import Tolerances
from .effects import EFFECTS, in_bounds
from .explanation import Explanation, Iteration
from .polynomial import TERMS
from .record import check_forcing, smooth
from .verification import verify
from .weak_fits import Fit, WeakFits, WeakSettings
from .weak_form import window_half_width

__all__ = ["Explanation", "Iteration", "explain", "parse_terms", "DEFAULT_START"]

#: the negres terms without the van der Pol damping ``x^2 x'``
DEFAULT_START = ("x'", "x^3")


def _norm(name):
    return name.replace("*", "").replace(" ", "").replace("v", "x'")


_BY_NORM = {_norm(n): n for n in TERMS}


def parse_terms(spec):
    """Library terms from ``"x',x^3"`` (or a sequence of names); ``*`` and spaces are
    optional (``x^2*x'``, ``x^2 x'``), ``v`` stands for ``x'``; ``"none"`` or an empty
    sequence: no terms (the forcing alone).  Returns names of :data:`TERMS`."""
    if isinstance(spec, str):
        if spec.strip().lower() == "none":
            return ()
        parts = [p for p in (s.strip() for s in spec.split(",")) if p]
        if not parts:
            raise InputError(
                "the start terms are empty; give library terms such as "
                '"x\',x^3" (or none for the forcing alone)'
            )
    else:
        parts = [str(p) for p in spec]
    out = []
    for p in parts:
        name = _BY_NORM.get(_norm(p))
        if name is None:
            raise InputError(
                f'unknown term {p!r}; the library terms are {", ".join(TERMS)} (e.g. "x\',x^3")'
            )
        if name not in out:
            out.append(name)
    return tuple(sorted(out, key=TERMS.index))


@dataclass(frozen=True)
class _Measure:
    """The criteria of a fit: its weak-form residual and, with ``simulate``, its
    verification by simulation against the record ``t, x`` (:func:`verify`, with the
    record's smoothing ``sm`` and ``verify_kwargs``)."""

    weak: WeakFits
    t: np.ndarray
    x: np.ndarray
    sm: object
    simulate: bool
    verify_kwargs: dict

    def __call__(self, fit):
        crit = {"residual_rms": self.weak.residual_rms(fit)}
        if not self.simulate:
            return crit, None
        v = verify(fit.model, self.t, self.x, smoothed=self.sm, **self.verify_kwargs)
        crit.update(
            {
                "energy_distance": v.energy_distance,
                "floor_q95": v.floor_q95,
                "energy_consistent": v.energy_consistent,
                "regime_record": v.regime_record,
                "regime_model": v.regime_model,
                "regime_agrees": v.regime_agrees,
                "lyapunov": v.lyapunov,
                "consistent": v.consistent,
                "diverged": v.diverged,
            }
        )
        return crit, v


def _floor(weak, sm, ver):
    """The noise floors the criteria are judged against."""
    floor = {
        "residual_rms": weak.noise_rms / weak.b_rms,
        "noise_sd": sm.noise_sd,
        "noise_fraction_of_range": sm.noise_sd / float(np.ptp(sm.x)),
    }
    if ver is not None:
        floor.update(
            {"energy_distance_q95": ver.floor_q95, "energy_distance_median": ver.floor_median}
        )
    return floor


@dataclass(frozen=True)
class _Settings:
    """What the loop may name and when it stops: the ``catalogue`` of effects, the
    family-wise level ``alpha``, the budget ``max_iterations``, and whether the gap is
    simulated."""

    catalogue: tuple
    alpha: float
    max_iterations: int
    simulate: bool


@dataclass(frozen=True)
class _State:
    """The model the loop has reached: its ``terms``, ``fit``, criteria ``crit`` and the
    verification ``ver`` behind them (None without simulation)."""

    terms: tuple
    fit: Fit
    crit: dict
    ver: object


@dataclass(frozen=True)
class _Round:
    """One round of score tests: the candidate effects, their ``scores``, the Bonferroni
    ``gate``, the ``eligible`` scores (significant and within bounds, largest share of the
    residual first) and the significant effects ``out_of_bounds``."""

    cands: list
    scores: list
    gate: float
    eligible: list
    out_of_bounds: list

    def effect(self, effect_id):
        return next(e for e in self.cands if e.id == effect_id)


class _Loop:
    """The loop of :func:`explain`: score the catalogue's effects not in the model, add the
    most significant one within its bounds, refit, measure; stop when none is significant or
    the budget of additions is used."""

    def __init__(self, weak, measure, settings, state):
        self.weak, self.measure, self.settings, self.state = weak, measure, settings, state
        self.iterations, self.stopped = [], ""

    def run(self):
        while True:
            terms = set(self.state.terms)
            cands = [e for e in self.settings.catalogue if not set(e.terms) & terms]
            if not cands:
                self.stopped = "every catalogue effect is already in the model"
                return
            scored = self._scores(cands)
            if not scored.eligible or len(self.iterations) >= self.settings.max_iterations:
                self._stop(scored)
                return
            self._add(scored)

    def _scores(self, cands):
        """Score tests of the candidate effects at the current fit (Bonferroni gate)."""
        scores = [self.weak.score(self.state.fit, e) for e in cands]
        gate = self.settings.alpha / len(scores)
        for s, e in zip(scores, cands, strict=True):
            s["significant"] = bool(s["p"] < gate)
            s["in_bounds"] = in_bounds(e, [s["direction"][n] for n in e.terms])
        eligible = sorted(
            (s for s in scores if s["significant"] and s["in_bounds"]), key=lambda s: -s["share"]
        )
        out_of_bounds = [s["effect"] for s in scores if s["significant"] and not s["in_bounds"]]
        return _Round(cands, scores, gate, eligible, out_of_bounds)

    def _stop(self, scored):
        """The last iteration: nothing (more) is named, and why."""
        settings, state = self.settings, self.state
        why = (
            "the model is consistent with the record"
            if state.crit.get("consistent")
            else "the model is still inconsistent with the record: the catalogue does not "
            "explain the rest (the coefficients' uncertainty or an effect outside the "
            "catalogue may)"
            if settings.simulate
            else "the gap was not simulated"
        )
        if scored.eligible:
            text = (
                f"the budget of {settings.max_iterations} added effect(s) is used; still "
                f"significant: {', '.join(s['effect'] for s in scored.eligible)}"
            )
        else:
            text = (
                f"no catalogue effect is significant (score tests at family-wise "
                f"level {settings.alpha:g}, gate {scored.gate:.2g} for {len(scored.scores)} "
                "effects)"
            )
            if scored.out_of_bounds:
                text += "; significant but outside its physical bounds (not named): " + ", ".join(
                    scored.out_of_bounds
                )
        self.iterations.append(
            Iteration(
                effect=None,
                evidence={"text": text},
                scores=scored.scores,
                criteria_before=state.crit,
                criteria_after=state.crit,
                parameters={},
                model_before=state.fit.model,
                model_after=state.fit.model,
                verification_before=state.ver,
                verification_after=state.ver,
            )
        )
        self.stopped = f"{text}; {why}"

    def _equivalent(self, eff, scored, fit2):
        """Confounded alternatives: significant effects that, added instead, would leave
        the named one insignificant while they are insignificant beside it."""
        weak, terms, gate = self.weak, self.state.terms, scored.gate
        equivalent = []
        after = {e.id: weak.score(fit2, e) for e in scored.cands if e is not eff}
        for s in scored.eligible[1:]:
            alt = scored.effect(s["effect"])
            alt_fit = weak.fit(tuple(sorted(set(terms) | set(alt.terms), key=TERMS.index)))
            if after[alt.id]["p"] >= gate and weak.score(alt_fit, eff)["p"] >= gate:
                equivalent.append(alt.id)
        return equivalent

    def _add(self, scored):
        """Name the most significant effect within its bounds, refit and measure."""
        weak, state, gate = self.weak, self.state, scored.gate
        crit = state.crit
        best = scored.eligible[0]
        eff = scored.effect(best["effect"])
        new_terms = tuple(sorted(set(state.terms) | set(eff.terms), key=TERMS.index))
        fit2 = weak.fit(new_terms)
        crit2, ver2 = self.measure(fit2)
        params = weak.parameters(fit2, eff.terms)
        equivalent = self._equivalent(eff, scored, fit2)
        text = (
            f"score test LM = {best['lm']:.4g} (p = {best['p']:.2g} < gate {gate:.2g}, "
            f"alpha {self.settings.alpha:g} over {len(scored.scores)} effects); its term "
            f"explains {100 * best['share']:.1f} % of the weak-form residual; refitted "
            + ", ".join(f"{n} {p['value']:.4g} +- {p['stderr']:.2g}" for n, p in params.items())
            + f"; residual {crit['residual_rms']:.3g} -> {crit2['residual_rms']:.3g} "
            f"(noise floor {weak.noise_rms / weak.b_rms:.3g})"
        )
        if self.settings.simulate:
            text += (
                f"; energy distance {crit['energy_distance']:.3g} -> "
                f"{crit2['energy_distance']:.3g} (floor q95 {crit2['floor_q95']:.3g}), "
                f"regime {crit['regime_model']} -> {crit2['regime_model']} (record "
                f"{crit2['regime_record']})"
            )
        if equivalent:
            text += (
                "; the record cannot tell it from "
                + ", ".join(equivalent)
                + " (each, added, leaves the other insignificant)"
            )
        evidence = {
            "lm": best["lm"],
            "p": best["p"],
            "gate": gate,
            "share": best["share"],
            "text": text,
        }
        self.iterations.append(
            Iteration(
                effect=eff.id,
                evidence=evidence,
                scores=scored.scores,
                criteria_before=crit,
                criteria_after=crit2,
                parameters=params,
                model_before=state.fit.model,
                model_after=fit2.model,
                verification_before=state.ver,
                verification_after=ver2,
                equivalent=equivalent,
            )
        )
        self.state = _State(new_terms, fit2, crit2, ver2)


@dataclass(frozen=True, repr=False)
class UedaExplainSettings(Settings):
    """The options of :func:`explain` (each is also a keyword of it; see its parameters)."""

    alpha: float = option(0.01, Real(0, 1, open_low=True, open_high=True))
    max_iterations: int = option(3, Real(0, integer=True))
    effects: object = option(None, (None, list, tuple))
    half_width: object = option(None, (None, Real(2, integer=True)))
    order: int = option(4, Real(2, integer=True))
    fit_forcing: bool = option(True)
    noise: object = option(None, (None, Real(0)))
    simulate: bool = option(True)
    transient: int = option(200, Real(0, integer=True))
    periods: int = option(2000, Real(1, integer=True))
    resamples: int = option(200, Real(0, integer=True))
    seed: int = option(0, Real(0, integer=True))
    tolerances: object = option(None, (Tolerances, None))


@takes(UedaExplainSettings)
@params(t=Array(1), x=Array(1), B=Real(), nu=Real(0, open_low=True))
def explain(t, x, B, nu, start_terms=DEFAULT_START, *, settings=None, **options):
    """Explain the gap between a start model and a record by named effects (see the
    module docstring).

    Parameters
    ----------
    t, x : array
        Uniformly sampled record (as for :func:`~discovery.ueda.equation_discovery.discover`).
    B, nu : float
        The known forcing ``B cos(nu t)``.
    start_terms : str or sequence of str
        Library terms of the start model (``"x',x^3"``: negres without the van der Pol
        damping, the default), see :func:`parse_terms`.
    settings : UedaExplainSettings, optional
        The options below in one object; keywords override its fields.
    alpha : float
        Family-wise level of the score tests (Bonferroni over the effects scored).
    max_iterations : int
        Effects added at most.
    effects : sequence of str, optional
        Catalogue ids to consider (default all).
    half_width, order : int
        Test windows of the weak form (as :func:`discover`).
    fit_forcing : bool
        Fit the forcing's coefficient (it should come out 1) or fix it at 1.
    noise : float, optional
        Known noise sd as a fraction of x's range (default: estimated from the
        smoothing residual).
    simulate : bool
        Measure the gap by simulation (:func:`verify`); without it only the weak-form
        residual is reported (the decisions do not depend on the simulation).
    transient, periods, resamples, seed, tolerances
        Of :func:`verify`.

    Returns
    -------
    Explanation
    """
    s = UedaExplainSettings.of("explain", settings, options)
    t_start = time.perf_counter()
    start = parse_terms(start_terms)
    catalogue = select(EFFECTS, s.effects)
    t, x, spp = check_forcing(t, x, B, nu)
    T = 2 * np.pi / nu
    hs = window_half_width(t.size, spp, s.half_width)
    sm = smooth(t, x, spp)
    if s.noise is not None:
        sm = replace(sm, noise_sd=float(s.noise * np.ptp(x)))
    weak = WeakFits(t, x, sm, B=B, nu=nu, settings=WeakSettings(hs, int(s.order), s.fit_forcing))
    measure = _Measure(
        weak=weak,
        t=t,
        x=x,
        sm=sm,
        simulate=s.simulate,
        verify_kwargs=dict(
            transient=s.transient,
            periods=s.periods,
            resamples=s.resamples,
            seed=s.seed,
            tolerances=s.tolerances,
        ),
    )
    fit = weak.fit(start)
    crit, ver = measure(fit)
    loop = _Loop(
        weak,
        measure,
        _Settings(tuple(catalogue), s.alpha, s.max_iterations, s.simulate),
        _State(start, fit, crit, ver),
    )
    loop.run()
    final = loop.state
    coef, se = weak.coefficients(final.fit)
    recorded = {
        "alpha": s.alpha,
        "max_iterations": int(s.max_iterations),
        "effects": [e.id for e in catalogue],
        "half_width": hs,
        "order": int(s.order),
        "fit_forcing": bool(s.fit_forcing),
        "simulate": bool(s.simulate),
        "transient": s.transient,
        "periods": s.periods,
        "resamples": s.resamples,
        "seed": s.seed,
        "samples_per_period": float(spp),
        "record_periods": float((t[-1] - t[0]) / T),
        "n_windows": int(weak.G.shape[0]),
        "hac_lag": weak.lag,
        "method": "weak-form least squares on a fixed support; score (LM) tests with "
        "a Newey-West variance (Bartlett weights), Bonferroni gate; gap by "
        "simulation (verify)",
    }
    return Explanation(
        iterations=tuple(loop.iterations),
        start_model=fit.model,
        final_model=final.fit.model,
        start_terms=start,
        final_terms=final.terms,
        coefficients=coef,
        standard_errors=se,
        criteria_start=crit,
        criteria=final.crit,
        noise_floor=_floor(weak, sm, final.ver),
        consistent=final.crit.get("consistent"),
        stopped_because=loop.stopped,
        seconds=time.perf_counter() - t_start,
        settings=recorded,
        start_verification=ver,
        final_verification=final.ver,
    )
