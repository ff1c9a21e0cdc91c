"""The missing-effect workflow for Ueda's forced oscillators (issue 9, section 3): from a
model missing a term, name the missing physical effect from this system's catalogue
(:data:`discovery.ueda.effects.EFFECTS`), add it, refit, and show the gap shrink.

One iteration (:func:`explain`):

1. **Fit** the current terms by least squares on the weak form of the equation (the
   regression of :func:`discovery.ueda.discover.discover`, ``G c = b``, with the
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
   (the largest drop of the weak-form residual when refitted; ranking by LM instead
   named the van der Pol damping before the linear damping in 83 of 100 duffing records
   at 1 % noise), add its term, **refit** (least squares on the new support; standard
   errors from the same sandwich), and measure the gap before and after by
   **simulation**: :func:`discovery.ueda.discover.verify`
   (energy distance of strobe points against the noise floor of the record's own random
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
from dataclasses import dataclass, field, replace

import numpy as np
from scipy.stats import chi2

from .._printing import generic_lines, readable
from .._result import Result, part
from .._validate import Array, Real, params
from ..catalogue import select
from ..errors import InputError
from .discover import (
    FORCING,
    MONOMIALS,
    TERMS,
    ForcedPolynomial,
    _record_forcing,
    _test_function,
    smooth,
    verify,
    weak_system,
)
from .effects import EFFECTS, effect_dict, in_bounds

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


def _hac(U, lag):
    """Newey-West estimate of ``Var(sum_i U_i)`` (rows ``U_i``, Bartlett weights)."""
    U = U.reshape(U.shape[0], -1)
    V = U.T @ U
    for k in range(1, min(lag, U.shape[0] - 1) + 1):
        C = U[k:].T @ U[:-k]
        V += (1.0 - k / (lag + 1.0)) * (C + C.T)
    return V


@dataclass(frozen=True)
class _Fit:
    cols: tuple  # column indices of G (library terms, then the forcing's)
    coef: np.ndarray
    se: np.ndarray
    r: np.ndarray
    model: ForcedPolynomial


class _Weak:
    """The weak-form system of one record and least-squares fits on given supports."""

    def __init__(self, t, x, B, nu, half_width, order, fit_forcing, smoothed):
        self.B, self.nu = B, nu
        dt = float(t[1] - t[0])
        self.hs = int(half_width)
        G, b, self.centres = weak_system(t, x, smoothed.v, B, nu, self.hs, order=order)
        self.nt = len(MONOMIALS)
        self.fit_forcing = bool(fit_forcing)
        self.b = b if fit_forcing else b - G[:, self.nt]
        self.G = G
        self.stride = max(1, self.hs // 2)
        # rows share samples up to (2 hs) / stride rows apart; twice that for Bartlett
        self.lag = 2 * int(np.ceil(2 * self.hs / self.stride))
        self.b_rms = float(np.sqrt(np.mean(self.b**2))) or 1.0
        # the residual's floor: b's part from white measurement noise of sd noise_sd
        _, _, ddphi = _test_function(self.hs, order)
        w = np.full(ddphi.size, dt)
        w[0] = w[-1] = dt / 2
        H = self.hs * dt
        self.noise_rms = float(smoothed.noise_sd * np.linalg.norm(w * ddphi / H**2))

    def fit(self, terms):
        cols = tuple(TERMS.index(n) for n in terms) + ((self.nt,) if self.fit_forcing else ())
        if cols:
            X = self.G[:, cols]
            s = np.sqrt(np.mean(X**2, axis=0))
            s[s == 0] = 1.0
            Xs = X / s
            cs = np.linalg.lstsq(Xs, self.b, rcond=None)[0]
            r = self.b - Xs @ cs
            A = np.linalg.pinv(Xs.T @ Xs)
            cov = A @ _hac(Xs * r[:, None], self.lag) @ A
            coef, se = cs / s, np.sqrt(np.maximum(np.diag(cov), 0.0)) / s
        else:
            coef, se, r = np.zeros(0), np.zeros(0), self.b.copy()
        c = np.zeros(self.nt)
        forcing = 1.0
        for j, v in zip(cols, coef, strict=True):
            if j < self.nt:
                c[j] = v
            else:
                forcing = float(v)
        return _Fit(cols, coef, se, r, ForcedPolynomial(tuple(c), self.B, self.nu, forcing))

    def score(self, fit, eff):
        """The robust LM test of adding ``eff``'s terms to ``fit``."""
        k = [TERMS.index(n) for n in eff.terms]
        Z = self.G[:, k]
        if fit.cols:
            Q, _ = np.linalg.qr(self.G[:, fit.cols])
            Z = Z - Q @ (Q.T @ Z)
        zz = np.einsum("ij,ij->j", Z, Z)
        if np.any(zz <= 1e-24 * max(float(self.b @ self.b), 1e-300)):
            return {
                "effect": eff.id,
                "terms": list(eff.terms),
                "lm": 0.0,
                "p": 1.0,
                "share": 0.0,
                "direction": dict.fromkeys(eff.terms, 0.0),
                "note": "its columns are absorbed by the current terms",
            }
        s = Z.T @ fit.r
        V = _hac(Z * fit.r[:, None], self.lag)
        lm = float(s @ np.linalg.pinv(V) @ s) if np.all(np.diag(V) > 0) else 0.0
        direction = np.linalg.lstsq(Z, fit.r, rcond=None)[0]
        share = float((fit.r @ (Z @ direction)) / max(float(fit.r @ fit.r), 1e-300))
        return {
            "effect": eff.id,
            "terms": list(eff.terms),
            "lm": lm,
            "p": float(chi2.sf(lm, len(k))),
            "share": share,
            "direction": {n: float(d) for n, d in zip(eff.terms, direction, strict=True)},
        }

    def residual_rms(self, fit):
        return float(np.sqrt(np.mean(fit.r**2))) / self.b_rms

    def parameters(self, fit, terms):
        return {
            n: {
                "value": float(fit.coef[fit.cols.index(TERMS.index(n))]),
                "stderr": float(fit.se[fit.cols.index(TERMS.index(n))]),
            }
            for n in terms
        }

    def coefficients(self, fit):
        names = [TERMS[j] if j < self.nt else FORCING for j in fit.cols]
        coef = dict(zip(names, map(float, fit.coef), strict=True))
        se = dict(zip(names, map(float, fit.se), strict=True))
        if not self.fit_forcing:
            coef[FORCING], se[FORCING] = 1.0, 0.0
        return coef, se


