"""Units and signs a record contradicts: each a machine no calibration should accept.

Three facts of any record with motions hold whatever the machine:

* the velocities are the rate of the positions (``int phi v = -int phi' w``);
* between contacts the moulding falls freely at ``g``: fitted with the force as
  ``F = m2 w2'' + m2 g``, the ratio of the two coefficients is ``+g``, and ``m2 > 0``;
* the force and the moulding's acceleration give its mass, which a sheet knows within tens
  of percent, never a factor of three.

A ratio off by about a power of ten is a unit (mm, kN); a sign is a direction.  Each
failure is one :class:`~discovery.errors.InputError` naming the likely cause.
"""

import math

import numpy as np

from ...errors import InputError

__all__ = ["check_units", "free_fall", "kinematic_ratio"]

#: ratios within these bounds of 1 are the same units (the rest is calibration's work)
RATIO_BAND = (0.5, 2.0)
#: the moulding's mass may differ from the sheet's by up to this factor either way
MASS_BAND = 3.0
#: the fewest windows with contact for the free-fall and mass checks
MIN_CONTACT_WINDOWS = 3
#: a record's contacts stand out: its largest window force over its median one
CONTRAST = 20.0

_NAMES = {
    1e3: "mm (mm/s)",
    1e-3: "km (km/s)",
    1e2: "cm (cm/s)",
}


def _power(ratio):
    return 10.0 ** round(math.log10(abs(ratio))) if ratio and math.isfinite(ratio) else math.nan


def kinematic_ratio(rows, body):
    """The velocity channel over the positions' rate for ``body`` ("1" or "2"), or NaN
    without a velocity channel."""
    k = rows.kinematics.get(body)
    if k is None:
        return math.nan
    vel, rate = k
    den = float(rate @ rate)
    return float(vel @ rate) / den if den > 0 else math.nan


def free_fall(rows):
    """``(m2, g)`` of the fit ``int phi F = m2 int phi w2'' + m2 g int phi`` over the
    windows with contact, or ``(nan, nan)`` when the record has too few contacts."""
    even = ~rows.anchored
    f = rows.force[even]
    scale = float(np.max(np.abs(f))) if f.size else 0.0
    if scale == 0:
        return math.nan, math.nan
    contact = np.abs(f) > 0.05 * scale
    if contact.sum() < MIN_CONTACT_WINDOWS or contact.all():
        return math.nan, math.nan
    if scale < CONTRAST * float(np.median(np.abs(f))):
        return math.nan, math.nan  # no flight with the force at rest: no contact to judge
    X = np.column_stack([rows.acc2[even], rows.ones[even]])
    (a, b), *_ = np.linalg.lstsq(X, f, rcond=None)
    r = f - X @ np.array([a, b])
    cov = np.linalg.pinv(X.T @ X) * float(r @ r) / max(1, f.size - 2)
    if not abs(a) > 5.0 * math.sqrt(max(cov[0, 0], 0.0)):
        return math.nan, math.nan  # the force does not follow the moulding's motion
    return float(a), float(b / a) if a != 0 else math.nan


def check_units(rows, sheet, source=""):
    """Refuse a record whose units or signs contradict any machine (one line each, see
    the module docstring).  ``rows`` are its :class:`MachineRows`, ``sheet`` the
    scenario it is given with."""
    where = f"{source}: " if source else ""
    for body in ("1", "2"):
        r = kinematic_ratio(rows, body)
        if math.isfinite(r) and not RATIO_BAND[0] <= r <= RATIO_BAND[1]:
            hint = (
                "positions in mm and velocities in m/s?"
                if 3e-4 < r < 3e-3
                else ("velocities in mm/s and positions in m?" if 3e2 < r < 3e3 else "")
            )
            raise InputError(
                f"{where}v{body} is {r:.3g} times the rate of w{body}: the positions and "
                f"velocities are not in the same units ({hint or 'a sign or unit mix-up'}); "
                "give w in m and v in m/s"
            )
    m2, g = free_fall(rows)
    if not math.isfinite(g):
        return
    if m2 < 0 and g > 0:
        raise InputError(
            f"{where}the force is negative while the moulding is pushed up: give the "
            "contact force as positive in compression (negate F)"
        )
    if g < 0:
        raise InputError(
            f"{where}between contacts the moulding falls upward in the record (at "
            f"{-g:.3g} m/s^2): its positions and velocities look measured downwards; "
            "give w1, v1, w2, v2 positive upward (negate them)"
        )
    ratio = g / sheet.g if sheet.g > 0 else 1.0
    if not RATIO_BAND[0] <= ratio <= RATIO_BAND[1]:
        p = _power(ratio)
        unit = _NAMES.get(p, f"{p:g} times the metre")
        raise InputError(
            f"{where}between contacts the moulding falls at {g:.4g} m/s^2, {ratio:.3g} "
            f"times g: the motions look recorded in {unit}; give w in m and v in m/s"
        )
    mass = m2 / sheet.m2
    if not 1.0 / MASS_BAND <= mass <= MASS_BAND:
        p = _power(mass)
        hint = {1e-3: " (is F in kN?)", 1e3: " (is F in mN?)", 1e-6: " (is F in MN?)"}.get(p, "")
        raise InputError(
            f"{where}the force and the moulding's motion give it a mass of {m2:.4g} kg, "
            f"{mass:.3g} times the scenario's m2 = {sheet.m2:.4g} kg: the force's units or "
            f"the scenario are wrong{hint}; give F in N and the machine's scenario"
        )
