"""The motion criterion I5: the recorded penetration against the simulated one over the contacts.

The force criteria I0-I4 cannot tell two laws apart whose force histories differ by less
than the force noise: a spring several times too soft with more damping reaches nearly the
same depth and impulse, but at the contact's turning point (where the rate is zero and only
the spring acts) its force is far smaller, and a small force tail keeps the bodies together
longer.  Those differences sit under the force noise; the penetration ``zeta = w1 - w2``
shows them.  With positions recorded, both penetrations go through the same fold as the
force (:class:`~discovery.vibroimpact.verify.fold.Fold`, the same sample times and bins)::

    I5 = sqrt( sum_b n_b (Z_N,b - Z_E,b)^2 / sum_b n_b Z_E,b^2 )

over the bins ``b`` (``n_b`` samples each) inside the contact window: where either side is
in contact by its force (the folded supports) or by its geometry (a folded penetration
``> 0``), widened by 1 % of a drive period (as the force criteria's window).
``Z_E`` is the recorded penetration, ``Z_N`` the simulated one, both bin means.  For a
record span it is the blocks' mean weighted by their cycles, like the force criteria.  Its
noise floor comes from the same replicates as theirs (the law's own runs from start states
drawn from the state fit's covariance, with the record's penetration noise added at its
sample times).  A record without positions has no I5; its verdict says so.
"""

import numpy as np

from ...numerics.intervals import in_widened_intervals
from ...numerics.memo import Memo

__all__ = [
    "MOTION_CRITERION",
    "penetration_criterion",
    "block_penetration",
    "fold_penetration",
    "penetration_mean",
    "contact_window",
    "contact_runs",
    "contact_samples_of",
    "penetration_residuals",
    "penetration_jacobian",
    "penetration_size",
    "force_penetration_loops",
]

MOTION_CRITERION = "I5"
"""The criterion's name in every table, floor and limit."""

WINDOW_PAD = 0.01
"""The contact window's widening on each side, in drive periods (as the force criteria's)."""


def contact_window(fold, impulses, penetrations=(), pad=WINDOW_PAD):
    """Whether each of the fold's bins lies in the contact window, ndarray of bool of shape
    (k,): where either side is in contact by its force (the ``impulses``' supports) or by
    its geometry (a folded penetration ``> 0``), widened by ``pad`` drive periods on each
    side (cyclic over the fold's cycle).  The geometry matters: a law whose force tail
    stays under the contact threshold still holds the bodies together, while the recorded
    ones have parted."""
    W = fold.duration
    pad = pad * fold.period
    iv = [np.asarray(imp.support, dtype=float).reshape(-1, 2) for imp in impulses]
    iv += [fold.positive_phases(z) for z in penetrations]
    return in_widened_intervals(fold.phase, np.concatenate(iv), pad, W)


def penetration_criterion(fold, z_measured, z_simulated, window):
    """I5 of one fold: the bin means of both penetrations compared inside ``window``.

    Parameters
    ----------
    fold : Fold
    z_measured, z_simulated : ndarray of shape (m,)
        The penetrations at the fold's samples [m].
    window : ndarray of bool, shape (k,)
        The bins compared (:func:`contact_window`).

    Returns
    -------
    float
        ``inf`` when the window is empty or the recorded penetration is zero there.
    """
    if not np.any(window):
        return float("inf")
    ze = fold.average(z_measured)[window]
    zn = fold.average(z_simulated)[window]
    n = fold.counts[window].astype(float)
    den = float(np.sum(n * ze * ze))
    if den <= 0.0:
        return float("inf")
    return float(np.sqrt(np.sum(n * (zn - ze) ** 2) / den))


def block_penetration(span, measured, simulated, z_measured, z_simulated):
    """I5 of a record span: each block's value and their mean weighted by cycles.

    Parameters
    ----------
    span : RecordSpan
    measured, simulated : sequence of Impulse
        Each block's folded force cycles (their supports make the window).
    z_measured, z_simulated : sequence of ndarray
        Each block's penetration at its folded samples [m].

    Returns
    -------
    mean : float
    per_block : list of float
    """
    per = [
        fold_penetration(b.fold, m, s, zm, zs)
        for b, m, s, zm, zs in zip(
            span.blocks, measured, simulated, z_measured, z_simulated, strict=True
        )
    ]
    return penetration_mean(span, per), per


def fold_penetration(fold, measured, simulated, z_measured, z_simulated):
    """I5 of one block's fold: its penetrations compared inside the contact window of its
    folded force cycles and penetrations (a block farm's worker computes it with the
    block's other criteria)."""
    window = contact_window(fold, (measured, simulated), (z_measured, z_simulated))
    return penetration_criterion(fold, z_measured, z_simulated, window)


def penetration_mean(span, per_block):
    """The blocks' I5 values' mean weighted by their cycles."""
    w = np.array([b.fold.n_cycles for b in span.blocks], dtype=float)
    return float(np.dot(w / w.sum(), per_block))


RESIDUAL_PAD = 0.1
"""The output-error residual's penetration window: the record's own contact window widened
by this many drive periods on each side, fixed by the record (a residual vector of one size
for every law), wide enough to hold a law's longer contact."""


def _residual_window(blk, measured):
    """The record's residual window of a block, asked once per block (the memo's entry
    keeps the block, so its id is not reused while cached)."""
    return _WINDOWS.get(
        id(blk),
        lambda: (blk, contact_window(blk.fold, (measured,), (blk.Z,), pad=RESIDUAL_PAD)),
    )[1]


_WINDOWS = Memo(256)


