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

from ...numerics.test_functions import test_function, window_weights
from ..data.contact_edges import contact_onsets

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
#: a contact: the force above this share of its peak (beyond a record's noise) ...
CONTACT_LEVEL = 0.2
#: ... widened while it stays above this share
EDGE_LEVEL = 0.02
#: the fewest samples on each side of a contact window's centre
MIN_CONTACT_HALF_WIDTH = 4


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
    force_rate : ndarray
        ``int phi F' = -int phi' F``: with a force sensor of first order and time constant
        ``tau`` (``tau F' + F = F_true``), ``int phi F_true = force + tau force_rate``
        exactly (:mod:`.sensor`).
    moulding : ndarray
        ``int phi (w2'' + g)``: the coefficient of ``m2``.
    acc2, ones : ndarray
        ``int phi w2''`` and ``int phi`` (the free-fall check fits ``g`` too).
    kinematics : dict
        Per body (``"1"``, ``"2"``), ``(int phi v, -int phi' w)`` over the evenly spread
        windows: equal when the positions and velocities are in the same units (the units
        check), or ``None``.
    cycle : ndarray of int
        The drive period each window's centre lies in (the bootstrap's blocks).
    centre : ndarray
        The windows' centre times [s].
    anchored : ndarray of bool
        The windows of one contact each, from the last sample before it to the first
        after it (the rest are spread evenly).  A stiff, damped contact's force jumps at
        its onset, and where between two samples the jump falls is the same every period
        when the sampling is commensurate with the drive: a window whose ``phi`` is large
        there carries that quadrature error into ``int phi F`` (the paper's machine at
        10 kHz: -5 % on the scale).  A contact window's ``phi`` and its first three
        derivatives vanish at the jump, so it costs nothing there: the equations that hold
        the force use these windows, the momentum balance the evenly spread ones.
    lagged : bool
        The force is a lagging sensor's, corrected for its lag (:mod:`.sensor`): it has no
        jump, and on a contact's short window the machine's scale follows the lag's
        error 4 % for 2 % of it, so the force's equations use the evenly spread windows.
    """

    frame: np.ndarray
    drive_cos: np.ndarray
    force: np.ndarray
    force_rate: np.ndarray
    moulding: np.ndarray
    acc2: np.ndarray
    ones: np.ndarray
    kinematics: dict
    cycle: np.ndarray
    centre: np.ndarray
    anchored: np.ndarray
    lagged: bool = False

    @property
    def n_windows(self):
        return self.force.size


def _half_width(dt, period):
    return max(MIN_HALF_WIDTH, int(round(HALF_WIDTH_PERIODS * period / dt)))


def _contacts(F, dt, period):
    """``(start, stop)`` sample indices of each contact: a run of the force above
    :data:`CONTACT_LEVEL` of its peak (noise does not reach it), widened while the force
    stays above :data:`EDGE_LEVEL`, so that a window from ``start - 1`` to ``stop`` holds
    the whole contact."""
    top = float(np.max(np.abs(F))) if F.size else 0.0
    if top == 0:
        return []
    strong = F > CONTACT_LEVEL * top
    weak = F > EDGE_LEVEL * top
    gap = max(2, int(0.01 * period / dt))
    runs, k, n = [], 0, F.size
    on = np.flatnonzero(strong)
    while k < on.size:
        a = b = on[k]
        while k + 1 < on.size and on[k + 1] - b <= gap:
            k += 1
            b = on[k]
        k += 1
        while a > 0 and weak[a - 1]:
            a -= 1
        while b + 1 < n and weak[b + 1]:
            b += 1
        if runs and a <= runs[-1][1] + 1:
            runs[-1] = (runs[-1][0], b + 1)
        else:
            runs.append((a, b + 1))
    return runs


def machine_rows(measurement, scenario, time_offset=0.0):
    """The weak-form rows of ``measurement`` (a record with ``w1`` and ``w2``; ``v1``,
    ``v2`` used where present) on the drive of ``scenario``, or ``None`` when the record
    has no positions or is too short for four test windows (the machine is then taken as
    the scenario gives it).

    Two sets of windows: evenly spread ones of :data:`HALF_WIDTH_PERIODS` drive periods,
    and one per contact, from the last sample before it to the first after it
    (:attr:`MachineRows.anchored`).

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
    data = _Channels.of(measurement, scenario, time_offset)
    parts = [_rows(data, np.arange(hs, n - hs, stride), hs, dt)]
    windows = []
    for a, b in _contacts(data.F, dt, scenario.period)[:MAX_WINDOWS]:
        half = max(MIN_CONTACT_HALF_WIDTH, int(np.ceil((b - a + 2) / 2)))
        centre = a - 1 + half
        if centre - half >= 0 and centre + half < n:
            windows.append((half, centre))
    for half in sorted({h for h, _ in windows}):
        centres = np.array([c for h, c in windows if h == half])
        parts.append(_rows(data, centres, half, dt))
    rows = {k: np.concatenate([p[k] for p in parts]) for k in parts[0] if k != "kinematics"}
    regular = parts[0]
    anchored = np.arange(rows["force"].size) >= regular["force"].size
    centre = rows.pop("centre")
    return MachineRows(
        **rows,
        kinematics=regular["kinematics"],
        cycle=np.floor((centre - t[0]) / scenario.period).astype(int),
        centre=centre,
        anchored=anchored,
    )


@dataclass(frozen=True)
class _Channels:
    """A record's channels as the windows read them (velocities ``None`` when absent)."""

    t: np.ndarray
    F: np.ndarray
    w1: np.ndarray
    v1: object
    w2: np.ndarray
    v2: object
    sin: np.ndarray
    cos: np.ndarray
    g: float
    share: object = None
    onsets: object = None

    @classmethod
    def of(cls, measurement, scenario, time_offset):
        ch = measurement.channels

        def get(name):
            return None if ch.get(name) is None else np.asarray(ch[name], dtype=float)

        t = np.asarray(measurement.t, dtype=float)
        phase = scenario.omega * (t + time_offset)
        F = np.asarray(measurement.F, dtype=float)
        share, onsets = None, None
        if scenario.mass_loss > 0:
            # the moulding sheds mass_loss of its mass at every contact's onset: its mass
            # as a share of the record's starting mass, sample by sample
            at = contact_onsets(t, F, scenario.period, zeta=get("w1") - get("w2"))
            onsets = np.searchsorted(t, at, side="left")
            before = np.searchsorted(onsets, np.arange(t.size), side="right")
            share = (1.0 - scenario.mass_loss) ** before
        return cls(
            t=t,
            F=F,
            w1=get("w1"),
            v1=get("v1"),
            w2=get("w2"),
            v2=get("v2"),
            sin=np.sin(phase),
            cos=np.cos(phase),
            g=scenario.g,
            share=share,
            onsets=onsets,
        )


def _rows(data, centres, hs, dt):
    """The rows of the windows of half width ``hs`` samples centred on ``centres``."""
    idx = centres[:, None] + np.arange(-hs, hs + 1)[None, :]
    w_phi, w_dphi, w_ddphi = window_weights(hs, ORDER, dt)
    ones = np.full(centres.size, float(w_phi.sum()))

    def integral(x):
        return x[idx] @ w_phi

    def motion(w, v):
        pos_rate = -(w[idx] @ w_dphi)  # int phi w' dt from the positions
        if v is None:
            return pos_rate, w[idx] @ w_ddphi, None
        vel = v[idx] @ w_phi
        return vel, -(v[idx] @ w_dphi), (vel, pos_rate)

    vel1, acc1, kin1 = motion(data.w1, data.v1)
    _, acc2, kin2 = motion(data.w2, data.v2)
    frame = np.column_stack(
        [acc1 + data.g * ones, vel1, integral(data.w1), integral(data.w1**3), integral(data.sin)]
    )
    moulding = acc2 + data.g * ones
    if data.share is not None:
        moulding = _shedding_moulding(data, centres, hs, dt)
    return {
        "frame": frame,
        "drive_cos": integral(data.cos),
        "force": integral(data.F),
        "force_rate": -(data.F[idx] @ w_dphi),
        "moulding": moulding,
        "acc2": acc2,
        "ones": ones,
        "kinematics": {"1": kin1, "2": kin2},
        "centre": data.t[centres],
    }


def _shedding_moulding(data, centres, hs, dt):
    """The moulding's column ``int phi s (w2'' + g) dt`` of a moulding that sheds mass at
    every onset (``s``: its mass over the record's starting mass, ``data.share``).  The
    mass jumps while the velocity does not, so moving the derivative onto ``phi`` leaves a
    term at each onset ``t_j`` inside a window: ``int phi s v2' dt = -int phi' s v2 dt -
    sum_j phi(t_j) (s_j+ - s_j-) v2(t_j)`` (the rate from the positions where the record
    has no velocities)."""
    idx = centres[:, None] + np.arange(-hs, hs + 1)[None, :]
    w_phi, w_dphi, _ = window_weights(hs, ORDER, dt)
    s = data.share
    v2 = data.v2 if data.v2 is not None else np.gradient(data.w2, dt)
    col = -((s * v2)[idx] @ w_dphi) + data.g * (s[idx] @ w_phi)
    phi = test_function(hs, ORDER)[0]
    for j in data.onsets:
        if j <= 0:
            continue
        near = np.abs(centres - j) <= hs
        jump = s[j] - s[j - 1]
        col[near] -= phi[j - centres[near] + hs] * jump * 0.5 * (v2[j] + v2[j - 1])
    return col