@dataclass(frozen=True, eq=False)
class Iteration(Result):
    """One pass of the loop.

    Attributes
    ----------
    effect : str or None
        The effect named (None when this pass stopped the loop).
    evidence : dict
        For the named effect: ``lm`` (score statistic), ``p``, ``gate`` (the Bonferroni
        level), ``share`` (fraction of the weak-form residual's sum of squares its column
        explains), ``text``; otherwise ``text`` only.
    scores : list of dict
        Every scored effect: ``effect``, ``terms``, ``lm``, ``p``, ``share``,
        ``direction`` (the coefficient it would take), ``significant``, ``in_bounds``.
    criteria_before, criteria_after : dict
        ``residual_rms`` (weak form, relative to ``b``), ``energy_distance``,
        ``floor_q95``, ``energy_consistent``, ``regime_record``, ``regime_model``,
        ``regime_agrees``, ``lyapunov``, ``consistent``, ``diverged`` (the simulation
        entries only when simulating).
    parameters : dict
        ``{term: {"value", "stderr"}}`` of the added terms after the refit.
    model_before, model_after : ForcedPolynomial
    verification_before, verification_after : Verification or None
        The simulations behind the criteria (for figures).
    equivalent : list of str
        Significant effects the record cannot tell from the named one: added instead,
        each leaves the named one insignificant, and beside it each is insignificant.
    """

    KIND = "ueda-explain-iteration"
    _LOAD = {
        "model_before": lambda d: ForcedPolynomial.from_dict(d.get("model_before")),
        "model_after": lambda d: ForcedPolynomial.from_dict(d.get("model_after")),
    }

    effect: str | None
    evidence: dict
    scores: list
    criteria_before: dict
    criteria_after: dict
    parameters: dict
    model_before: ForcedPolynomial
    model_after: ForcedPolynomial
    verification_before: object = field(default=None, repr=False)
    verification_after: object = field(default=None, repr=False)
    equivalent: list = field(default_factory=list)

    def as_dict(self):
        return {
            "effect": self.effect,
            "evidence": self.evidence,
            "scores": self.scores,
            "equivalent": self.equivalent,
            "criteria_before": self.criteria_before,
            "criteria_after": self.criteria_after,
            "parameters": self.parameters,
            "model_before": _model_dict(self.model_before),
            "model_after": _model_dict(self.model_after),
        }


