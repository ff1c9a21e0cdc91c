"""Where the fit of a named contact model starts (:mod:`.contact_fit`): the best by I2 of a
linear least-squares fit to the record's contact samples, a grid of stiffness and damping
ratios, and for a model its spec says is seeded by another (Lankarani-Nikravesh and Flores
by Hunt-Crossley) that model's fit read at the record's impact velocity.  Each rule reads
the model's spec (:mod:`~discovery.vibroimpact.model.contact_registry`): its fixed
exponent, its damping term, its restitution relation."""

import numpy as np

from ...errors import VidiError
from ..model.contact_models import ContactModel, restitution_from_ratio
from ..model.contact_registry import CONTACT_MODELS
from ..model.law import Term
from .identification import contact_scales, record_start

__all__ = ["start_model", "record_samples", "from_seed", "regression_start"]

_START_N = (1.0, 1.25, 1.5)
_START_XI = (0.05, 0.2, 0.6)  # damping ratios of the start grid
# stiffness factors of the start grid: the contact time's spring is too stiff when the
# force rises slowly from zero (a Hertzian onset, Hunt-Crossley damping), where the
# record's threshold cuts the contact short
_START_K = (1.0, 0.3, 0.1)


def _model(name, k, n, d, e_start):
    """The model ``name`` of stiffness ``k``, exponent ``n`` and damping ``d``: the
    coefficient of its damping term (``c`` of ``dz``, ``lambda`` of ``z^n dz``), or for an
    impact-scaled model its ratio ``r``, read as a restitution clipped to ``e_start``'s
    ``(low, high)`` (``e_start[0]`` where the ratio means none)."""
    spec = CONTACT_MODELS[name]
    if spec.impact_scaled:
        e = restitution_from_ratio(name, d)
        d = min(max(e if np.isfinite(e) else e_start[0], e_start[1]), e_start[2])
    return ContactModel(name, spec.values(k, n, d))


def _candidate(name, k, n, c, *, v0, z0):
    """A start model of stiffness ``k``, exponent ``n`` and a dashpot ``c`` at the typical
    penetration ``z0`` [m] and impact velocity ``v0`` [m/s]."""
    spec = CONTACT_MODELS[name]
    d = c / z0**n if spec.damper_with_n else c
    return _model(name, k, n, d * v0 / k if spec.impact_scaled else d, (0.3, 0.1, 0.95))


def _start_candidates(name, scenario, ref):
    """The start grid of a model: ``n`` in :data:`_START_N` (the model's own when fixed),
    the record's spring-dashpot stiffness times :data:`_START_K`, damping ratios
    :data:`_START_XI`."""
    mu = scenario.m1 * scenario.m2 / (scenario.m1 + scenario.m2)
    _, v0, z0 = contact_scales(scenario, ref)
    fixed = CONTACT_MODELS[name].fixed_n
    out = []
    for n in (fixed,) if fixed else _START_N:
        (k,) = record_start(scenario, ref, [Term(n, 0.0)])
        for kf in _START_K:
            k_lin = kf * k * z0 ** (n - 1.0)  # the secant stiffness at the typical penetration
            for xi in _START_XI:
                c = 2.0 * xi * np.sqrt(k_lin * mu)
                out.append(_candidate(name, kf * k, n, c, v0=v0, z0=z0))
    return out


_LS_N = np.linspace(1.0, 1.6, 13)  # exponents the regression start tries
# a restitution read from a fit: where the ratio means none, and the range it is clipped to
_E_FIT = (0.05, 0.05, 0.98)


def _impact_velocities(samples):
    """Each sample's impact approach velocity: the penetration rate of its impact's first
    sample in contact."""
    imp = samples.impact
    first = {}
    for i, j in enumerate(imp):
        first.setdefault(int(j), max(float(samples.dzeta[i]), 1e-9))
    return np.array([first[int(j)] for j in imp])


