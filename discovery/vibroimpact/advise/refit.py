"""Whether the advised point still separates the candidates once each rival is refitted.

A point's separation judges every candidate at its fitted coefficients.  The next step of
the loop is a fit with the new record, in which a rival is refitted and can absorb part of
the difference.  At the advised point, each rival's coefficients are refitted to the other
candidate's predicted record (output error, least squares, from its own values) and judged
again by the verdict's rule.  A refit to the predicted record alone is the rival's best
chance: a joint fit with the record it was fitted on constrains it more, so the refitted
separation is a lower bound of what that fit will show.
"""

from dataclasses import dataclass

from ...errors import IntegrationError, VidiError
from ..fit.identification import identify
from .separation import _direction, _orbit, _predicted_reference, at_point

__all__ = ["RefitSeparation", "refitted_separations"]


@dataclass(frozen=True)
class RefitSeparation:
    """A pair's separation at the advised point with each rival refitted.

    Attributes
    ----------
    pair : (int, int)
        Candidate indices ``(i, j)``.
    directions : (float, float)
        The verdict's ratio of candidate ``j`` refitted to ``i``'s predicted record, and of
        ``i`` refitted to ``j``'s (``inf``: the refitted law has no orbit with contact
        there, or its fit failed to simulate).
    laws : (str, str)
        The refitted laws (``j``'s, ``i``'s), or the message of a failed refit.
    nested : (bool, bool)
        Whether the refitted law of each direction holds every term of the law whose record
        it is refitted to: it can reduce to that law (its own terms near zero), so that
        direction tells them apart by the extra terms' intervals, not by a rejection.
    """

    pair: tuple
    directions: tuple
    laws: tuple
    nested: tuple = (False, False)

    @property
    def separation(self):
        """The smaller direction over those not :attr:`nested` (both when both are): the
        pair stays separated when it is > 1."""
        kept = [r for r, n in zip(self.directions, self.nested, strict=True) if not n]
        return min(kept or self.directions)

    def to_dict(self):
        return {
            "pair": list(self.pair),
            "directions": [_num(v) for v in self.directions],
            "laws": list(self.laws),
            "nested": list(self.nested),
        }

    @classmethod
    def from_dict(cls, d):
        return cls(
            tuple(int(k) for k in d["pair"]),
            tuple(float(v) for v in d["directions"]),
            tuple(str(t) for t in d["laws"]),
            tuple(bool(v) for v in d.get("nested", (False, False))),
        )


def _num(v):
    """A ratio as JSON keeps it (``inf`` as text)."""
    return "inf" if v == float("inf") else float(v)


def _toward(judged, other):
    """``judged`` with the coefficients of ``other`` on the terms they share and a
    thousandth of its own on the rest: a refit's second start, in the other's basin (a
    refit from its own values can stop at a regime boundary between them)."""
    theirs = other.as_dict()
    return judged.with_coefficients(
        [
            theirs.get(t.name, 1e-3 * c)
            for t, c in zip(judged.terms, judged.coefficients, strict=True)
        ]
    )


def _refit_direction(sc, judged, other, refs, settings):
    """``(ratio, law text)`` of ``judged`` refitted to ``other``'s predicted record
    ``refs`` (its noisy and clean references), from its own values and from
    :func:`_toward` ``other``, the better refit judged on them again."""
    tolerances, budget = settings
    best, why = (float("inf"), None), ""
    for start in (judged, _toward(judged, other)):
        try:
            res = identify(
                sc,
                refs[0],
                start,
                criterion="I2",
                method="least-squares",
                max_simulations=budget,
                tolerances=tolerances,
                check=False,
                progress=False,
            )
        except (IntegrationError, VidiError) as exc:
            why = f"refit failed: {exc}"
            continue
        ratio, _, _ = _direction(sc, res.law, refs, tolerances)
        if best[1] is None or ratio < best[0]:
            best = (ratio, res.law.to_text())
    return best if best[1] is not None else (float("inf"), why)


def refitted_separations(context, point, max_simulations=40):
    """Every pair of ``point`` judged with each rival refitted to the other's predicted
    record (see the module docstring).

    Parameters
    ----------
    context : _Context
        The advice's scenario, candidates, noise model and tolerances.
    point : Point
        A usable point (the advised one).
    max_simulations : int
        Simulations of each refit.

    Returns
    -------
    tuple of RefitSeparation
        One per pair whose two candidates have an orbit there (a pair separated on
        physics stays so).
    """
    sc = at_point(context.scenario, point.amplitude, point.frequency, point.m2)
    laws = context.laws
    refs = []
    for law, pred in zip(laws, point.predictions, strict=True):
        if pred.status != "ok":
            refs.append(None)
            continue
        refs.append(
            _predicted_reference(_orbit(sc, law, context.tolerances), sc, law, context.noise)
        )
    out = []
    for q in point.pairs:
        i, j = q.pair
        if refs[i] is None or refs[j] is None:
            continue
        how = (context.tolerances, max_simulations)
        r_ij, law_j = _refit_direction(sc, laws[j], laws[i], refs[i], how)
        r_ji, law_i = _refit_direction(sc, laws[i], laws[j], refs[j], how)
        nested = (_holds(laws[j], laws[i]), _holds(laws[i], laws[j]))
        out.append(RefitSeparation((i, j), (r_ij, r_ji), (law_j, law_i), nested))
    return tuple(out)


def _holds(a, b):
    """Whether law ``a`` has every term of law ``b`` (loading and unloading) and the same
    permanent set (a refit moves the coefficients only): refitted, it can become ``b``."""
    return (
        {t.name for t in b.terms} <= {t.name for t in a.terms}
        and {t.name for t in b.unloading} <= {t.name for t in a.unloading}
        and b.permanent_set == a.permanent_set
    )