def penetration_residuals(reference, evaluation, weights=None):
    """The penetration part of the output-error residual, in the force's units.

    Per block of a record span: the bin means of ``Z_N - Z_E`` inside the record's contact
    window (:data:`RESIDUAL_PAD`), times ``sigma_F / sigma_Z`` (so a bin's noise is a force
    bin's) and the force residual's own weight of that bin (``weights``: one array per
    block, the force cycle's, of shape (bins + 2,)).  Empty for a record without positions
    (or compared with its steady orbit).

    Returns
    -------
    ndarray of shape (n,)
    """
    span = getattr(reference, "span", None)
    z_sim = evaluation.penetration if evaluation is not None else None
    if span is None or span.sigma_z <= 0 or z_sim is None:
        return np.zeros(0)
    scale = span.sigma_f / span.sigma_z
    out = []
    for k, (blk, E, zs) in enumerate(zip(span.blocks, reference.blocks, z_sim, strict=True)):
        win = _residual_window(blk, E)
        r = blk.fold.average(zs - blk.Z) * scale
        if weights is not None:
            r = r * weights[k][1:-1]
        out.append(r[win])
    return np.concatenate(out) if out else np.zeros(0)


def penetration_jacobian(reference, derivatives, weights=None):
    """The derivatives of :func:`penetration_residuals` along ``m`` parameters, from the
    simulated penetration's derivatives at every block's samples (``derivatives``: one
    array of shape (m, samples) per block; the residual is linear in the penetration).

    Returns
    -------
    ndarray of shape (n, m)
    """
    span = reference.span
    scale = span.sigma_f / span.sigma_z
    out = []
    for k, (blk, E, d) in enumerate(zip(span.blocks, reference.blocks, derivatives, strict=True)):
        win = _residual_window(blk, E)
        rows = np.array([blk.fold.average(r) for r in d]).reshape(len(d), -1) * scale
        if weights is not None:
            rows = rows * weights[k][1:-1]
        out.append(rows[:, win].T)
    return np.concatenate(out)


def penetration_size(reference):
    """The length of :func:`penetration_residuals` for ``reference`` (0 without positions)."""
    span = getattr(reference, "span", None)
    if span is None or span.sigma_z <= 0:
        return 0
    return int(
        sum(
            np.count_nonzero(_residual_window(b, E))
            for b, E in zip(span.blocks, reference.blocks, strict=True)
        )
    )


def contact_runs(active, gap):
    """``[(start, stop)]`` of the runs of ``active`` samples (runs closer than ``gap``
    samples are one: the bounces of one contact)."""
    idx = np.flatnonzero(active)
    if not idx.size:
        return []
    cut = np.flatnonzero(np.diff(idx) > gap)
    starts = np.concatenate([[idx[0]], idx[cut + 1]])
    stops = np.concatenate([idx[cut], [idx[-1]]]) + 1
    return [(int(a), int(b)) for a, b in zip(starts, stops, strict=True)]


def contact_samples_of(blk, simulated, sigma):
    """The samples of a block where the measured or the simulated force is in contact
    (above three noise deviations and 2 % of the measured peak, in runs of three samples or
    more: a lone noise sample is none), ndarray of bool."""
    fm, fn = np.asarray(blk.F, dtype=float), np.asarray(simulated, dtype=float)
    thr = max(3.0 * sigma, 0.02 * float(np.max(np.abs(fm))))
    active = (fm > thr) | (fn > thr)
    inside = np.zeros(fm.size, dtype=bool)
    for a, b in contact_runs(active, 2):
        inside[a:b] = b - a >= 3
    return inside & active


def force_penetration_loops(reference, evaluation):
    """The measured and simulated force-penetration loops of a record span's latest block.
    With the evaluation's simulated histories (a fresh evaluation): the record's own
    samples where either force is in contact (:func:`contact_samples_of`), in time order.
    A record in a transient has its contacts at another phase in each cycle, and a fold of
    several cycles would pair one cycle's force with another's penetration.  Without them
    (a loaded evaluation): the folded bin means inside the contact window.

    Returns
    -------
    dict or None
        ``{"measured": (zeta, F), "simulated": (zeta, F), "phase": t}`` (ndarrays [m],
        [N], and the samples' times since the block's start, or the bins' since the fold's
        origin [s]); ``None`` for a record without positions or an evaluation without a
        simulation.
    """
    span = getattr(reference, "span", None)
    z_sim = evaluation.penetration if evaluation is not None else None
    blocks = evaluation.blocks if evaluation is not None else None
    if span is None or span.sigma_z <= 0 or not z_sim or not blocks:
        return None
    hist = evaluation.histories
    if hist and len(hist[-1]) == len(span.blocks[-1].F):
        blk, zs, fs = span.blocks[-1], np.asarray(z_sim[-1]), np.asarray(hist[-1])
        win = contact_samples_of(blk, fs, span.sigma_f)
        if win.any():
            td = np.asarray(blk.fold.td, dtype=float)
            return {
                "measured": (np.asarray(blk.Z)[win], np.asarray(blk.F)[win]),
                "simulated": (zs[win], fs[win]),
                "phase": td[win] - td[0],
            }
    blk, (E, S), zs = span.blocks[-1], blocks[-1], z_sim[-1]
    fold = blk.fold
    zm, zn = fold.average(blk.Z), fold.average(zs)
    win = contact_window(fold, (E, S), (blk.Z, zs))
    # the folded force at the bins (the impulses hold the bins between their two end knots)
    return {
        "measured": (zm[win], np.asarray(E.F[1:-1])[win]),
        "simulated": (zn[win], np.asarray(S.F[1:-1])[win]),
        "phase": fold.phase[win],
    }
