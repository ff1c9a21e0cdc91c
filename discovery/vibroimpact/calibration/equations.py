"""The machine's equations of motion in the weak form, one row per test window of a record.

With the contact force ``F`` measured, both bodies' equations are linear in the machine's
parameters::

    m1 (w1'' + g) + c1 w1' + k1 w1 + k3 w1^3 + A sin(omega (t + tau)) = -F   (grid frame)
    m2 (w2'' + g)                                                     =  F   (moulding)

Multiplied by a compact test function ``phi`` and integrated over its window, the
accelerations move onto ``phi`` (``int phi w'' dt = -int phi' v dt``, or ``int phi'' w dt``
without a velocity channel): no channel is differentiated, and the noise of every channel is
averaged over the window.  The force sets the scale: flight alone gives only ratios.
"""

from dataclasses import dataclass

import numpy as np

from ...numerics.test_functions import window_weights

__all__ = ["MachineRows", "machine_rows", "FRAME_TERMS", "MAX_WINDOWS", "ORDER"]

#: the frame equation's parameters, in column order (``A`` is one column per record)
FRAME_TERMS = ("m1", "c1", "k1", "k3", "A")
#: the test functions' order (``(1 - s^2)^4``: smooth enough for ``phi''``)
ORDER = 4
#: the most test windows taken from one record (a long record's windows are spread out)
MAX_WINDOWS = 4000
#: the test windows' half width in drive periods, and at least this many samples
HALF_WIDTH_PERIODS = 0.2
MIN_HALF_WIDTH = 7


@dataclass(frozen=True)
class MachineRows:
    """The weak-form rows of one record (ndarrays of shape (n_windows,) unless noted).

    Attributes
    ----------
    frame : ndarray of shape (n_windows, 5)
        Columns ``int phi (w1'' + g)``, ``int phi w1'``, ``int phi w1``, ``int phi w1^3``,
        ``int phi sin(omega (t + tau))``: the coefficients of ``m1, c1, k1, k3, A``.
    drive_cos : ndarray
        ``int phi cos(omega (t + tau))``: a drive out of phase (the phase check).
    force : ndarray
        ``int phi F``.
    moulding : ndarray
        ``int phi (w2'' + g)``: the coefficient of ``m2``.
    acc2, ones : ndarray, float
        ``int phi w2''`` and ``int phi`` (the free-fall check fits ``g`` too).
    kinematics : dict
        Per body (``"1"``, ``"2"``), ``(int phi v, -int phi' w)``: equal when the positions
        and velocities are in the same units (the units check), or ``None``.
    cycle : ndarray of int
        The drive period each window's centre lies in (the bootstrap's blocks).
    centre : ndarray
        The windows' centre times [s].
    half_width : int
        Samples on each side of a window's centre.
    """

    frame: np.ndarray
    drive_cos: np.ndarray
    force: np.ndarray
    moulding: np.ndarray
    acc2: np.ndarray
    ones: float
    kinematics: dict
    cycle: np.ndarray
    centre: np.ndarray
    half_width: int

    @property
    def n_windows(self):
        return self.force.size


def _half_width(dt, period):
    return max(MIN_HALF_WIDTH, int(round(HALF_WIDTH_PERIODS * period / dt)))


def machine_rows(measurement, scenario, time_offset=0.0):
    """The weak-form rows of ``measurement`` (a record with ``w1`` and ``w2``; ``v1``,
    ``v2`` used where present) on the drive of ``scenario``, or ``None`` when the record
    has no positions or is too short for four test windows (the machine is then taken as
    the scenario gives it).

    ``time_offset`` [s] is the drive-clock time of the record's ``t = 0``."""
    ch = measurement.channels
    if "w1" not in ch or "w2" not in ch:
        return None
    t = np.asarray(measurement.t, dtype=float)
    n = t.size
    dt = float((t[-1] - t[0]) / (n - 1))
    hs = _half_width(dt, scenario.period)
    if 2 * hs + 1 > n // 4:
        return None
    stride = max(1, hs // 2, int(np.ceil((n - 2 * hs) / MAX_WINDOWS)))
    centres = np.arange(hs, n - hs, stride)
    idx = centres[:, None] + np.arange(-hs, hs + 1)[None, :]
    w_phi, w_dphi, w_ddphi = window_weights(hs, ORDER, dt)
    ones = float(w_phi.sum())
    g = scenario.g

    def integral(x):
        return np.asarray(x, dtype=float)[idx] @ w_phi

    def motion(body):
        w = np.asarray(ch[f"w{body}"], dtype=float)
        v = ch.get(f"v{body}")
        pos_rate = -(w[idx] @ w_dphi)  # int phi w' dt from the positions
        if v is None:
            return w, pos_rate, w[idx] @ w_ddphi, None
        v = np.asarray(v, dtype=float)
        vel = v[idx] @ w_phi
        return w, vel, -(v[idx] @ w_dphi), (vel, pos_rate)

    w1, vel1, acc1, kin1 = motion(1)
    _, _, acc2, kin2 = motion(2)
    phase = scenario.omega * (t + time_offset)
    frame = np.column_stack(
        [acc1 + g * ones, vel1, integral(w1), integral(w1**3), integral(np.sin(phase))]
    )
    return MachineRows(
        frame=frame,
        drive_cos=integral(np.cos(phase)),
        force=integral(measurement.F),
        moulding=acc2 + g * ones,
        acc2=acc2,
        ones=ones,
        kinematics={"1": kin1, "2": kin2},
        cycle=np.floor((t[centres] - t[0]) / scenario.period).astype(int),
        centre=t[centres],
        half_width=hs,
    )
