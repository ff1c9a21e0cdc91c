"""A force sensor that lags the motions, read from the machine's equations.

A sensor of first order with time constant ``tau`` records ``F`` with ``tau F' + F =
F_true``.  On a test window ``phi`` that vanishes at its ends, ``int phi F_true = int phi F
- tau int phi' F`` exactly, so the lag is one more linear column in the force's equations
(the frame's and the moulding's, with opposite signs; the momentum balance holds no force).
Read as the true force, a lagged one biases the machine's scale: on a subharmonic record
with a 1.07 ms sensor the calibrated machine was 45 % heavy, on a slow P1 with 0.38 ms
3.5 %, and the drive's phase was off by 9-15 degrees.

The lag is kept where the records pin it (positive, its 95 % interval above 0 and within
:data:`~.machine.LOOSE` of it) and it moves the force's equations by at least
:data:`~.shedding.MATERIAL`; the machine is then read from the force the sensor saw, and a
note says so.  The lag is the sensor's, not the machine's: the machine used has none of it,
and ``explain`` names it (``sensor_lag``) where a law is judged against the record.
"""

from dataclasses import dataclass, replace

import numpy as np

from .estimate import AGREE, force_lag

__all__ = ["SensorLag", "sensor_lag", "with_lag"]


@dataclass(frozen=True)
class SensorLag:
    """The force sensor's time constant ``tau`` [s] with its 95 % interval, its share of
    the force's equations (``|tau| ||int phi F'|| / ||int phi F||``) and whether it is
    found."""

    tau: float
    low: float
    high: float
    share: float
    found: bool


def _share(rows, tau):
    rate = np.concatenate([r.force_rate for r in rows])
    force = np.concatenate([r.force for r in rows])
    ref = float(np.linalg.norm(force))
    return abs(tau) * float(np.linalg.norm(rate)) / ref if ref > 0 else 0.0


def sensor_lag(rows, fixed, draws, *, loose, material):
    """The lag the records ``rows`` (:class:`~.equations.MachineRows` of one machine) show,
    with the parameters ``fixed`` held: a :class:`SensorLag`.

    The lag is read on the evenly spread windows, where it is told from the machine's
    scale, and must agree with the one read on the contacts' own windows (within
    :data:`AGREE` combined standard errors).  A force that jumps at the onset, cut the
    same way every period by a sampling commensurate with the drive, biases the evenly
    spread windows' force like a lag (a spurious 5 % of the scale on the paper's machine
    at 10 kHz, without noise), but not the contacts' windows, whose test function
    vanishes at the jump; a sensor's lag shows on both."""
    tau, low, high = force_lag(rows, fixed, draws, "even")
    share = _share(rows, tau)
    pinned = bool(
        tau > 0
        and np.isfinite(low)
        and low > 0
        and (high - low) / 2 <= loose * tau
        and share >= material
    )
    if pinned and draws:
        tc, lc, hc = force_lag(rows, fixed, draws, "contacts")
        se = np.hypot(high - low, hc - lc) / (2 * 1.96)
        pinned = bool(np.isfinite(se) and abs(tc - tau) <= AGREE * se)
    return SensorLag(float(tau), float(low), float(high), share, pinned)


def with_lag(rows, tau):
    """The rows with the force the sensor of time constant ``tau`` saw: ``int phi F +
    tau int phi F'``."""
    return [replace(r, force=r.force + tau * r.force_rate, lagged=True) for r in rows]
