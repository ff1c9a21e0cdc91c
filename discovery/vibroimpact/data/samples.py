"""Data preparation for regression: contact samples ``(zeta, dzeta, F)`` from a record.

``zeta = w1 - w2`` from the positions; ``dzeta`` from the velocities when recorded,
otherwise by Savitzky-Golay differentiation of ``zeta`` (a local cubic fit, robust
to noise) or pysindy's smoothed finite differences.  A sample is a *contact
sample* when ``zeta`` is clearly positive, so no sample of free flight enters the
fit.  Contact is decided on ``zeta`` (above its own noise level), never on the
force: selecting on the dependent variable would bias the fit (samples whose noise
happens to push them over a force threshold would be kept, the others not).  Each
sample carries the index of its impact, so cross-validation and bootstrap resample
whole impacts.
"""

from dataclasses import dataclass

import numpy as np

from ..._api._printing import fmt, readable
from ..._api._validate import Choice, Real, Text, params
from ...errors import InputError
from .impulse import impulse_from_samples
from .measurement import Measurement
from .noise import estimate_noise

__all__ = ["ContactSamples", "contact_samples", "join_samples"]

DERIVATIVES = ("velocities", "savgol", "pysindy")


@readable
@dataclass(frozen=True)
class ContactSamples:
    """Samples in contact.

    Attributes
    ----------
    zeta : ndarray of shape (n,)
        Interpenetration [m].
    dzeta : ndarray of shape (n,)
        Penetration velocity [m/s].
    F : ndarray of shape (n,)
        Contact force [N].
    impact : ndarray of shape (n,), int
        Index of the impact each sample belongs to.
    weight : ndarray of shape (n,)
        Regression weights: how many recorded samples each sample stands for (1, or the
        number of averaged cycles with ``average_cycles``), or equal totals per impact.
    noise : float
        Estimated force noise standard deviation [N].
    derivative : str
        How ``dzeta`` was obtained.
    """

    zeta: np.ndarray
    dzeta: np.ndarray
    F: np.ndarray
    impact: np.ndarray
    weight: np.ndarray
    noise: float
    derivative: str

    @property
    def X(self):
        """ndarray of shape (n, 2): ``zeta``, ``dzeta`` (the estimators' input)."""
        return np.column_stack([self.zeta, self.dzeta])

    @property
    def n_impacts(self):
        return int(np.unique(self.impact).size)

    def __len__(self):
        return self.zeta.size

    def _lines(self):
        if not self.F.size:
            return ["no contact samples"]
        return [
            f"{self.F.size} contact samples of {self.n_impacts} impact(s): penetration up to "
            f"{fmt(np.max(self.zeta), 3)} m, its velocity {fmt(np.min(self.dzeta), 3)} to "
            f"{fmt(np.max(self.dzeta), 3)} m/s, force up to {fmt(np.max(self.F))} N",
            f"  noise {fmt(self.noise, 3)} N, velocity by {self.derivative}",
        ]


def join_samples(parts):
    """The contact samples of several records as one set (impacts renumbered so each
    record's impacts stay distinct groups; the noise is the RMS of the records')."""
    parts = list(parts)
    if len(parts) == 1:
        return parts[0]
    impact, offset = [], 0
    for p in parts:
        impact.append(p.impact + offset)
        offset += int(p.impact.max()) + 1 if p.impact.size else 0
    derivs = sorted({p.derivative for p in parts})
    return ContactSamples(
        zeta=np.concatenate([p.zeta for p in parts]),
        dzeta=np.concatenate([p.dzeta for p in parts]),
        F=np.concatenate([p.F for p in parts]),
        impact=np.concatenate(impact),
        weight=np.concatenate([p.weight for p in parts]),
        noise=float(np.sqrt(np.mean([p.noise**2 for p in parts]))),
        derivative=derivs[0] if len(derivs) == 1 else "+".join(derivs),
    )


def _steady_cycles(*stacks):
    """Indices of the cycles that repeat: rows of every ``(stack, sigma)`` pair (``stack`` of
    shape (n_cycles, m)) within what the noise explains of the sample-wise median cycle.

    A cycle is steady when, for every signal, its mean square deviation from the median of
    all the cycles is at most ``2 sigma^2 (1 + 6 sqrt(2/m))`` plus ``(0.5 % of the peak)^2``
    (the allowance of :func:`discovery.vibroimpact.data.impulse.impulse_from_samples`), or four
    times the median deviation of the cycles (the median is robust to isolated outliers)."""
    ok = None
    for stack, sigma in stacks:
        m = stack.shape[1]
        ref = np.median(stack, axis=0)
        peak = float(np.max(np.abs(ref))) or 1.0
        dev = np.mean((stack - ref) ** 2, axis=1)
        expected = 2.0 * sigma**2 * (1.0 + 6.0 * np.sqrt(2.0 / m)) + (0.005 * peak) ** 2
        good = dev <= max(expected, 4.0 * float(np.median(dev)))
        ok = good if ok is None else ok & good
    return np.flatnonzero(ok)


