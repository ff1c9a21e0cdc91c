"""The moulding's mass loss per contact, as the record shows it.

On each contact's own window the moulding's equation gives its mass at that contact:
``m2_j = int phi F / int phi (w2'' + g)`` (:class:`~.equations.MachineRows`, the anchored
windows).  A moulding that sheds a share ``mu`` of its mass at every contact's onset has
``m2_j = m2 (1 - mu)^n_j``, ``n_j`` the onsets up to that contact, so ``log m2_j`` falls
linearly in ``n_j``: one least squares over the records of a machine (an intercept per
record, the slope shared) gives ``mu`` with its standard error.  A constant mass leaves
the slope at 0 within its noise; a loss is *found* where the slope stands
:data:`SIGNIFICANCE` standard errors below 0.  The sheet's mass is then the machine's at the
record's start, not the average over the record a constant-mass calibration returns.
"""

import math
from dataclasses import dataclass

import numpy as np

from ...numerics.distributions import t_quantile
from ..data.contact_edges import contact_onsets

__all__ = ["Shedding", "shedding", "MIN_CONTACTS", "SIGNIFICANCE", "MATERIAL"]

#: the fewest contacts (over the records) that can show a loss
MIN_CONTACTS = 6
#: a loss is found when it stands this many standard errors above 0 (a t statistic; on
#: records of a constant mass the slope's |t| stayed below 1.2, on shedding ones 2.9-28)
SIGNIFICANCE = 4.0
#: a machine effect the sheet lacks (stiffening supports, a mass loss) is kept only where it
#: changes its force by at least this share over the records: a stiffening measured to 4 %
#: that moves the supports' force by 1e-6 (the paper's machine, motions without noise) is
#: the equations' quadrature error, not the machine
MATERIAL = 0.01


@dataclass(frozen=True)
class Shedding:
    """The loss per contact ``loss`` with its 95 % interval ``[low, high]``, its standard
    error, the contacts it was read from and whether it is found: :data:`SIGNIFICANCE`
    standard errors above 0, and the mass changed by :data:`MATERIAL` over the records."""

    loss: float
    low: float
    high: float
    se: float
    contacts: int
    found: bool


def _contact_masses(row, measurement, scenario):
    """``(log m2_j, n_j)`` over the contacts' windows of one record."""
    t = np.asarray(measurement.t, dtype=float)
    ch = measurement.channels
    zeta = np.asarray(ch["w1"], dtype=float) - np.asarray(ch["w2"], dtype=float)
    onsets = contact_onsets(t, np.asarray(measurement.F, dtype=float), scenario.period, zeta=zeta)
    a = row.anchored
    with np.errstate(divide="ignore", invalid="ignore"):
        mass = row.force[a] / row.moulding[a]
    n = np.searchsorted(onsets, row.centre[a], side="right").astype(float)
    ok = np.isfinite(mass) & (mass > 0)
    return np.log(mass[ok]), n[ok]


def shedding(rows, measurements, sheets):
    """The mass loss of records of one machine (``rows``: their
    :class:`~.equations.MachineRows`), or ``None`` when they hold too few contacts, or
    contacts all at one count, to show one."""
    ys, ns, record = [], [], []
    for r, (row, m, s) in enumerate(zip(rows, measurements, sheets, strict=True)):
        y, n = _contact_masses(row, m, s)
        ys.append(y)
        ns.append(n)
        record.append(np.full(y.size, r))
    y, n, record = np.concatenate(ys), np.concatenate(ns), np.concatenate(record)
    R = len(rows)
    if y.size < MIN_CONTACTS or y.size <= R + 1 or np.ptp(n) == 0:
        return None
    X = np.zeros((y.size, R + 1))
    X[np.arange(y.size), record] = 1.0
    X[:, -1] = n
    coef, *_ = np.linalg.lstsq(X, y, rcond=None)
    dof = y.size - X.shape[1]
    sigma2 = float(np.sum((y - X @ coef) ** 2)) / dof
    try:
        cov = np.linalg.inv(X.T @ X) * sigma2
    except np.linalg.LinAlgError:
        return None
    slope, se = float(coef[-1]), math.sqrt(max(float(cov[-1, -1]), 0.0))
    q = t_quantile(dof, 0.975)  # without scipy.special's 0.16 s import
    loss = -math.expm1(slope)
    return Shedding(
        loss=loss,
        low=-math.expm1(slope + q * se),
        high=-math.expm1(slope - q * se),
        se=math.exp(slope) * se,
        contacts=int(y.size),
        found=bool(
            se > 0 and -slope / se >= SIGNIFICANCE and -math.expm1(slope * np.ptp(n)) >= MATERIAL
        ),
    )
