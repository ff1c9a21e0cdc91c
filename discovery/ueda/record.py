"""A record of Ueda's oscillator, ``x(t)`` uniformly sampled under a known forcing
``B cos(nu t)``: reading and checking it, simulating one, smoothing it, and what the record
alone says (its stroboscopic points and its regime).

* :func:`read_record_csv`, :func:`check_record`, :func:`check_forcing` - the checks every
  workflow runs first;
* :func:`simulate_record` - a synthetic record (compiled kernel or ``solve_ivp``);
* :func:`smooth` -> :class:`Smoothed` - Savitzky-Golay smoothing and velocity, and the
  noise's standard deviation from the filter's residual;
* :func:`record_strobe_points`, :func:`classify_record` - the record's attractor.
"""

from dataclasses import dataclass, field

import numpy as np

from .._api._settings import Settings, option, takes
from .._api._validate import Array, Choice, Real, params
from ..errors import InputError, IntegrationError
from ..numerics.tolerances import Tolerances
from .polynomial import ForcedPolynomial
from .regimes import rotation_number
from .system import UedaSystem

__all__ = [
    "read_record_csv",
    "check_record",
    "check_forcing",
    "simulate_record",
    "Smoothed",
    "smooth",
    "record_strobe_points",
    "classify_record",
]


def read_record_csv(path):
    """``(t, x)`` from a CSV with a header naming columns ``t`` and ``x`` (other columns
    ignored); checked: finite, at least 64 rows, strictly increasing and uniform ``t``
    (to 1e-6 of the step)."""
    from .._files._csv import parse_column, read_csv_rows

    rows = read_csv_rows(path, "t and x")
    header = rows.header
    missing = [c for c in ("t", "x") if c not in header]
    if missing:
        raise InputError(
            f"data file {str(path)!r}: no column(s) {', '.join(missing)} in the "
            f"header {','.join(header)[:80]!r}; name the columns t and x"
        )
    limits = {"t": (1e7, "s"), "x": (1e6, "")}
    t, x = (
        parse_column(rows, c, header.index(c), name=str(path), limits=limits) for c in ("t", "x")
    )
    return check_record(t, x, what=f"--data {path}")


def check_record(t, x, what="the record"):
    """The record as flat float arrays ``(t, x)``, checked: the same length, at least 64
    finite samples, ``t`` strictly increasing and uniform (to 1e-6 of the step), ``x`` not
    constant; an error names ``what``."""
    t = np.asarray(t, dtype=float).ravel()
    x = np.asarray(x, dtype=float).ravel()
    if t.shape != x.shape:
        raise InputError(f"{what}: t and x differ in length ({t.size} vs {x.size})")
    if t.size < 64:
        raise InputError(
            f"{what}: {t.size} samples; need at least 64 (e.g. 20 periods at "
            "20-50 samples per period)"
        )
    bad = ~(np.isfinite(t) & np.isfinite(x))
    if bad.any():
        raise InputError(f"{what}: non-finite value at row {int(np.argmax(bad)) + 1}")
    dt = np.diff(t)
    h = float(np.median(dt))
    if not h > 0 or np.any(dt <= 0):
        raise InputError(f"{what}: t must increase strictly (row {int(np.argmax(dt <= 0)) + 2})")
    if np.max(np.abs(dt - h)) > 1e-6 * h + 1e-12 * np.max(np.abs(t)):
        raise InputError(
            f"{what}: t must be uniformly sampled (steps from {dt.min():.6g} to "
            f"{dt.max():.6g}); resample it first"
        )
    if np.ptp(x) == 0:
        raise InputError(f"{what}: x is constant")
    return t, x


@dataclass(frozen=True, repr=False)
class UedaRecordSettings(Settings):
    """The keyword options of :func:`simulate_record` (each is also a keyword of it)."""

    transient: int = option(200, Real(0, integer=True))
    y0: object = option(None, (None, Array(1)))
    integrator: str = option("compiled", Choice("compiled", "scipy"))
    rtol: float = option(1e-10, Real(0, 1, open_low=True))


