"""Least squares of the weak-form rows of records that share one machine, with intervals
from a bootstrap over the records' drive cycles (the windows of one cycle overlap and share
noise, those of different cycles hardly).

Three equations hold in every window: the frame's, the moulding's and their sum, the
momentum balance of the two bodies.  The balance holds no force: it fixes the machine's
ratios (``m2/m1``, ``c1/m1``, ``k1/m1``, ``A/m1``) from the motions alone, far tighter than
the equations that carry the force's noise, and those two set the one number the motions
cannot, the machine's scale (the frame's and the moulding's weighted by the inverse RMS of
their residuals).  Ratios and scale are fitted in turn: in one least squares with the others
the balance, which is homogeneous, would pull the whole machine toward zero.
``m1, c1, k1, k3, m2`` are shared by the records; each has its own drive amplitude ``A``.
A parameter may be held (its column moves to the right-hand side).

The scale is fitted twice: with the force's equations on each contact's own window, whose
test function vanishes at the onset's force jump (unbiased whatever the sampling, see
:attr:`~.equations.MachineRows.anchored`), and on the evenly spread windows, which weigh the
whole impulse (tighter where the force's noise dominates, biased where a jump falls between
the same two samples every period).  Where the two agree within :data:`AGREE` combined
standard errors the tighter one is used, else the first; the intervals span both.

The bootstrap's replicates are the same fit on the drawn windows; they are fitted together,
each window weighted by how often its replicate draws it (:mod:`.batched`: 0.52 s of
per-replicate fits in a calibration of a 30-period record down to 0.07 s).
"""

from dataclasses import dataclass

import numpy as np

from . import batched
from .equations import FRAME_TERMS

__all__ = [
    "Estimate",
    "estimate",
    "cycle_draws",
    "parameter_names",
    "drive_phase",
    "force_lag",
]

#: the fewest contact windows for the force's equations to use them alone
MIN_ANCHORED = 3
#: the two window sets' scales agree within this many combined standard errors
AGREE = 3.0


def parameter_names(n_records):
    """``m1, c1, k1, k3``, one ``A`` per record (``A`` alone for one record, else ``A[1]``,
    ``A[2]``, ...), then ``m2``."""
    amps = ["A"] if n_records == 1 else [f"A[{r + 1}]" for r in range(n_records)]
    return (*FRAME_TERMS[:4], *amps, "m2")


@dataclass(frozen=True)
class Estimate:
    """Estimated parameters (ndarrays over :attr:`names`; a held one has its given value
    and a zero-width interval).

    Attributes
    ----------
    names : tuple of str
    value, low, high : ndarray
        Estimates and their 95 % bootstrap intervals.
    fixed : ndarray of bool
    residual : dict
        ``{"frame", "moulding"}``: RMS of the weak-form residual over the RMS of the
        measured force term (0: the equations hold exactly).
    """

    names: tuple
    value: np.ndarray
    low: np.ndarray
    high: np.ndarray
    fixed: np.ndarray
    residual: dict

    def get(self, name):
        return float(self.value[self.names.index(name)])


def cycle_draws(rows, n_boot, seed):
    """``n_boot`` resamples of each record's cycles (with replacement), as row indices: a
    list over replicates of lists over records."""
    rng = np.random.default_rng(seed)
    groups = []
    for r in rows:
        cycles = np.unique(r.cycle)
        groups.append([np.flatnonzero(r.cycle == c) for c in cycles])
    draws = []
    for _ in range(n_boot):
        one = []
        for g in groups:
            pick = rng.integers(0, len(g), len(g))
            one.append(np.concatenate([g[k] for k in pick]))
        draws.append(one)
    return draws


def _blocks(rows, pick=None, force_on="contacts"):
    """The three stacked blocks of the design, each ``(X, y)`` with the columns of
    :func:`parameter_names`: the frame (``y = -int phi F``), the moulding
    (``y = int phi F``) and their sum, the momentum balance (``y = 0``)."""
    R = len(rows)
    frame, mould, f, anchored = [], [], [], []
    for r, row in enumerate(rows):
        sel = np.arange(row.n_windows) if pick is None else pick[r]
        fr = row.frame[sel]
        X = np.zeros((fr.shape[0], 5 + R))
        X[:, :4] = fr[:, :4]
        X[:, 4 + r] = fr[:, 4]
        M = np.zeros_like(X)
        M[:, -1] = row.moulding[sel]
        frame.append(X)
        mould.append(M)
        f.append(row.force[sel])
        anchored.append(row.anchored[sel])
    frame, mould, f = np.vstack(frame), np.vstack(mould), np.concatenate(f)
    anchored = np.concatenate(anchored)
    force, even = _force_windows(rows, anchored, force_on), ~anchored
    return (
        (frame[force], -f[force]),
        (mould[force], f[force]),
        (frame[even] + mould[even], np.zeros(int(even.sum()))),
    )


