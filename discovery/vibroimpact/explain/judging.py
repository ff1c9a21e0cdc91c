"""The rules a model or a refit is judged by in the missing-effect loop: within the noise,
the recorded motion, a repulsive contact spring, a parameter within its bounds and away from 0.
"""

import numpy as np

from ..fit.records import contact_scales
from ..verify.motion import MOTION_CRITERION
from .effects import effect


def _present(eff, model, res, negligible=0.0):
    """The effect's parameter is away from 0 by more than 2 standard errors and larger than
    ``negligible`` (:func:`negligible`: a value whose effect on the force is below about
    0.1 % of its peak explains no gap; a refit that lands there carried a refit of the law)."""
    name = eff.parameters[0].name
    v = model.value(eff)
    se = res.standard_errors.get(name)
    return bool(
        v != 0.0
        and abs(v) > negligible
        and (se is None or not np.isfinite(se) or abs(v) > 2.0 * se)
    )


NEGLIGIBLE = 0.1
"""An effect's parameter below this fraction of its small step
(:func:`~discovery.vibroimpact.explain.effects.small_step`: about 1 % of the peak force, 1 %
of the contact time for a time constant) is negligible: it is not named."""


def negligible(small):
    """The largest negligible value of a parameter whose small step is ``small``."""
    return NEGLIGIBLE * abs(float(small))


def _within_noise(evs, criterion):
    """Every record in the measured regime, with a floor, and ``criterion`` within its
    consistency limit (:meth:`~discovery.vibroimpact.verify.Evaluation.within`)."""
    return all(e.same_regime and e.noise_floor and e.within(criterion) for e in evs)


#: the contact-time criterion (the symmetric difference of the contact supports): where the
#: force and the penetration are within their limits and it alone fails, it is the gap, and
#: an effect is named only where its refit makes the model consistent (:func:`supports_gap`)
SUPPORTS_CRITERION = "I4"


def supports_gap(evs, criterion):
    """Whether ``criterion`` and the penetration are within their limits on every record
    and the contact time (:data:`SUPPORTS_CRITERION`) alone fails: the contact supports of
    a noisy record, or an effect that moves the onsets and losses more than the force."""
    if not (_within_noise(evs, criterion) and _motion_within(evs)):
        return False
    failing = _failing(evs)
    return failing == [SUPPORTS_CRITERION]


def _motion_within(evs):
    """The recorded penetration (I5) within its consistency limit on every record that has
    it: a law that trades spring for damping matches the force, not the motion, and is
    still to be explained."""
    return all(e.within(MOTION_CRITERION, absent=True) for e in evs)


def _worse(k, before, after, evs):
    """Whether a refit takes criterion ``k`` further from the record and beyond its limit on
    a record."""
    if k not in before or k not in after or after[k] <= before[k]:
        return False
    return any(k in e.limits and e.criteria.get(k, 0.0) > e.limits[k] for e in evs)


def _motion_worse(before, after, evs):
    """Whether a refit takes the recorded penetration (I5) further from the record and
    beyond its limit on a record: a fit of the force by another motion (a sensor lag that
    smears the force of a too-soft spring), which names nothing."""
    return _worse(MOTION_CRITERION, before, after, evs)


def _force_worse(criterion, gap, before, after, evs):
    """Whether a refit judged by the penetration's gap (``gap`` is I5: the force was within
    its limit) takes the force's ``criterion`` further from the record and beyond its limit:
    a fit of the motion by another force, which names nothing."""
    return gap == MOTION_CRITERION and _worse(criterion, before, after, evs)


def _failing(evs):
    """The criteria beyond their consistency limit in any record."""
    out = []
    for e in evs:
        out += [k for k in e.failing() if k not in out]
    return out or ["the comparison"]


#: where the elastic branch must push: these shares of the records' typical penetration
_PUSH_AT = (1e-3, 1e-2, 0.1, 0.3, 1.0)


def _repulsive(law, records):
    """Whether the law's elastic branch pushes the bodies apart from first touch to the
    records' typical penetration ``z0`` (at :data:`_PUSH_AT` of it): a refit that turns
    the contact spring into a pull has explained the residual by undoing the contact, not
    by the effect (a start that already pulls is not held against the effect).  At ``z0``
    alone a Hertz term's refit passed with the linear spring pulling below a tenth of it
    (``-1.55e10*z + 9.41e12*z^1.5``: survey draw 31, an unloading damper named as Hertz
    stiffening)."""
    for sc, ref in records:
        _, _, z0 = contact_scales(sc, ref)
        if not all(float(law.polynomial(f * z0, 0.0)) > 0 for f in _PUSH_AT):
            return False
    return True


def _keeps_repulsive(refit, model, records):
    """Whether a refit keeps the contact spring pushing (:func:`_repulsive`); a start that
    already pulls is not held against it."""
    return _repulsive(refit.law, records) or not _repulsive(model.law, records)


def _in_bounds(eff, model):
    """Whether the effect's parameter in ``model`` is within its physical bounds."""
    lo, hi = eff.parameters[0].bounds
    return bool(lo <= model.value(eff) <= hi)


def out_of_bounds(model):
    """The effects of ``model`` whose parameter a refit took outside its physical bounds
    (a refit of every parameter can push an effect named earlier past its bound: a
    penetration-velocity coupling turned negative beside stiffening supports)."""
    return [e for e in map(effect, model.effects) if not _in_bounds(e, model)]


def _keeps_signs(refit, model):
    """Whether every loading coefficient of ``model``'s law that is not negative stays so
    in the ``refit`` (a term an effect adds is held by the effect's bounds): a damper
    refitted to ``-8.3e7*zd`` beside a contact offset on survey draw 33 had traded the
    contact's damping for the offset."""
    before = dict(zip(model.law.terms, model.law.coefficients, strict=True))
    return all(
        c >= 0
        for t, c in zip(refit.law.terms, refit.law.coefficients, strict=True)
        if before.get(t, -1.0) >= 0
    )


def physical(refit, model, records):
    """Whether a refit of ``model`` stays physical: every effect within its bounds
    (:func:`out_of_bounds`), the contact spring still pushing (:func:`_keeps_repulsive`),
    no loading coefficient turned negative (:func:`_keeps_signs`).  One that is not stands
    for nothing: no baseline, no winner, no start."""
    return (
        not out_of_bounds(refit)
        and _keeps_repulsive(refit, model, records)
        and _keeps_signs(refit, model)
    )