@readable
@dataclass(frozen=True, eq=False)
class Explanation(Result):
    """Outcome of :func:`explain`.

    Attributes
    ----------
    iterations : tuple of Iteration
    start_model, final_model : ForcedPolynomial
    start_terms, final_terms : tuple of str
    coefficients, standard_errors : dict
        Of the final model's terms and the forcing (weak-form least squares; standard
        errors from the autocorrelation-consistent sandwich).
    criteria_start, criteria : dict
        Of the start and the final model (see :class:`Iteration`).
    noise_floor : dict
        ``residual_rms`` (the relative weak-form residual that white measurement noise of
        the estimated sd alone gives), ``energy_distance_q95`` and ``_median`` (the record's
        random halves), ``noise_sd``, ``noise_fraction_of_range``.
    consistent : bool
        The final model's attractor is consistent with the record's (None without
        simulation).
    stopped_because : str
    """

    KIND = "ueda-explain"
    _LOAD = {
        "iterations": lambda d: tuple(part(Iteration, it) for it in d["iterations"]),
        "start_model": lambda d: ForcedPolynomial.from_dict(d.get("start_model")),
        "final_model": lambda d: ForcedPolynomial.from_dict(d.get("final_model")),
        "start_terms": lambda d: tuple(d["start_terms"]),
        "final_terms": lambda d: tuple(d["final_terms"]),
        "settings": lambda d: (
            d["method"] if isinstance(d.get("method"), dict) else d.get("settings")
        ),
    }

    iterations: tuple
    start_model: ForcedPolynomial
    final_model: ForcedPolynomial
    start_terms: tuple
    final_terms: tuple
    coefficients: dict
    standard_errors: dict
    criteria_start: dict
    criteria: dict
    noise_floor: dict
    consistent: object
    stopped_because: str
    seconds: float = 0.0
    settings: dict = field(default_factory=dict)
    start_verification: object = field(default=None, repr=False)
    final_verification: object = field(default=None, repr=False)

    @property
    def effects_added(self):
        """Ids of the effects named, in order."""
        return tuple(it.effect for it in self.iterations if it.effect)

    @property
    def gap(self):
        """The start model's gap against the final model's: ``{criterion: {"before",
        "after", "ratio"}}`` for the weak-form residual and the energy distance."""
        out = {}
        for k in ("residual_rms", "energy_distance"):
            if k in self.criteria_start:
                a, b = self.criteria_start[k], self.criteria[k]
                out[k] = {"before": a, "after": b, "ratio": (a / b) if b > 0 else float("inf")}
        return out

    def as_dict(self, settings_key="settings"):
        """The document's keys; ``settings_key`` names the method's settings (the command
        line keeps ``settings`` for its options)."""
        return {
            "start_terms": list(self.start_terms),
            "final_terms": list(self.final_terms),
            "effects_added": list(self.effects_added),
            "iterations": [it.as_dict() for it in self.iterations],
            "start_model": _model_dict(self.start_model),
            "final_model": {
                **_model_dict(self.final_model),
                "coefficients": self.coefficients,
                "standard_errors": self.standard_errors,
            },
            "criteria_start": self.criteria_start,
            "criteria": self.criteria,
            "gap": self.gap,
            "noise_floor": self.noise_floor,
            "consistent": self.consistent,
            "stopped_because": self.stopped_because,
            "catalogue": [
                effect_dict(e) for e in EFFECTS if e.id in self.settings.get("effects", ())
            ],
            settings_key: self.settings,
            "seconds": self.seconds,
        }

    def _lines(self):
        return generic_lines(self)


def _model_dict(m):
    return {**m.as_dict(), "equation": m.text()}


def _check_settings(alpha, max_iterations, order, noise):
    """The settings :func:`explain` checks beyond their types."""
    if not (0 < alpha < 1):
        raise InputError(f"alpha must be in (0, 1); got {alpha!r}")
    if (
        isinstance(max_iterations, bool)
        or not isinstance(max_iterations, int | np.integer)
        or max_iterations < 0
    ):
        raise InputError(f"max_iterations must be an integer >= 0; got {max_iterations!r}")
    if int(order) < 2:
        raise InputError(f"order must be >= 2, got {order}")
    if noise is not None and not (np.isfinite(noise) and noise >= 0):
        raise InputError(f"noise must be a finite fraction >= 0, got {noise}")