def _force_windows(rows, anchored, force_on):
    """The windows of the force's equations (``anchored``: the rows' flags, stacked): the
    contacts' own where there are enough (see :attr:`~.equations.MachineRows.anchored`),
    ``force_on`` is ``"contacts"`` and no record's force is a lagging sensor's (``lagged``),
    else the evenly spread ones (those of the balance)."""
    return anchored if _on_contacts(rows, anchored.sum(), force_on) else ~anchored


def _on_contacts(rows, n_anchored, force_on):
    """Whether the force's equations are on the contacts' own windows (:func:`_force_windows`)
    where ``n_anchored`` of them are taken."""
    lagged = any(r.lagged for r in rows)
    return force_on == "contacts" and not lagged and n_anchored >= MIN_ANCHORED


def _force_rates(rows, pick, force_on):
    """The force's rate column (``force_rate``) on the rows of the force's equations of
    :func:`_blocks`, in their order."""
    sels = [np.arange(r.n_windows) if pick is None else pick[k] for k, r in enumerate(rows)]
    rate = np.concatenate([r.force_rate[s] for r, s in zip(rows, sels, strict=True)])
    anchored = np.concatenate([r.anchored[s] for r, s in zip(rows, sels, strict=True)])
    return rate[_force_windows(rows, anchored, force_on)]


def _with_lag_column(blocks, rate):
    """The blocks with a last column for a force sensor's time constant ``tau``: ``+rate``
    in the frame's equation (``X theta + tau rate = -int phi F``), ``-rate`` in the
    moulding's, 0 in the balance (it holds no force)."""
    (Xf, yf), (Xm, ym), (Xb, yb) = blocks
    return (
        (np.column_stack([Xf, rate]), yf),
        (np.column_stack([Xm, -rate]), ym),
        (np.column_stack([Xb, np.zeros(yb.size)]), yb),
    )


def _solve(X, y, held):
    """Least squares with the columns of the non-NaN ``held`` values held at them."""
    free = np.isnan(held)
    theta = np.where(free, 0.0, held)
    rhs = y - X[:, ~free] @ theta[~free]
    A = X[:, free]
    scale = np.sqrt((A * A).sum(axis=0))
    scale[scale == 0] = 1.0
    theta[free] = np.linalg.lstsq(A / scale, rhs, rcond=None)[0] / scale
    return theta


def _weighted_solve(blocks, weights, held):
    X = np.vstack([w * b[0] for b, w in zip(blocks, weights, strict=True)])
    y = np.concatenate([w * b[1] for b, w in zip(blocks, weights, strict=True)])
    return _solve(X, y, held)


def _block_weights(blocks, theta):
    """Each block's weight: the inverse RMS of its residual at ``theta``."""
    rms = [float(np.sqrt(np.mean((y - X @ theta) ** 2))) for X, y in blocks]
    top = max(rms)
    if top == 0:
        return [1.0] * len(blocks)
    return [1.0 / max(r, 1e-12 * top) for r in rms]


#: rounds of the alternation between the ratios and the scale
ROUNDS = 4


def _fit(rows, held, pick=None, weights=None, force_on="contacts", *, lag=False):
    """The machine from the three blocks of :func:`_blocks`: the ratios to ``m1`` from the
    balance, the scale from the two equations that hold the force, in turn (a held
    parameter enters the balance at its value over the current scale).

    The balance is homogeneous: fitted in one least squares with the other two, its tight
    residual would pull the whole machine toward zero (measured: -6 % on a record with 3 %
    force noise), so it only ever sees the ratios.  ``weights`` (of the frame's and the
    moulding's equations, the inverse RMS of their residuals) are found on the first call.
    With ``lag`` a force sensor's time constant is fitted too, beside the scale (the
    balance does not see it).  Returns ``(theta, weights, tau)`` (``tau`` 0 without
    ``lag``)."""
    frame, mould, balance = _blocks(rows, pick, force_on)
    if lag:
        frame, mould, balance = _with_lag_column(
            (frame, mould, balance), _force_rates(rows, pick, force_on)
        )
        held = np.append(held, np.nan)
    theta = _weighted_solve((frame, mould), weights or (1.0, 1.0), held)
    if weights is None:
        weights = _block_weights((frame, mould), theta)
        theta = _weighted_solve((frame, mould), weights, held)
    free = np.isnan(held)
    scaled = free.copy()
    if lag:
        scaled[-1] = False  # tau is no ratio to m1
    X = np.vstack([w * b[0] for b, w in zip((frame, mould), weights, strict=True)])
    y = np.concatenate([w * b[1] for b, w in zip((frame, mould), weights, strict=True)])
    tau = theta[-1] if lag else 0.0
    for _ in range(ROUNDS):
        scale = theta[0]
        if not (np.isfinite(scale) and scale != 0):
            break
        ratios_held = np.where(free, np.nan, held / scale)
        ratios_held[0] = 1.0
        if lag:
            ratios_held[-1] = 0.0
        rho = _solve(*balance, ratios_held)
        if free[0]:
            part = X[:, scaled] @ rho[scaled]
            rest = y - X[:, ~free] @ held[~free]
            scale, tau = _scale_step(part, X[:, -1] if lag else None, rest, scale)
        theta = np.where(free, scale * rho, held)
        if lag:
            theta[-1] = tau
    return (theta[:-1], weights, float(tau)) if lag else (theta, weights, 0.0)


