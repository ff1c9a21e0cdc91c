"""Contacts in a sampled force record: the runs above a threshold with their sub-sample
onsets and losses (:func:`_edges`), as the record's contacts (:func:`_contact_runs`: noise
runs dropped, onsets refined on the penetration; their onsets: :func:`contact_onsets`) or as
a cycle's support (:func:`_sampled_support`)."""

import numpy as np

from .noise import estimate_noise


def _refine_onset(t, zeta, s, t_on, max_back):
    """Onset as the zero up-crossing of zeta at or before sample ``s`` (searched back
    at most ``max_back`` samples): a quadratic through the three samples before the
    crossing (free flight, smooth) extrapolated into the crossing interval, O(dt^3)."""
    k = min(s, len(t) - 1)
    stop = max(3, k - int(max_back))
    while k > stop and zeta[k - 1] > 0.0:
        k -= 1
    if not (k >= 3 and zeta[k - 1] <= 0.0 < zeta[k]):
        return t_on
    a, b, c = np.polyfit(t[k - 3 : k] - t[k - 1], zeta[k - 3 : k], 2)
    roots = np.roots([a, b, c]) if a != 0 else np.array([-c / b])
    h = t[k] - t[k - 1]
    ok = [r.real for r in roots if abs(r.imag) < 1e-12 and -1e-9 * h <= r.real <= h]
    if ok:
        return t[k - 1] + min(ok)
    return t[k - 1] + (0.0 - zeta[k - 1]) / (zeta[k] - zeta[k - 1]) * h


def _merge_unseparated(t, zeta, runs):
    """Runs of force whose gap has no separation are one contact: when ``zeta`` never
    goes clearly below zero between them (by three times its noise), the force only
    dipped below the threshold within a contact (a near-loss), and the second run is
    neither a new impact nor, however large, the main one (its "onset" would be a
    point inside the contact)."""
    if len(runs) < 2:
        return runs
    sz = estimate_noise(zeta, order=3)
    out = [runs[0]]
    for r in runs[1:]:
        t_on, t_off, s = out[-1]
        a, b = int(np.searchsorted(t, t_off)), r[2]
        if b > a and np.min(zeta[a:b]) > -3.0 * sz:
            out[-1] = (t_on, r[1], s)
        else:
            out.append(r)
    return out


def _bracket_onset(t, F, run, thr):
    """The ``zeta`` onset of ``run = (t_on, t_off, s)`` (onset, loss, first sample above
    ``thr``) kept where the force allows it: not after sample ``s``, the first
    one above the threshold (the contact has begun there), and, when the force *jumps*
    at ``s`` (from at most half the threshold to a quarter of the contact's peak or
    more: a viscous contact's ``F(0+)``), not before sample ``s - 1`` either (the force
    was still zero there).  A noisy ``zeta`` can be a sample or two off; a force jump
    brackets the onset within one sample."""
    t_on, t_off, s = run
    hi = t[s]
    lo = -np.inf
    if s >= 1:
        e = max(int(np.searchsorted(t, t_off)), s + 1)
        if F[s - 1] <= 0.5 * thr and F[s] >= 0.25 * float(np.max(F[s:e])):
            lo = t[s - 1]
    return float(min(max(t_on, lo), hi))


def moving_mean(x, width):
    """The mean of ``x`` over ``width`` samples centred on each (``width`` odd), the ends
    padded with the end values: ``scipy.ndimage.uniform_filter1d(x, width, mode="nearest")``
    to the last bit (the same running sum, in the same order: the contact edges decide
    samples at a threshold, and a last-bit change moved a survey record's final refit),
    without importing ``scipy.ndimage`` (a quarter of a second of every command's start)."""
    from ...numerics.sampled import running_mean  # (numba: not at import)

    return running_mean(np.ascontiguousarray(x, dtype=float), int(width))


def _edge_params(t, period, min_samples=3):
    """Debounce length and edge extrapolation bound [samples] for a sampling."""
    dt = float(np.median(np.diff(t)))
    return max(min_samples, int(0.01 * period / dt)), max(4.0, 0.02 * period / dt)


def _sampled_support(tau, F, thr, period, *, noise=0.0, extrapolate=True, edges=None):
    """Support of a cycle sampled at ``tau`` (starting at the onset, ``tau[0] = 0``).

    When its noise is not negligible (``noise > thr / 100``) the cycle is first smoothed
    by a moving average over 1 % of a period, so noise near a flat tail does not stretch
    the support by chance crossings of the threshold (the measured and the simulated
    cycle go through the same operator; a smoothed edge moves by up to half a window).
    ``edges``: :func:`_edge_params` of ``tau`` when the caller keeps them (a fold's)."""
    min_len, max_extrap = _edge_params(tau, period) if edges is None else edges
    dt = tau[2] - tau[1]
    width = max(1, int(0.01 * period / dt)) | 1 if noise > thr / 100.0 else 1
    Fs = moving_mean(np.asarray(F, dtype=float), width)
    Fs[0] = F[0]
    t_ext = np.concatenate([[-dt], tau, [tau[-1] + dt]])
    f_ext = np.concatenate([[0.0], Fs, [0.0]])
    runs = _edges(
        t_ext,
        f_ext,
        thr,
        min_len,
        max_extrap=max_extrap if extrapolate else None,
        noise=noise / np.sqrt(width),
    )
    sup = [(max(a, 0.0), min(b, tau[-1])) for a, b, _ in runs]
    return np.array(sup, dtype=float).reshape(-1, 2)


