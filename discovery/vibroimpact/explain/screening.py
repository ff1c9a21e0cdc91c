"""Screening: the score (Lagrange-multiplier) test of every applicable catalogue effect at
the current model, and the significant effects ranked.
"""

from dataclasses import dataclass

import numpy as np

from ...numerics.distributions import chi2_sf_one
from .problem import _small_step


def _signature_agrees(eff, loc, top_phases):
    """Whether the localisation shows the effect's signature: its phases among the two
    with the largest shares, the grid's motion off beyond its noise (``"grid"``), or a
    significant trend across the impacts (``"drift"``)."""
    if set(eff.phases) & set(top_phases):
        return True
    if "grid" in eff.phases and (loc.get("grid") or {}).get("exceeds_noise"):
        return True
    return bool("drift" in eff.phases and (loc.get("drift") or {}).get("significant"))


@dataclass(frozen=True)
class _Linearisation:
    """The current model's residual on every record, the output Jacobian of its own
    coefficients (forward differences through full simulations) and the noise of the
    averaged cycles: what a score test needs."""

    problem: object
    records: list
    model: object
    r0: np.ndarray
    J: np.ndarray
    sigma: float

    @classmethod
    def at(cls, problem, records, model):
        r0 = problem.residual(model)
        return cls(
            problem=problem,
            records=records,
            model=model,
            r0=r0,
            J=_jacobian(problem, model, r0),
            sigma=problem.sigma(),
        )

    def score(self, eff):
        """The score test of ``eff``: ``effect``, ``lm``, ``p``, ``significant`` (set by the
        screening) and ``direction`` (the LM step), or a ``note`` without a sensitivity."""
        problem, model, r0, J, sigma = self.problem, self.model, self.r0, self.J, self.sigma
        # the sensitivity between h and 2h, not from 0: switching an effect on can change the
        # simulated history by a step of its own (an observation model resamples it)
        h = _small_step(eff, self.records)
        r1 = problem.residual(model.with_effect(eff, h))
        r2 = problem.residual(model.with_effect(eff, 2 * h)) if r1 is not None else None
        if r2 is None or sigma <= 0:
            return {
                "effect": eff.id,
                "lm": None,
                "p": None,
                "significant": False,
                "note": "its sensitivity could not be simulated",
            }
        s = (r2 - r1) / h
        if J.shape[1]:
            Q, _ = np.linalg.qr(J)
            s_perp = s - Q @ (Q.T @ s)
            r_perp = r0 - Q @ (Q.T @ r0)
        else:
            s_perp, r_perp = s, r0
        den = float(s_perp @ s_perp)
        lm = float((s_perp @ r_perp) ** 2 / (sigma**2 * den)) if den > 0 else 0.0
        return {
            "effect": eff.id,
            "lm": lm,
            "p": chi2_sf_one(lm),
            "significant": False,
            "direction": float(-(s_perp @ r_perp) / den) if den > 0 else 0.0,
        }


def _jacobian(problem, model, r0):
    law = model.law
    cols = []
    for i, c in enumerate(law.coefficients):
        h = 1e-4 * abs(c)
        coefs = list(law.coefficients)
        coefs[i] = c + h
        r1 = problem.residual(model.with_law(law.with_coefficients(coefs)))
        if r1 is None:
            continue
        cols.append((r1 - r0) / h)
    return np.column_stack(cols) if cols else np.zeros((r0.size, 0))


def _score(run, model, eff, local, spans):
    """An effect's score test: on the averaged cycle's linearisation, and a drift's (the
    mass loss) on the drift channel; on records compared over their span, where each block
    starts with the mass left, a drift is scored on the blocks too and the stronger test
    kept (a motion whose impulses vary from orbit to orbit hides a trend from the drift
    channel's few windows that the blocks' force histories show)."""
    if "drift" not in eff.phases:
        return local.score(eff)
    s = run.drift.score(model, eff, _small_step(eff, run.records))
    if spans:
        blocks = local.score(eff)
        if blocks.get("lm") is not None and blocks["lm"] > (s.get("lm") or 0.0):
            return {**blocks, "channel": "blocks"}
    return s


@dataclass
class _Screening:
    """The score tests of one iteration: the candidate effects, their scores, the
    family-wise level, the localisation's two largest phases, the significant effects ranked
    (and those without a local score) and whether the cycle is within its noise."""

    cands: list
    scores: list
    level: float
    top_phases: list
    ranked: list
    quiet: bool

    @classmethod
    def of(cls, run, step):
        """Score tests of the applicable effects at the current model (``step``); the
        significant ones ranked by their statistic."""
        model, loc = run.model, step.loc
        # a consistent cycle leaves only the drift to explain; one that fails the contact
        # time alone (:func:`~.judging.supports_gap`) is screened in full, and its refits
        # name an effect only where they make the model consistent
        quiet = step.cycle_ok
        cands = [
            e
            for e in run.catalogue
            if e.applicable(model)
            and (run.drift is not None or "drift" not in e.phases)
            and (not quiet or "drift" in e.phases)
        ]
        local = _Linearisation.at(run.problem, run.records, model)
        scores = [_score(run, model, e, local, run.spans) for e in cands]
        level = run.alpha / max(len(scores), 1)
        top_phases = sorted(loc["phases"], key=lambda p: -loc["phases"][p]["share"])[:2]
        for s, e in zip(scores, cands, strict=True):
            s["significant"] = bool(s["p"] is not None and s["p"] < level)
            s["signature_agrees"] = _signature_agrees(e, loc, top_phases)
        ranked = sorted((s for s in scores if s["significant"]), key=lambda s: -s["lm"])
        if any(s.get("channel") == "drift" for s in ranked):
            # a record that drifts has no steady cycle to compare: the drift comes first
            ranked = [s for s in ranked if s.get("channel") == "drift"]
        else:
            # an effect whose small step already changes the regime has no local score;
            # its refit (from the regression, over a ladder of values) still decides
            ranked += [s for s in scores if s["lm"] is None]
        return cls(
            cands=cands,
            scores=scores,
            level=level,
            top_phases=top_phases,
            ranked=ranked,
            quiet=quiet,
        )

    @property
    def by_id(self):
        """``{id: effect}`` of the candidate effects."""
        return {e.id: e for e in self.cands}