def _average_steady(t, zeta, dzeta, F, period):
    """Replace the steady cycles at the end of a record by their sample-wise average.

    The steady part starts at the first cycle
    :func:`~discovery.vibroimpact.data.impulse.impulse_from_samples`
    averages (``imp.onset``); every whole cycle from there to the end of the record is
    checked again (force and ``zeta`` against their median cycle, :func:`_steady_cycles`),
    because the impulse leaves out isolated deviating cycles: those, like the run-up before
    the steady part and the incomplete cycle at the end, stay as they are (count 1).

    Returns ``(t, zeta, dzeta, F, count)`` where ``count`` is how many samples each
    value stands for (the number of averaged cycles, 1 elsewhere)."""
    imp = impulse_from_samples(t, F, period, zeta=zeta)
    dt = float(np.median(np.diff(t)))
    m = imp.duration / dt
    if abs(m - round(m)) > 1e-6 * m:
        raise InputError(
            "average_cycles needs a whole number of samples per cycle (fs * T "
            f"= {m:.6g}); resample the record or do not average"
        )
    m = int(round(m))
    i0 = int(np.searchsorted(t, imp.onset - dt))  # one sample before the first steady onset
    k = (t.size - i0) // m  # whole cycles from there to the end of the record
    if k < 2:
        return t, zeta, dzeta, F, np.ones(t.size)
    block = slice(i0, i0 + k * m)
    steady = _steady_cycles(
        (F[block].reshape(k, m), estimate_noise(F)),
        (zeta[block].reshape(k, m), estimate_noise(zeta, order=3)),
    )
    if steady.size < 2:
        return t, zeta, dzeta, F, np.ones(t.size)
    avg = [a[block].reshape(k, m)[steady].mean(axis=0) for a in (zeta, dzeta, F)]
    # the average takes the first steady cycle's place; the run-up, the deviating cycles
    # and the incomplete last cycle stay as recorded, in time order (every cycle starts
    # one sample before its onset, so no contact is joined to another one)
    idx = np.arange(t.size)
    cycle = np.full(t.size, -1)
    cycle[block] = np.repeat(np.arange(k), m)
    raw = ~np.isin(cycle, steady)
    at = i0 + int(steady[0]) * m
    before, after = raw & (idx < at), raw & (idx >= at)
    cat = [
        np.concatenate([a[before], b, a[after]])
        for a, b in zip((t, zeta, dzeta, F), (t[at : at + m], *avg), strict=True)
    ]
    count = np.concatenate(
        [np.ones(before.sum()), np.full(m, float(steady.size)), np.ones(after.sum())]
    )
    return (*cat, count)