@takes(UedaRecordSettings)
@params(
    system=(UedaSystem, ForcedPolynomial),
    periods=Real(1, integer=True),
    samples_per_period=Real(4, integer=True),
    noise=Real(0),
    seed=Real(0, integer=True),
)
def simulate_record(
    system, periods=200, samples_per_period=40, noise=0.0, seed=0, *, settings=None, **options
):
    """A synthetic record of ``system`` (a :class:`UedaSystem` or
    :class:`ForcedPolynomial`): ``(t, x_noisy, x_clean, v_clean)``.

    After ``transient`` periods from ``y0`` (default ``(0.1, 0)``), ``periods`` forcing
    periods sampled ``samples_per_period`` times per period from ``t = 0`` (the forcing's
    phase 0: the first sample is a strobe point).  Gaussian noise of standard deviation
    ``noise * (max x - min x)`` on ``x``.  ``integrator``: ``"compiled"`` (the
    :mod:`discovery.ueda` kernel, UedaSystem only) or ``"scipy"`` (``solve_ivp``,
    DOP853, the independent path).  ``settings`` (a :class:`UedaRecordSettings`) holds
    ``transient``, ``y0``, ``integrator`` and ``rtol`` in one object; keywords override
    its fields.
    """
    s = UedaRecordSettings.of("simulate_record", settings, options)
    from scipy.integrate import solve_ivp

    T = system.period
    n = int(periods) * int(samples_per_period) + 1
    t = np.arange(n) * (T / int(samples_per_period))
    y = np.array((0.1, 0.0) if s.y0 is None else s.y0, dtype=float)
    if s.integrator == "compiled":
        from .strobe import strobe_points, trajectory

        if not isinstance(system, UedaSystem):
            raise InputError("the compiled integrator simulates a UedaSystem; use scipy")
        tol = Tolerances(rtol=s.rtol)
        if s.transient > 0:
            y = strobe_points(system, y, 1, transient=int(s.transient) - 1, tolerances=tol)[1]
        # one period more than needed: the last sample may round past the last strobe time
        spp = int(samples_per_period)
        _, xc, vc = trajectory(system, y, (0.0, t[-1] + T), n_samples=n + spp, tolerances=tol)
        xc, vc = xc[:n], vc[:n]
    else:  # "scipy"
        if s.transient > 0:
            sol = solve_ivp(
                system.rhs,
                (0.0, s.transient * T),
                y,
                method="DOP853",
                rtol=s.rtol,
                atol=s.rtol * 1e-2,
            )
            y = sol.y[:, -1]
        sol = solve_ivp(
            system.rhs, (0.0, t[-1]), y, method="DOP853", rtol=s.rtol, atol=s.rtol * 1e-2, t_eval=t
        )
        if sol.status != 0:
            raise IntegrationError(f"solve_ivp: {sol.message}")
        xc, vc = sol.y
    rng = np.random.default_rng(seed)
    xn = xc + float(noise) * np.ptp(xc) * rng.standard_normal(xc.size)
    return t, xn, xc, vc


@dataclass(frozen=True)
class Smoothed:
    """The record smoothed by a Savitzky-Golay filter (window ``window`` samples, a
    quintic): ``x``, its derivative ``v`` at the samples, cubic interpolants of both
    (:meth:`at`), and the noise's standard deviation estimated from the residual
    (``std(x - x_s) / sqrt(1 - h)``, ``h`` the filter's central weight)."""

    t: np.ndarray = field(repr=False)
    x: np.ndarray = field(repr=False)
    v: np.ndarray = field(repr=False)
    window: int
    noise_sd: float

    def at(self, ts):
        """``(x, x')`` at times ``ts`` (inside the record)."""
        from scipy.interpolate import CubicSpline

        ts = np.asarray(ts, float)
        return np.column_stack([CubicSpline(self.t, self.x)(ts), CubicSpline(self.t, self.v)(ts)])