def regression_start(name, samples):
    """The model fitted to the record's contact samples by linear least squares (each ``n``
    of :data:`_LS_N` for the models that fit it, the best kept), or None: a start near the
    answer when the positions are recorded (the samples are noisy, the fit by simulation
    then removes the bias).  Samples with a clipped force (under 5 % of the peak) are left
    out."""
    if samples is None or len(samples) < 10:
        return None
    keep = samples.F > 0.05 * np.max(samples.F)
    z = np.maximum(samples.zeta[keep], 0.0)
    dz, F = samples.dzeta[keep], samples.F[keep]
    v0 = _impact_velocities(samples)[keep]
    spec = CONTACT_MODELS[name]
    fixed = spec.fixed_n
    best, best_r = None, np.inf
    for n in (fixed,) if fixed else _LS_N:
        zn = z**n
        columns = [zn]
        if spec.damper is not None:  # a dashpot, Hunt-Crossley's term, or it over each v0
            damp = zn * dz if spec.damper_with_n else dz
            columns.append(damp / v0 if spec.impact_scaled else damp)
        A = np.column_stack(columns)
        coef, *_ = np.linalg.lstsq(A, F, rcond=None)
        r = float(np.sum((A @ coef - F) ** 2))
        k = float(coef[0])
        c = max(float(coef[1]), 0.0) if len(coef) > 1 else 0.0
        if not (k > 0 and r < best_r):
            continue
        # an impact-scaled model's second coefficient is k r (lambda = k r / v0)
        best, best_r = _model(name, k, n, c / k if spec.impact_scaled else c, _E_FIT), r
    return best


def from_seed(name, fit, scenario, ref):
    """A start of an impact-scaled model (Lankarani-Nikravesh, Flores) from the fit of the
    model its spec is seeded by (Hunt-Crossley): the same force at the record's typical
    impact velocity (``r = lambda v0 / k``, ``lambda`` the seed's damping coefficient), or
    None."""
    if fit is None or fit.consistent is None:
        return None
    p = fit.parameters
    v0 = contact_scales(scenario, ref)[1]
    r = CONTACT_MODELS[fit.model].damping(p) * v0 / p["k"]
    if not np.isfinite(restitution_from_ratio(name, r)):
        return None
    return _model(name, p["k"], p["n"], r, _E_FIT)


def start_model(name, records, tolerances, extra=(), observe=None):
    """The start of a model's fit: the best of its start grid (and ``extra`` starts) by
    the mean I2 (one simulation per record and candidate; the simulated force read through
    ``observe``, a known sensor's observation model)."""
    from ..verify import evaluate

    sc0, ref0 = records[0]
    best, best_v = None, np.inf
    for cand in [*_start_candidates(name, sc0, ref0), *(m for m in extra if m is not None)]:
        vals = []
        for sc, ref in records:
            ev = evaluate(sc, cand.law, ref, tolerances=tolerances, floor=False, observe=observe)
            vals.append(ev.criteria["I2"] if ev.status == "ok" else np.inf)
        v = float(np.mean(vals))
        if v < best_v or best is None:
            best, best_v = cand, v
    return best


def record_samples(scenario, reference, lag=0.0):
    """The contact samples of every record that holds positions, as one set (each
    record's impacts their own groups, so each keeps its own approach velocity), or None
    when no record has them (force records, prepared
    :class:`~discovery.vibroimpact.verify.Reference` objects).  With records at several
    operating points the impacts arrive at several velocities, and the regression start
    separates a constant ``lambda`` from one set by each impact's ``v0``.  ``lag``: a known
    force sensor's time constant, the samples then of the force before it
    (:meth:`~discovery.vibroimpact.data.measurement.Measurement.unlagged`)."""
    from ..data.measurement import Measurement
    from ..data.samples import contact_samples, join_samples
    from .records import pair_records

    parts = []
    for sc, meas in pair_records(scenario, reference):
        if not isinstance(meas, Measurement):
            continue
        try:
            part = contact_samples(meas.unlagged(lag), period=sc.period)
        except (VidiError, ValueError):
            continue
        if len(part):
            parts.append(part)
    return join_samples(parts) if parts else None