class _Measure:
    """The criteria of a fit: its weak-form residual and, with ``simulate``, its
    verification by simulation against the record (:func:`verify`)."""

    def __init__(self, weak, t, x, sm, simulate, verify_kwargs):
        self.weak, self.t, self.x, self.sm = weak, t, x, sm
        self.simulate, self.verify_kwargs = simulate, verify_kwargs

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


class _Loop:
    """The loop of :func:`explain`: score the catalogue's effects not in the model, add the
    most significant one within its bounds, refit, measure; stop when none is significant or
    the budget of additions is used."""

    def __init__(
        self, weak, measure, catalogue, alpha, max_iterations, simulate, terms, fit, crit, ver
    ):
        self.weak, self.measure, self.catalogue = weak, measure, catalogue
        self.alpha, self.max_iterations, self.simulate = alpha, max_iterations, simulate
        self.terms, self.fit, self.crit, self.ver = terms, fit, crit, ver
        self.iterations, self.stopped = [], ""

    def run(self):
        while True:
            cands = [e for e in self.catalogue if not set(e.terms) & set(self.terms)]
            if not cands:
                self.stopped = "every catalogue effect is already in the model"
                return
            scores, gate, eligible, out_of_bounds = self._scores(cands)
            if not eligible or len(self.iterations) >= self.max_iterations:
                self._stop(scores, gate, eligible, out_of_bounds)
                return
            self._add(cands, scores, gate, eligible)

    def _scores(self, cands):
        """Score tests of the candidate effects at the current fit (Bonferroni gate)."""
        scores = [self.weak.score(self.fit, e) for e in cands]
        gate = self.alpha / len(scores)
        for s, e in zip(scores, cands, strict=True):
            s["significant"] = bool(s["p"] < gate)
            s["in_bounds"] = in_bounds(e, [s["direction"][n] for n in e.terms])
        eligible = sorted(
            (s for s in scores if s["significant"] and s["in_bounds"]), key=lambda s: -s["share"]
        )
        out_of_bounds = [s["effect"] for s in scores if s["significant"] and not s["in_bounds"]]
        return scores, gate, eligible, out_of_bounds

    def _stop(self, scores, gate, eligible, out_of_bounds):
        """The last iteration: nothing (more) is named, and why."""
        state = (
            "the model is consistent with the record"
            if self.crit.get("consistent")
            else "the model is still inconsistent with the record: the catalogue does not "
            "explain the rest (the coefficients' uncertainty or an effect outside the "
            "catalogue may)"
            if self.simulate
            else "the gap was not simulated"
        )
        if eligible:
            text = (
                f"the budget of {self.max_iterations} added effect(s) is used; still "
                f"significant: {', '.join(s['effect'] for s in eligible)}"
            )
        else:
            text = (
                f"no catalogue effect is significant (score tests at family-wise "
                f"level {self.alpha:g}, gate {gate:.2g} for {len(scores)} effects)"
            )
            if out_of_bounds:
                text += "; significant but outside its physical bounds (not named): " + ", ".join(
                    out_of_bounds
                )
        fit, crit, ver = self.fit, self.crit, self.ver
        self.iterations.append(
            Iteration(None, {"text": text}, scores, crit, crit, {}, fit.model, fit.model, ver, ver)
        )
        self.stopped = f"{text}; {state}"

    def _equivalent(self, eff, cands, eligible, fit2, gate):
        """Confounded alternatives: significant effects that, added instead, would leave
        the named one insignificant while they are insignificant beside it."""
        weak, terms = self.weak, self.terms
        equivalent = []
        after = {e.id: weak.score(fit2, e) for e in cands if e is not eff}
        for s in eligible[1:]:
            alt = next(e for e in cands if e.id == s["effect"])
            alt_fit = weak.fit(tuple(sorted(set(terms) | set(alt.terms), key=TERMS.index)))
            if after[alt.id]["p"] >= gate and weak.score(alt_fit, eff)["p"] >= gate:
                equivalent.append(alt.id)
        return equivalent

    def _add(self, cands, scores, gate, eligible):
        """Name the most significant effect within its bounds, refit and measure."""
        weak, crit = self.weak, self.crit
        best = eligible[0]
        eff = next(e for e in cands if e.id == best["effect"])
        new_terms = tuple(sorted(set(self.terms) | set(eff.terms), key=TERMS.index))
        fit2 = weak.fit(new_terms)
        crit2, ver2 = self.measure(fit2)
        params = weak.parameters(fit2, eff.terms)
        equivalent = self._equivalent(eff, cands, eligible, fit2, gate)
        text = (
            f"score test LM = {best['lm']:.4g} (p = {best['p']:.2g} < gate {gate:.2g}, "
            f"alpha {self.alpha:g} over {len(scores)} effects); its term explains "
            f"{100 * best['share']:.1f} % of the weak-form residual; refitted "
            + ", ".join(f"{n} {p['value']:.4g} +- {p['stderr']:.2g}" for n, p in params.items())
            + f"; residual {crit['residual_rms']:.3g} -> {crit2['residual_rms']:.3g} "
            f"(noise floor {weak.noise_rms / weak.b_rms:.3g})"
        )
        if self.simulate:
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
                eff.id,
                evidence,
                scores,
                crit,
                crit2,
                params,
                self.fit.model,
                fit2.model,
                self.ver,
                ver2,
                equivalent,
            )
        )
        self.terms, self.fit, self.crit, self.ver = new_terms, fit2, crit2, ver2