def _scale_step(part, lag_column, rest, scale):
    """The machine's scale (and a sensor's time constant, with its ``lag_column``) by least
    squares of ``rest`` on ``part``: ``(scale, tau)``; the given ``scale`` where ``part``
    is all zeros."""
    if lag_column is None:
        den = float(part @ part)
        return (float(part @ rest) / den if den > 0 else scale), 0.0
    A = np.column_stack([part, lag_column])
    sol = np.linalg.lstsq(A, rest, rcond=None)[0]
    return float(sol[0]), float(sol[1])


def _relative_rms(res, y):
    ref = float(np.sqrt(np.mean(y * y)))
    return float(np.sqrt(np.mean(res * res)) / ref) if ref > 0 else np.nan


def estimate(rows, fixed, draws):
    """Estimate the machine from the records' ``rows`` (:class:`MachineRows`, one machine).

    Parameters
    ----------
    rows : list of MachineRows
    fixed : dict
        ``{name: value}`` of the parameters held (names of :func:`parameter_names`).
    draws : list
        The bootstrap's cycle resamples (:func:`cycle_draws`).

    Returns
    -------
    Estimate
    """
    names = parameter_names(len(rows))
    held = np.array([fixed.get(n, np.nan) for n in names], dtype=float)
    value, low, high = _choose(
        _bootstrapped(rows, held, draws, "contacts"), _bootstrapped(rows, held, draws, "even")
    )
    fixed_mask = ~np.isnan(held)
    low = np.where(fixed_mask, value, low)
    high = np.where(fixed_mask, value, high)
    residual = {
        "frame": frame_residual(rows, value[:-1]),
        "moulding": moulding_residual(rows, value[-1]),
    }
    return Estimate(names, value, low, high, fixed_mask, residual)


def _choose(contacts, even):
    """The estimate of the two window sets' (see the module docstring): where their scales
    (``m1``) agree within :data:`AGREE` combined standard errors, the one with the tighter
    interval, else the contacts' (the evenly spread windows' is biased); the intervals span
    both, so that a bias of either is inside."""
    v_c, lo_c, hi_c = contacts
    v_e, lo_e, hi_e = even
    if not (np.all(np.isfinite(lo_c[:1])) and np.all(np.isfinite(lo_e[:1]))):
        return contacts
    se = np.hypot(hi_c[0] - lo_c[0], hi_e[0] - lo_e[0]) / (2 * 1.96)
    tighter = v_e if hi_e[0] - lo_e[0] <= hi_c[0] - lo_c[0] else v_c
    value = tighter if abs(v_e[0] - v_c[0]) <= AGREE * se else v_c
    return value, np.fmin(lo_c, lo_e), np.fmax(hi_c, hi_e)


def _bootstrapped(rows, held, draws, force_on):
    """``(value, low, high)``: the fit with the force's equations on ``force_on`` windows
    and its 95 % bootstrap interval."""
    value, weights, _ = _fit(rows, held, force_on=force_on)
    if not draws:
        nan = np.full(value.size, np.nan)
        return value, nan, nan
    boot = _boot_fits(rows, held, draws, weights, force_on)[0]
    low, high = np.nanpercentile(boot, [2.5, 97.5], axis=0)
    return value, low, high