@params(
    measurement=Measurement,
    derivative=(None, Text()),
    window=Real(3, integer=True),
    k_sigma=Real(0, open_low=True),
    weights=Text(),
    period=(None, Real(0, open_low=True)),
    contact=Choice("penetration", "force"),
)
def contact_samples(
    measurement,
    *,
    derivative=None,
    window=7,
    k_sigma=5.0,
    weights="uniform",
    average_cycles=False,
    period=None,
    contact="penetration",
):
    """Contact samples of a :class:`~discovery.vibroimpact.data.measurement.Measurement`.

    Parameters
    ----------
    measurement : Measurement
        Needs ``w1`` and ``w2``; ``v1`` and ``v2`` are used when present.
    derivative : {"velocities", "savgol", "pysindy"}, optional
        Source of ``dzeta``; default the velocities when recorded, else ``"savgol"``.
    window : int
        Samples in the differentiation window (odd, >= 5).
    k_sigma : float
        A sample counts as in contact when ``zeta > k_sigma * sigma_zeta`` (noise level
        of ``zeta`` from third differences,
        :func:`~discovery.vibroimpact.data.noise.estimate_noise`;
        a tiny floor for noise-free data).
    weights : {"uniform", "per-impact"}
        ``"per-impact"`` gives every impact the same total weight.
    average_cycles : bool
        Average the steady cycles at the end of the record sample by sample (noise
        down by the square root of their number) and weight each averaged sample by
        the number of cycles; run-up impacts, isolated deviating cycles and the
        incomplete last cycle are kept as they are.  Needs ``period`` and a whole
        number of samples per cycle.
    period : float, optional
        Drive period [s] (for ``average_cycles``).
    contact : {"penetration", "force"}
        What says a sample is in contact: ``zeta`` above ``k_sigma`` times its noise, or the
        force above ``k_sigma`` times the force's noise.  The force tells contact where the
        penetration, a small difference of two large noisy motions, is buried in their
        noise (a stiff contact whose peak penetration is a few noise deviations).

    Returns
    -------
    ContactSamples
    """
    ch = measurement.channels
    if "w1" not in ch or "w2" not in ch:
        raise InputError(
            "discovery needs the positions w1 and w2 in the data (zeta = w1 - w2); "
            "add those columns"
        )
    t = measurement.t
    zeta = ch["w1"] - ch["w2"]
    have_v = "v1" in ch and "v2" in ch
    derivative = derivative or ("velocities" if have_v else "savgol")
    if derivative not in DERIVATIVES:
        raise InputError(f"unknown derivative {derivative!r}; valid: {', '.join(DERIVATIVES)}")
    if not (isinstance(window, int) and window >= 5 and window % 2 == 1):
        raise InputError(f"window must be an odd integer >= 5, got {window!r}")
    dt = float(np.median(np.diff(t)))
    if derivative == "velocities":
        if not have_v:
            raise InputError("derivative 'velocities' needs the v1 and v2 columns")
        dzeta = ch["v1"] - ch["v2"]
    elif derivative == "savgol":
        from scipy.signal import savgol_filter  # 0.4 s to import; only this option needs it

        dzeta = savgol_filter(zeta, window, 3, deriv=1, delta=dt)
    else:
        from pysindy.differentiation import SmoothedFiniteDifference

        sfd = SmoothedFiniteDifference(smoother_kws={"window_length": window, "polyorder": 3})
        dzeta = np.asarray(sfd(zeta.reshape(-1, 1), t)).ravel()  # the public __call__
    F = measurement.F
    sigma = estimate_noise(F)
    count = np.ones(t.size)
    if average_cycles:
        if period is None:
            raise InputError("average_cycles needs the drive period")
        t, zeta, dzeta, F, count = _average_steady(t, zeta, dzeta, F, period)
    # third differences: the smooth motion cancels, only the measurement noise remains
    floor = max(k_sigma * estimate_noise(zeta, order=3), 1e-9 * float(np.max(np.abs(zeta))))
    contact_by_force = contact == "force"
    if contact_by_force:
        contact = F > max(k_sigma * sigma, 1e-9 * float(np.max(np.abs(F))))
    else:
        contact = zeta > floor
    if contact.sum() < 10:
        raise InputError(
            "fewer than 10 contact samples (zeta = w1 - w2 > 0 above its noise); "
            "check the w1 and w2 columns and their sign (positions upward)"
        )
    # impacts: runs of contact samples; two runs are one impact unless zeta falls clearly
    # below zero (< -floor) between them (noise dips near onset and loss do not split it)
    starts = np.flatnonzero(np.diff(np.concatenate([[0], contact.astype(np.int8)])) == 1)
    ends = np.flatnonzero(np.diff(np.concatenate([contact.astype(np.int8), [0]])) == -1)
    new = np.ones(starts.size, dtype=bool)
    for j in range(1, starts.size):
        if contact_by_force:  # a dip of one or two samples is the force's noise
            new[j] = starts[j] - ends[j - 1] > 3
        else:
            new[j] = bool(np.min(zeta[ends[j - 1] + 1 : starts[j]]) < -floor)
    impact_all = np.cumsum(np.isin(np.arange(t.size), starts[new])) - 1
    idx = np.flatnonzero(contact)
    impact = impact_all[idx]
    if weights == "uniform":
        w = count[idx].copy()
    elif weights == "per-impact":
        counts = np.bincount(impact)
        w = count[idx] / counts[impact]
        w *= idx.size / w.sum()
    else:
        raise InputError(f"weights must be 'uniform' or 'per-impact', got {weights!r}")
    return ContactSamples(
        zeta=zeta[idx],
        dzeta=dzeta[idx],
        F=F[idx],
        impact=impact,
        weight=w,
        noise=sigma,
        derivative=derivative,
    )