def _edges(t, F, thr, min_len, *, max_extrap=4.0, noise=0.0):
    """Sub-sample start/end times of the runs where F > thr (runs shorter than
    ``min_len`` samples dropped unless they last 3 samples and peak above ``3 thr``;
    gaps shorter than ``min_len``, or not going below ``thr - 3 noise``, closed).

    An edge whose step between samples clearly exceeds the noise (``> 3 noise``) is
    extrapolated along its slope to zero force, by at most ``max_extrap`` samples, so
    the part of a smooth rise or fall below the threshold is not cut off; a flat,
    noisy edge has no meaningful slope and ends at its threshold crossing."""
    from ...numerics.sampled import threshold_runs  # (numba: not at import)

    runs = threshold_runs(
        np.ascontiguousarray(t, dtype=float),
        np.ascontiguousarray(F, dtype=float),
        float(thr),
        int(min_len),
        -1.0 if max_extrap is None else float(max_extrap),
        float(noise),
    )
    return [(float(a), float(b), int(k)) for a, b, k in runs]


def _contact_runs(t, F, thr, sigma, period, *, min_samples, zeta):
    """The contacts ``[(onset, loss, first sample), ...]`` above ``thr`` (gaps shorter than
    1 % of a period are noise flicker inside one contact; a contact whose peak barely clears
    the threshold is noise); with ``zeta``, contacts not separated by a free flight merged
    and onsets refined on the penetration."""
    min_len, max_extrap = _edge_params(t, period, min_samples)
    runs = _edges(t, F, thr, min_len, max_extrap=max_extrap, noise=sigma)
    if runs:
        # a contact whose peak barely clears the threshold is noise, not an impact
        pk = np.array([np.max(F[s : int(np.searchsorted(t, off)) + 1]) for _, off, s in runs])
        runs = [r for r, p in zip(runs, pk, strict=True) if p >= max(3 * thr, 0.02 * pk.max())]
    if zeta is not None:
        zeta = np.asarray(zeta, dtype=float)
        runs = _merge_unseparated(t, zeta, runs)
        back = 0.25 * period / float(np.median(np.diff(t)))
        runs = [
            (_bracket_onset(t, F, (_refine_onset(t, zeta, s, t_on, back), t_off, s), thr), t_off, s)
            for t_on, t_off, s in runs
        ]
    return runs


def contact_onsets(t, F, period, *, zeta=None, min_samples=3):
    """The onset times [s] of a record's contacts, as
    :func:`~discovery.vibroimpact.data.impulse.impulse_from_samples` finds them (threshold
    ``max(5 sigma, 1e-3 max F)``, noise runs dropped; with ``zeta``, contacts not separated
    by a free flight are one)."""
    t, F = np.asarray(t, dtype=float), np.asarray(F, dtype=float)
    runs = _record_contacts(t, F, period, min_samples, zeta)[1]
    return np.array([r[0] for r in runs], dtype=float)


def _record_contacts(t, F, period, min_samples=3, zeta=None):
    """``(sigma, runs)``: the force's noise and its contacts (:func:`_contact_runs`) at the
    record's threshold ``max(5 sigma, 1e-3 max F)``."""
    sigma = estimate_noise(F)
    thr = max(5.0 * sigma, 1e-3 * float(np.max(F)))
    return sigma, _contact_runs(t, F, thr, sigma, period, min_samples=min_samples, zeta=zeta)


def onset_penetrations(t, F, zeta, period, *, flight=0.05):
    """The recorded penetration at each contact's onset [m]: where a contact offset's
    contacts start (the force acts beyond a recorded penetration ``delta0``).

    The onset time is the force's: for a force that *jumps* at its first sample above the
    threshold (a viscous contact's ``F(0+)``: its rise over the next interval, taken back
    one interval, leaves more than its noise) the middle of the sample interval that
    brackets it (uniform within it, so unbiased over many contacts: the edge drawn through
    the samples on either side of the jump reads it up to a sample early, and a sample read
    at the first one in contact is half a sample's motion late); for a force that rises from
    zero, that rise taken back to zero force (at most four intervals).  The penetration
    there is a quadratic fitted by least squares to the free flight before it (up to
    ``flight`` of a period, after the previous contact's loss, at least 6 samples),
    extrapolated to the onset: a noisy penetration read at one sample is as noisy as the
    offset is small (survey draw 26: 46 um under 20 um of noise)."""
    t, F, zeta = (np.asarray(x, dtype=float) for x in (t, F, zeta))
    sigma, runs = _record_contacts(t, F, period)
    dt = float(np.median(np.diff(t)))
    longest = max(6, int(flight * period / dt))
    out, loss = [], -np.inf
    for _, t_off, s in runs:
        if s < 1 or s + 1 >= t.size:
            continue
        rise = F[s + 1] - F[s]  # the force's rise over the contact's first sample interval
        if F[s] - rise > 3.0 * sigma or rise <= 0.0:  # a jump: the onset within [s - 1, s]
            onset = 0.5 * (t[s - 1] + t[s])
        else:  # a rise from zero: back along it
            onset = t[s] - min(F[s] / rise, 4.0) * (t[s + 1] - t[s])
        k = int(np.searchsorted(t, onset, side="left"))  # the samples before the onset
        a = max(k - longest, int(np.searchsorted(t, loss, side="right")), 0)
        loss = t_off
        if k - a < 6:
            continue
        c = np.polyfit(t[a:k] - onset, zeta[a:k], 2)
        out.append(float(c[-1]))
    return np.array(out, dtype=float)
