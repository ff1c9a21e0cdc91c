"""Where the fit of a named contact model starts (:mod:`.contact_fit`): the best by I2 of a
linear least-squares fit to the record's contact samples, a grid of stiffness and damping
ratios, and for Lankarani-Nikravesh and Flores the Hunt-Crossley fit read at the record's
impact velocity."""

import numpy as np

from ...errors import VidiError
from ..model.contact_models import ContactModel, restitution_from_ratio
from ..model.law import Term
from .identification import contact_scales, record_start

__all__ = ["start_model", "record_samples", "from_hunt_crossley", "regression_start"]

_START_N = (1.0, 1.25, 1.5)
_START_XI = (0.05, 0.2, 0.6)  # damping ratios of the start grid
# stiffness factors of the start grid: the contact time's spring is too stiff when the
# force rises slowly from zero (a Hertzian onset, Hunt-Crossley damping), where the
# record's threshold cuts the contact short
_START_K = (1.0, 0.3, 0.1)


def _candidate(name, k, n, c, *, v0, z0):
    """A start model of stiffness ``k``, exponent ``n`` and a dashpot ``c`` at the typical
    penetration ``z0`` [m] and impact velocity ``v0`` [m/s]."""
    if name in ("kelvin-voigt", "hertz-damper"):
        return ContactModel(name, (k, c))
    if name == "hunt-crossley":
        return ContactModel(name, (k, n, c / z0**n))
    e = restitution_from_ratio(name, c / z0**n * v0 / k)
    e = e if np.isfinite(e) else 0.3
    return ContactModel(name, (k, n, min(max(e, 0.1), 0.95)))


def _start_candidates(name, scenario, ref):
    """The start grid of a model: ``n`` in :data:`_START_N` (the model's own when fixed),
    the record's spring-dashpot stiffness times :data:`_START_K`, damping ratios
    :data:`_START_XI`."""
    mu = scenario.m1 * scenario.m2 / (scenario.m1 + scenario.m2)
    _, v0, z0 = contact_scales(scenario, ref)
    fixed = {"kelvin-voigt": 1.0, "hertz-damper": 1.5}.get(name)
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
    fixed = {"kelvin-voigt": 1.0, "hertz-damper": 1.5}.get(name)
    best, best_r = None, np.inf
    for n in (fixed,) if fixed else _LS_N:
        zn = z**n
        if fixed:
            damp = dz  # a linear dashpot
        elif name == "hunt-crossley":
            damp = zn * dz
        else:
            damp = zn * dz / v0  # lambda = k r / v0: the second coefficient is k r
        A = np.column_stack([zn, damp])
        coef, *_ = np.linalg.lstsq(A, F, rcond=None)
        r = float(np.sum((A @ coef - F) ** 2))
        k, c = float(coef[0]), max(float(coef[1]), 0.0)
        if not (k > 0 and r < best_r):
            continue
        if fixed:
            cand = (k, c)
        elif name == "hunt-crossley":
            cand = (k, n, c)
        else:
            e = restitution_from_ratio(name, c / k)
            cand = (k, n, min(max(e if np.isfinite(e) else 0.05, 0.05), 0.98))
        best, best_r = ContactModel(name, cand), r
    return best


def from_hunt_crossley(name, fit, scenario, ref):
    """A Lankarani-Nikravesh or Flores start from a fitted Hunt-Crossley model: the same
    force at the record's typical impact velocity (``r = lambda v0 / k``), or None."""
    if fit is None or fit.consistent is None:
        return None
    p = fit.parameters
    v0 = contact_scales(scenario, ref)[1]
    e = restitution_from_ratio(name, p["lambda"] * v0 / p["k"])
    if not np.isfinite(e):
        return None
    return ContactModel(name, (p["k"], p["n"], min(max(e, 0.05), 0.98)))


def start_model(name, records, tolerances, extra=()):
    """The start of a model's fit: the best of its start grid (and ``extra`` starts) by
    the mean I2 (one simulation per record and candidate)."""
    from ..verify import evaluate

    sc0, ref0 = records[0]
    best, best_v = None, np.inf
    for cand in [*_start_candidates(name, sc0, ref0), *(m for m in extra if m is not None)]:
        vals = []
        for sc, ref in records:
            ev = evaluate(sc, cand.law, ref, tolerances=tolerances, floor=False)
            vals.append(ev.criteria["I2"] if ev.status == "ok" else np.inf)
        v = float(np.mean(vals))
        if v < best_v or best is None:
            best, best_v = cand, v
    return best


def record_samples(scenario, reference):
    """The contact samples of every record that holds positions, as one set (each
    record's impacts their own groups, so each keeps its own approach velocity), or None
    when no record has them (force records, prepared
    :class:`~discovery.vibroimpact.verify.Reference` objects).  With records at several
    operating points the impacts arrive at several velocities, and the regression start
    separates a constant ``lambda`` from one set by each impact's ``v0``."""
    from ..data.measurement import Measurement
    from ..data.samples import contact_samples, join_samples
    from .records import pair_records

    parts = []
    for sc, meas in pair_records(scenario, reference):
        if not isinstance(meas, Measurement):
            continue
        try:
            part = contact_samples(meas, period=sc.period)
        except (VidiError, ValueError):
            continue
        if len(part):
            parts.append(part)
    return join_samples(parts) if parts else None