def smooth(t, x, samples_per_period):
    """The record smoothed and differentiated (see :class:`Smoothed`): window about a
    quarter period (at least 7 samples, odd), polynomial order 5."""
    from scipy.signal import savgol_coeffs, savgol_filter

    w = max(7, int(round(samples_per_period / 4)) | 1)
    dt = float(t[1] - t[0])
    xs = savgol_filter(x, w, 5)
    v = savgol_filter(x, w, 5, deriv=1, delta=dt)
    h = float(savgol_coeffs(w, 5)[w // 2])
    core = slice(w, -w)
    sd = float(np.std((x - xs)[core]) / np.sqrt(1.0 - h))
    return Smoothed(t=t, x=xs, v=v, window=w, noise_sd=sd)


def check_forcing(t, x, B, nu):
    """The checked record ``(t, x)`` and its samples per forcing period; the forcing needs
    finite ``B`` and ``nu > 0``, the record at least 8 samples per period."""
    t, x = check_record(t, x)
    if not (np.isfinite(B) and np.isfinite(nu) and nu > 0):
        raise InputError(f"the forcing needs finite B and nu > 0, got B = {B}, nu = {nu}")
    spp = 2 * np.pi / nu / float(t[1] - t[0])
    if spp < 8:
        raise InputError(
            f"{spp:.3g} samples per forcing period; need at least 8 (20-50 is typical)"
        )
    return t, x, spp


def record_strobe_points(t, x, nu, smoothed=None):
    """The record's stroboscopic points ``(x, x')`` at ``t = 2 pi k / nu`` inside it
    (away from the filter's edge), from the smoothed record (:func:`smooth`); also their
    times."""
    t, x = check_record(t, x)
    T = 2 * np.pi / nu
    sm = smooth(t, x, T / float(t[1] - t[0])) if smoothed is None else smoothed
    dt = float(t[1] - t[0])
    lo, hi = t[0] + sm.window * dt, t[-1] - sm.window * dt
    ts = np.arange(int(np.ceil(lo / T - 1e-9)), int(np.floor(hi / T + 1e-9)) + 1) * T
    ts = ts[(ts >= lo - 1e-9 * T) & (ts <= hi + 1e-9 * T)]
    return sm.at(ts), ts


def classify_record(strobe, noise_sd, *, max_period=8, monotone=0.98):
    """The regime of a record from its strobe points alone (no exponent): ``P<n>`` if
    the last ``3 max_period`` points repeat after ``n`` periods in ``x`` to within
    ``6 noise_sd`` (plus 1e-5 of the range); else ``beat`` if the points turn around
    their centre monotonically (fraction >= ``monotone``: an invariant closed curve);
    else ``chaotic``.  Returns a :class:`~discovery.ueda.Regime`."""
    from .regimes import Regime

    s = np.asarray(strobe, float)
    rng_x = float(np.ptp(s[:, 0])) or 1.0
    closure = 6.0 * float(noise_sd) + 1e-5 * rng_x
    m = min(len(s) - 1, 3 * max_period)
    tail = s[-(m + 1) :, 0]
    rec = {
        n: float(np.max(np.abs(tail[n:] - tail[:-n])))
        for n in range(1, max_period + 1)
        if n < len(tail)
    }
    ev = {"recurrence_x": rec, "closure_x": closure, "noise_sd": float(noise_sd)}
    for n, d in rec.items():
        if d < closure:
            ev["rule"] = (
                f"x at the strobe points repeats after {n} period(s) ({d:.2g} < "
                f"{closure:.2g}, 6 noise sd)"
            )
            return Regime(f"P{n}", "P1" if n == 1 else "Pn", n, ev)
    rho, mono = rotation_number(s)
    ev["rotation_number"], ev["monotone_fraction"] = rho, mono
    if mono >= monotone:
        ev["rule"] = (
            f"no period <= {max_period}; the points turn monotonically around their "
            f"centre ({mono:.3f} >= {monotone}): an invariant closed curve"
        )
        return Regime("beat", "beat", 0, ev)
    ev["rule"] = (
        f"no period <= {max_period}; the points do not turn monotonically ({mono:.3f} "
        f"< {monotone}): chaotic"
    )
    return Regime("chaotic", "chaotic", 0, ev)