@params(
    t=Array(1),
    x=Array(1),
    B=Real(),
    nu=Real(0, open_low=True),
    alpha=Real(0, 1, open_low=True),
    max_iterations=Real(1, integer=True),
    effects=(None, list, tuple),
    seed=Real(0, integer=True),
)
def explain(
    t,
    x,
    B,
    nu,
    start_terms=DEFAULT_START,
    *,
    alpha=0.01,
    max_iterations=3,
    effects=None,
    half_width=None,
    order=4,
    fit_forcing=True,
    noise=None,
    simulate=True,
    transient=200,
    periods=2000,
    resamples=200,
    seed=0,
    tolerances=None,
):
    """Explain the gap between a start model and a record by named effects (see the
    module docstring).

    Parameters
    ----------
    t, x : array
        Uniformly sampled record (as for :func:`~discovery.ueda.discover.discover`).
    B, nu : float
        The known forcing ``B cos(nu t)``.
    start_terms : str or sequence of str
        Library terms of the start model (``"x',x^3"``: negres without the van der Pol
        damping, the default), see :func:`parse_terms`.
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
    t_start = time.perf_counter()
    _check_settings(alpha, max_iterations, order, noise)
    start = parse_terms(start_terms)
    catalogue = select(EFFECTS, effects)
    t, x, spp = _record_forcing(t, x, B, nu)
    T = 2 * np.pi / nu
    hs = max(7, int(round(spp / 4))) if half_width is None else int(half_width)
    if hs < 2 or 2 * hs + 1 > t.size // 4:
        raise InputError(
            f"the record ({t.size} samples) is too short for test windows of "
            f"{2 * hs + 1} samples; record more periods"
        )
    sm = smooth(t, x, spp)
    if noise is not None:
        sm = replace(sm, noise_sd=float(noise * np.ptp(x)))
    weak = _Weak(t, x, B, nu, hs, int(order), fit_forcing, sm)
    measure = _Measure(
        weak,
        t,
        x,
        sm,
        simulate,
        dict(
            transient=transient,
            periods=periods,
            resamples=resamples,
            seed=seed,
            tolerances=tolerances,
        ),
    )
    fit = weak.fit(start)
    crit, ver = measure(fit)
    loop = _Loop(weak, measure, catalogue, alpha, max_iterations, simulate, start, fit, crit, ver)
    loop.run()
    coef, se = weak.coefficients(loop.fit)
    settings = {
        "alpha": alpha,
        "max_iterations": int(max_iterations),
        "effects": [e.id for e in catalogue],
        "half_width": hs,
        "order": int(order),
        "fit_forcing": bool(fit_forcing),
        "simulate": bool(simulate),
        "transient": transient,
        "periods": periods,
        "resamples": resamples,
        "seed": seed,
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
        final_model=loop.fit.model,
        start_terms=start,
        final_terms=loop.terms,
        coefficients=coef,
        standard_errors=se,
        criteria_start=crit,
        criteria=loop.crit,
        noise_floor=_floor(weak, sm, loop.ver),
        consistent=loop.crit.get("consistent"),
        stopped_because=loop.stopped,
        seconds=time.perf_counter() - t_start,
        settings=settings,
        start_verification=ver,
        final_verification=loop.ver,
    )
