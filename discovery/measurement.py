"""Measured (or synthetic) records: validated loading and writing of CSV files.

CSV format: a header row; ``t`` [s] and ``F`` [N] required; ``w1``, ``w2`` [m],
``v1``, ``v2`` [m/s] and ``a2`` [m/s^2] optional; other columns are ignored (with a
note).  Without ``F``, the force is taken from the moulding's acceleration,
``F = m2 (a2 + g)`` (its equation of motion), which needs the scenario.  The time
``t`` is the drive's clock: the drive is ``A sin(2 pi f t)``.
"""

import csv
import io
from dataclasses import dataclass, field

import numpy as np

from ._io import atomic_write_text
from .dynamics import simulate
from .dynamics.steady_state import steady_state
from .errors import InputError
from .impulse import estimate_noise, impulse_from_samples

__all__ = ["Measurement", "synthesize"]

_OPTIONAL = ("w1", "v1", "w2", "v2", "a2")
_STATE = ("w1", "v1", "w2", "v2")


@dataclass(frozen=True)
class Measurement:
    """A force record, optionally with the bodies' positions and velocities.

    Attributes
    ----------
    t : ndarray of shape (n,)
        Strictly increasing sample times [s].
    F : ndarray of shape (n,)
        Contact force [N].
    channels : dict
        Optional ``w1, v1, w2, v2`` arrays of shape (n,).
    source : str
        File it came from.
    notes : tuple of str
        What was ignored or assumed while loading.
    """

    t: np.ndarray
    F: np.ndarray
    channels: dict = field(default_factory=dict)
    source: str = ""
    notes: tuple = ()

    def __post_init__(self):
        t = np.asarray(self.t, dtype=float)
        F = np.asarray(self.F, dtype=float)
        where = f" in {self.source}" if self.source else ""
        if t.ndim != 1 or t.shape != F.shape or t.size < 4:
            raise InputError(f"t and F must be 1-D of equal length >= 4{where}")
        for name, arr in (("t", t), ("F", F), *self.channels.items()):
            bad = np.flatnonzero(~np.isfinite(np.asarray(arr, dtype=float)))
            if bad.size:
                raise InputError(f"column {name}{where} has a missing or non-finite value at "
                                 f"data row {bad[0] + 1}; remove or fill it")
        d = np.diff(t)
        if np.any(d == 0):
            k = int(np.flatnonzero(d == 0)[0])
            raise InputError(f"duplicate time t = {t[k]!r}{where} (data rows {k + 1}, {k + 2}); "
                             "each sample needs its own time")
        if np.any(d < 0):
            k = int(np.flatnonzero(d < 0)[0])
            raise InputError(f"times are not increasing{where} at data row {k + 2}; sort the "
                             "file by t")
        object.__setattr__(self, "t", t)
        object.__setattr__(self, "F", F)

    @property
    def fs(self):
        """Sampling rate [Hz] (median)."""
        return 1.0 / float(np.median(np.diff(self.t)))

    @classmethod
    def from_csv(cls, path, scenario=None):
        """Load and validate a CSV file (see module docstring).

        Parameters
        ----------
        path : str or Path
        scenario : Scenario, optional
            Needed only when the file has ``a2`` but no ``F``.
        """
        try:
            text = open(path, newline="").read()
        except FileNotFoundError:
            raise InputError(f"data file {str(path)!r} does not exist") from None
        rows = list(csv.reader(io.StringIO(text)))
        if not rows:
            raise InputError(f"data file {str(path)!r} is empty; it needs a header with t and F")
        header = [h.strip() for h in rows[0]]
        from_a2 = "F" not in header and "a2" in header
        if from_a2 and scenario is None:
            raise InputError(f"data file {str(path)!r} has a2 but no F; give the scenario so "
                             "that F = m2 (a2 + g) can be formed")
        missing = [c for c in ("t", "F") if c not in header and not (c == "F" and from_a2)]
        if missing:
            raise InputError(f"data file {str(path)!r} has no column {' or '.join(missing)}; "
                             f"the header must name t [s] and F [N] (found {header})")
        cols = {}
        body = [r for r in rows[1:] if any(c.strip() for c in r)]
        for name in ("t", "F", *_OPTIONAL):
            if name in header:
                j = header.index(name)
                try:
                    cols[name] = np.array([float(r[j]) if r[j].strip() else np.nan
                                           for r in body])
                except (ValueError, IndexError):
                    raise InputError(f"column {name} in {str(path)!r} has a non-numeric or "
                                     "missing entry; every row needs a number") from None
        ignored = [h for h in header if h not in ("t", "F", *_OPTIONAL)]
        notes = (f"ignored column(s): {', '.join(ignored)}",) if ignored else ()
        channels = {k: cols[k] for k in _OPTIONAL if k in cols}
        if from_a2:
            cols["F"] = scenario.m2 * (cols["a2"] + scenario.g)
            notes += ("F formed from the moulding's acceleration: F = m2 (a2 + g)",)
        return cls(cols["t"], cols["F"], channels, str(path), notes)

    def to_csv(self, path):
        """Write atomically as CSV (``t, F`` then the optional channels)."""
        names = ["t", "F", *[k for k in _OPTIONAL if k in self.channels]]
        data = np.column_stack([self.t, self.F, *[self.channels[k] for k in names[2:]]])
        buf = io.StringIO()
        buf.write(",".join(names) + "\n")
        np.savetxt(buf, data, delimiter=",", fmt="%.12g")
        atomic_write_text(path, buf.getvalue())

    @property
    def zeta(self):
        """Interpenetration ``w1 - w2`` [m] if both positions were recorded, else None."""
        if "w1" in self.channels and "w2" in self.channels:
            return self.channels["w1"] - self.channels["w2"]
        return None

    def state_at_strobe(self, period, time_offset=0.0):
        """The bodies' state at a late strobe time of the record (drive phase 0).

        The latest time ``t + time_offset = k T`` with a window of samples on both sides
        and, preferably, no contact force in it; positions (and velocities, when
        recorded; otherwise the slope of the position fit) from a local quadratic fit
        over +-1 % of a period, which averages the sensor noise down.

        Returns
        -------
        state : ndarray of shape (4,)
            ``w1, v1, w2, v2``.
        t_drive : float
            The strobe time on the drive's clock [s].
        """
        ch = self.channels
        if "w1" not in ch or "w2" not in ch:
            raise InputError("the state needs the positions w1 and w2 in the data")
        t = self.t
        dt = float(np.median(np.diff(t)))
        m = max(3, int(0.01 * period / dt))
        k_hi = int(np.floor((t[-1 - m] + time_offset) / period))
        k_lo = int(np.ceil((t[m] + time_offset) / period))
        if k_hi < k_lo:
            raise InputError("the record is shorter than one drive period")
        thr = 5.0 * estimate_noise(self.F)
        best = None
        for k in range(k_hi, max(k_lo, k_hi - 8) - 1, -1):
            i = int(np.searchsorted(t, k * period - time_offset))
            free = bool(np.all(self.F[max(i - m, 0):i + m + 1] <= max(thr, 0.0)))
            if best is None or free:
                best = (k, i)
            if free:
                break
        k, i = best
        tk = k * period - time_offset
        sl = slice(max(i - m, 0), min(i + m + 1, t.size))
        x = t[sl] - tk

        def fit(y):
            return np.polyfit(x, y[sl], 2)

        state = []
        for w, v in (("w1", "v1"), ("w2", "v2")):
            cw = fit(ch[w])
            state.append(np.polyval(cw, 0.0))
            state.append(np.polyval(fit(ch[v]), 0.0) if v in ch else cw[1])
        return np.array(state, dtype=float), float(k * period)

    def impulse(self, period, **kwargs):
        """Period-averaged steady-state impulse (see :func:`impulse_from_samples`);
        the onset comes from ``zeta`` when positions were recorded."""
        return impulse_from_samples(self.t, self.F, period, zeta=self.zeta, **kwargs)