def force_lag(rows, fixed, draws, force_on="even"):
    """A force sensor's time constant ``tau`` [s] fitted with the machine (:func:`_fit`
    with ``lag``, the force's equations on ``force_on`` windows), and its 95 % bootstrap
    interval over the draws: ``(tau, low, high)``."""
    names = parameter_names(len(rows))
    held = np.array([fixed.get(n, np.nan) for n in names], dtype=float)
    _, weights, tau = _fit(rows, held, force_on=force_on, lag=True)
    if not draws:
        return tau, np.nan, np.nan
    boot = _boot_fits(rows, held, draws, weights, force_on, lag=True)[1]
    low, high = np.nanpercentile(boot, [2.5, 97.5])
    return tau, float(low), float(high)


def _row_counts(rows, draws):
    """How often each replicate of ``draws`` takes each window of ``rows`` (stacked in
    their order): ``(B, windows)``."""
    offsets = np.cumsum([0, *(r.n_windows for r in rows)])
    n = int(offsets[-1])
    flat = np.concatenate(
        [b * n + offsets[k] + p for b, one in enumerate(draws) for k, p in enumerate(one)]
    )
    return np.bincount(flat, minlength=len(draws) * n).reshape(len(draws), n).astype(float)


def _boot_fits(rows, held, draws, weights, force_on, *, lag=False):
    """Each draw's :func:`_fit` with the full fit's ``weights``, all at once
    (:func:`.batched.fits`): ``(theta, tau)``, ``(B, P)`` and ``(B,)`` (zeros without
    ``lag``).  A draw whose force's equations fall on the other kind of windows (too few
    contacts drawn, see :func:`_force_windows`) or whose batched fit is degenerate is
    fitted alone by :func:`_fit`."""
    counts = _row_counts(rows, draws)
    anchored = np.concatenate([r.anchored for r in rows])
    contacts = _on_contacts(rows, anchored.sum(), force_on)
    force = anchored if contacts else ~anchored
    blocks, h = _blocks(rows, None, force_on), held
    if lag:
        blocks = _with_lag_column(blocks, _force_rates(rows, None, force_on))
        h = np.append(held, np.nan)
    theta, ok = batched.fits(
        blocks, (counts[:, force], counts[:, ~anchored]), h, weights, rounds=ROUNDS, lag=lag
    )
    ok &= np.array([_on_contacts(rows, k, force_on) == contacts for k in counts @ anchored])
    for b in np.flatnonzero(~ok):
        th, _, tau = _fit(rows, held, draws[b], weights, force_on, lag=lag)
        theta[b] = np.append(th, tau) if lag else th
    return (theta[:, :-1], theta[:, -1]) if lag else (theta, np.zeros(len(draws)))


def frame_residual(rows, theta_frame):
    """The frame's relative weak-form residual with given ``m1, c1, k1, k3, A...``, on the
    evenly spread windows (those of the figure: the same rows for every machine)."""
    X, y = _blocks(rows, force_on="even")[0]
    return _relative_rms(y - X[:, :-1] @ np.asarray(theta_frame, dtype=float), y)


def moulding_residual(rows, m2):
    """The moulding's relative weak-form residual with the mass ``m2`` (evenly spread windows)."""
    X, y = _blocks(rows, force_on="even")[1]
    return _relative_rms(y - X[:, -1] * m2, y)


def drive_phase(rows, draws):
    """Each record's drive phase [deg] at its ``t = 0`` from a fit of the frame with a
    ``cos`` column too, and its 95 % interval: ``[(phase, low, high), ...]`` (0 when the
    record is on the drive's clock)."""
    R = len(rows)

    def fit(pick):
        blocks, ys = [], []
        for r, row in enumerate(rows):
            sel = np.arange(row.n_windows) if pick is None else pick[r]
            sel = sel[~row.anchored[sel]]
            X = np.zeros((sel.size, 4 + 2 * R))
            X[:, :4] = row.frame[sel, :4]
            X[:, 4 + r] = row.frame[sel, 4]
            X[:, 4 + R + r] = row.drive_cos[sel]
            blocks.append(X)
            ys.append(-row.force[sel])
        X, y = np.vstack(blocks), np.concatenate(ys)
        th = _solve(X, y, np.full(X.shape[1], np.nan))
        return np.degrees(np.arctan2(th[4 + R :], th[4 : 4 + R]))

    phase = fit(None)
    if not draws:
        return [(float(p), np.nan, np.nan) for p in phase]
    boot = np.array([fit(p) for p in draws])
    boot = phase + (boot - phase + 180.0) % 360.0 - 180.0  # wrapped around the estimate
    low, high = np.percentile(boot, [2.5, 97.5], axis=0)
    return [(float(p), float(a), float(b)) for p, a, b in zip(phase, low, high, strict=True)]
