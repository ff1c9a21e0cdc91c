"""Coefficient intervals by a parametric bootstrap through the full processing.

The Jacobian standard errors of an output-error fit assume white residuals.  A record
compared over its span has two more sources of error that they miss: the machine's state
at the start of each block is itself estimated from noisy positions (its error moves
every later impact of the block), and the record's own sampling.  The bootstrap repeats
the whole experiment under the fitted model: for each replicate, every block is simulated
from a state drawn from that block's state-fit covariance, sampled at the record's own
sample times with the record's force noise, folded like the record, and refitted from the
fitted model; the spread of the refitted coefficients gives the intervals.  Seeds are
explicit.
"""

from dataclasses import dataclass, replace

import numpy as np

from .errors import InputError, IntegrationError

__all__ = ["Intervals", "bootstrap_intervals"]


@dataclass(frozen=True)
class Intervals:
    """Bootstrap intervals of a fitted law's coefficients.

    Attributes
    ----------
    bounds : dict
        ``{name: (low, high)}`` at ``level``: the estimate +- z * (bootstrap sd).
    sd : dict
        ``{name: bootstrap standard deviation}``.
    level : float
    n_boot : int
        Replicates whose refit succeeded.
    seed : int
    method : str
    """

    bounds: dict
    sd: dict
    level: float
    n_boot: int
    seed: int
    method: str = "parametric bootstrap through the record-span processing"

    def as_dict(self):
        return {"bounds": {k: list(v) for k, v in self.bounds.items()}, "sd": dict(self.sd),
                "level": self.level, "n_boot": self.n_boot, "seed": self.seed,
                "method": self.method}


def _replicate(scenario, law, observe, ref, rng, tolerances):
    """A synthetic copy of ``ref`` made by ``law`` (the same span, states and sample times)."""
    from .verify.trajectory import simulated_history

    span = ref.span
    starts = [b.state.draw(rng) for b in span.blocks]
    hist = simulated_history(scenario, law, span, tolerances=tolerances, starts=starts,
                             observe=observe)
    blocks = tuple(replace(b, F=h + rng.normal(0.0, span.sigma_f, h.size))
                   for b, h in zip(span.blocks, hist, strict=True))
    span2 = replace(span, blocks=blocks)
    imps = tuple(span2.measured(onset_record_time=ref.impulse.onset))
    return replace(ref, span=span2, blocks=imps, impulse=imps[-1], _source=None)


def bootstrap_intervals(scenario, reference, model, *, n_boot=30, seed=0, level=0.95,
                        max_simulations=60, criterion="I2", tolerances=None):
    """Intervals of ``model``'s coefficients by a parametric bootstrap (module docstring).

    Parameters
    ----------
    scenario : Scenario or sequence of Scenario
    reference : Reference or sequence of Reference
        Records prepared with positions (a record span); others have no bootstrap.
    model : ForceLaw or Model
        The fitted law (or a model with effect parameters, :func:`identify.model_parts`).
    n_boot : int
        Replicates (>= 5).
    seed : int
        Seed of ``numpy.random.default_rng``.
    level : float
        Two-sided level in (0, 1).
    max_simulations : int
        Budget of each replicate's refit.
    criterion : str
    tolerances : Tolerances, optional

    Returns
    -------
    Intervals or None
        ``None`` when a record has no span (no state to draw), a parameter is 0, or fewer
        than 5 refits succeeded.
    """
    from scipy.stats import norm

    from .identify import as_records, identify, model_parts

    if not (isinstance(n_boot, int) and n_boot >= 5):
        raise InputError(f"n_boot must be an integer >= 5; got {n_boot!r}")
    if not 0 < level < 1:
        raise InputError(f"level must be in (0, 1); got {level!r}")
    records = as_records(scenario, reference)
    if any(getattr(ref, "span", None) is None for _, ref in records):
        return None
    if any(c == 0 for c in model.coefficients):
        return None  # a parameter at 0 sets no scale for the refits
    law, machine, observe = model_parts(model)
    rng = np.random.default_rng(seed)
    draws = []
    for _ in range(n_boot):
        try:
            reps = [_replicate(machine(sc), law, observe, ref, rng, tolerances)
                    for sc, ref in records]
            res = identify([sc for sc, _ in records], reps, model, criterion=criterion,
                           method="least-squares", max_simulations=max_simulations,
                           tolerances=tolerances, uncertainty=False, short_first=False)
        except IntegrationError:
            continue
        draws.append(np.array(res.law.coefficients, dtype=float))
    if len(draws) < 5:
        return None
    D = np.array(draws)
    names = list(model.names)
    est = np.array(model.coefficients, dtype=float)
    sd = D.std(axis=0, ddof=1)
    z = float(norm.ppf(0.5 + level / 2))
    return Intervals(bounds={n: (float(e - z * s), float(e + z * s))
                             for n, e, s in zip(names, est, sd, strict=True)},
                     sd={n: float(s) for n, s in zip(names, sd, strict=True)},
                     level=float(level), n_boot=len(draws), seed=int(seed))