def synthesize(scenario, law, periods=20, fs=20000.0, noise=0.0, seed=0, ss=None, *,
               from_rest=False, position_noise=0.0, velocities=True):
    """A synthetic measurement of ``law`` sampled at ``fs``.

    Parameters
    ----------
    scenario : Scenario
    law : ForceLaw
    periods : int
        Drive periods recorded.
    fs : float
        Sampling rate [Hz].
    noise : float
        Gaussian noise on ``F`` with standard deviation ``noise * max F``.
    seed : int
        Seed of ``numpy.random.default_rng`` for all noise.
    ss : SteadyState, optional
        Precomputed steady state.
    from_rest : bool
        Record from the scenario's initial state (the run-up, with impacts at many
        velocities, then the steady state) instead of from a time on the periodic
        orbit.  Either way the drive phase at ``t = 0`` is zero.
    position_noise : float
        Gaussian noise on ``w1`` and ``w2`` with standard deviation
        ``position_noise * max(w1 - w2)`` (a fraction of the largest penetration).
    velocities : bool
        Include the ``v1``, ``v2`` channels.

    Returns
    -------
    Measurement
    """
    if not (periods >= 1 and fs > 0 and noise >= 0 and position_noise >= 0):
        raise InputError("periods must be >= 1, fs > 0 and the noise levels >= 0")
    n = int(round(periods * scenario.period * fs))
    t = np.arange(n) / fs
    if from_rest:
        tr = simulate(scenario, law, (0.0, t[-1]), t_eval=t)
    else:
        ss = ss or steady_state(scenario, law)
        if not ss.periodic:
            raise InputError(f"law '{law}' has no periodic steady state in scenario "
                             f"{scenario.name!r} ({ss.regime}); choose another law or scenario, "
                             "or record from rest")
        tr = simulate(scenario, law, (ss.t0, ss.t0 + t[-1]), y0=ss.y0, t_eval=ss.t0 + t)
    rng = np.random.default_rng(seed)
    F = tr.force.copy()
    if noise > 0:
        F = F + rng.normal(0.0, noise * float(np.max(F)), size=F.shape)
    ch = dict(zip(_STATE, (v.copy() for v in tr.y), strict=True))
    if position_noise > 0:
        sd = position_noise * float(np.max(ch["w1"] - ch["w2"]))  # of the largest penetration
        ch["w1"] += rng.normal(0.0, sd, n)
        ch["w2"] += rng.normal(0.0, sd, n)
    if not velocities:
        del ch["v1"], ch["v2"]
    return Measurement(t, F, ch, source=f"synthetic:{scenario.name}")
