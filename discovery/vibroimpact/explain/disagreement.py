"""Where a model and a record disagree, and by how much.

On the aligned measured cycle (the evaluation's common time axis) the residual
``r = F_N - F_E`` is split into impact phases, defined on the measured contact windows
``[a, b)`` with the measured peak at ``t_p``:

``onset``       the first two samples after ``a`` (the force jump of a damper)
``loading``     from there to ``t_p - 5 %`` of the contact
``peak``        within 5 % of the contact time around ``t_p``
``unloading``   from ``t_p + 5 %`` to two samples before ``b``
``separation``  from there to ``b + 2 %`` of a period
``free``        the rest (free flight: both forces should be zero)

Each phase gets its share of the energy in excess of the noise (``sum r^2 - n sigma^2``,
summed over the phases) and the ratio of its ``sum r^2`` to what the record's noise
alone would give there (``n sigma^2``, ``sigma`` the noise of the averaged
cycle): above 2 the phase's disagreement exceeds the noise.  The residual is also binned
over the simulated orbit's ``(zeta, dzeta)`` plane, the grid's motion ``w1`` is compared
(the simulated orbit at the record's times), and the impacts of the record are checked
for a drift (a trend of the peak force across impacts).
"""

import numpy as np

from ..dynamics.simulation import simulate

__all__ = ["PHASES", "localise", "simulated_at"]

PHASES = ("onset", "loading", "peak", "unloading", "separation", "free")
_EXCEEDS = 2.0


def _phase_of(t, windows, t_peaks, dt, period):
    phase = np.full(t.size, PHASES.index("free"))
    for (a, b), tp in zip(windows, t_peaks, strict=True):
        c = b - a
        sep = (t >= b - 2 * dt) & (t < b + 0.02 * period)
        phase[sep] = PHASES.index("separation")
        inside = (t >= a) & (t < b - 2 * dt)
        phase[inside & (t < tp - 0.05 * c)] = PHASES.index("loading")
        phase[inside & (np.abs(t - tp) <= 0.05 * c)] = PHASES.index("peak")
        phase[inside & (t > tp + 0.05 * c)] = PHASES.index("unloading")
        phase[(t >= a) & (t < a + 2 * dt)] = PHASES.index("onset")
    return phase


def simulated_at(scenario, law, steady, t_record, F_record, *, time_offset=0.0, tolerances=None):
    """States ``(w1, v1, w2, v2)`` of ``law``'s periodic orbit at the record's times (the
    orbit's phase among its ``n`` drive periods: the one whose force matches best)."""
    P = steady.n_periods * scenario.period
    best, out = np.inf, None
    for k in range(steady.n_periods):
        tau = np.mod(t_record + time_offset - steady.t0 + k * scenario.period, P)
        order = np.argsort(tau)
        tr = simulate(
            scenario,
            law,
            (steady.t0, steady.t0 + P),
            y0=steady.y0,
            t_eval=steady.t0 + tau[order],
            tolerances=tolerances,
            zeta_max0=steady.zeta_max0,
            impact_v0=steady.impact_v0,
        )
        inv = np.empty_like(order)
        inv[order] = np.arange(order.size)
        d = float(np.sum((tr.force[inv] - F_record) ** 2))
        if d < best:
            best, out = d, (tr.y[:, inv], tr.force[inv])
    return out


def _drift(measurement, period, threshold):
    """Trend of the per-impact peak force across the record (relative per impact)."""
    t, F = measurement.t, measurement.F
    k = np.floor((t - t[0]) / period).astype(int)
    peaks = np.array([F[k == j].max() for j in range(k.max()) if np.any(k == j)])
    peaks = peaks[peaks > threshold]
    if peaks.size < 5:
        return {"n_impacts": int(peaks.size), "slope": None, "t": None, "significant": False}
    x = np.arange(peaks.size, dtype=float)
    A = np.column_stack([np.ones_like(x), x])
    coef, res, *_ = np.linalg.lstsq(A, peaks, rcond=None)
    s2 = float(np.sum((peaks - A @ coef) ** 2)) / max(peaks.size - 2, 1)
    se = np.sqrt(s2 / float(np.sum((x - x.mean()) ** 2))) if s2 > 0 else 0.0
    tval = float(coef[1] / se) if se > 0 else 0.0
    return {
        "n_impacts": int(peaks.size),
        "slope": float(coef[1] / np.mean(peaks)),
        "t": tval,
        "significant": bool(abs(tval) > 4.0),
    }


def localise(scenario, model, reference, evaluation, measurement=None, *, tolerances=None):
    """Localise the disagreement of ``model`` (already evaluated) with a record.

    Returns
    -------
    dict
        ``phases`` {phase: {share, ratio_to_noise, exceeds_noise, n}}, ``plane`` (binned
        mean residual over the simulated ``(zeta, dzeta)``), ``grid`` (w1 disagreement
        relative to its range and to its noise), ``drift``, ``sigma`` (noise of the
        averaged cycle [N]), ``rms`` (residual RMS [N]).
    """
    E, sim = reference.impulse, evaluation.simulated
    r = sim.F - E.F
    dt = float(np.median(np.diff(E.t[E.t > 0]))) if E.t.size > 2 else 1.0
    period = E.duration / E.n_periods
    windows = E.support if len(E.support) else np.zeros((0, 2))
    t_peaks = [
        E.t[(E.t >= a) & (E.t < b)][np.argmax(E.F[(E.t >= a) & (E.t < b)])]
        if np.any((E.t >= a) & (E.t < b))
        else a
        for a, b in windows
    ]
    phase = _phase_of(E.t, windows, t_peaks, dt, period)
    sigma = (
        reference.noise.get("F", 0.0) / np.sqrt(max(reference.noise.get("n_cycles", 1), 1))
        if reference.noise
        else 0.0
    )
    # shares of the energy in excess of the noise (sum r^2 - n sigma^2): long phases of
    # pure noise (free flight) do not look like disagreement
    energy = {name: float(np.sum(r[phase == i] ** 2)) for i, name in enumerate(PHASES)}
    count = {name: int(np.sum(phase == i)) for i, name in enumerate(PHASES)}
    excess = {k: max(energy[k] - count[k] * sigma**2, 0.0) for k in PHASES}
    total = sum(excess.values()) or 1e-300
    phases = {}
    for name in PHASES:
        e, n = energy[name], count[name]
        ratio = e / (n * sigma**2) if sigma > 0 and n else None
        phases[name] = {
            "share": excess[name] / total,
            "ratio_to_noise": ratio,
            "n": n,
            "exceeds_noise": bool(
                ratio is None and e > 0 or (ratio is not None and ratio > _EXCEEDS)
            ),
        }
    out = {
        "phases": phases,
        "sigma": float(sigma),
        "rms": float(np.sqrt(np.mean(r**2))),
        "plane": None,
        "grid": None,
        "drift": None,
    }
    if measurement is None or evaluation.steady is None:
        return out
    out["drift"] = _drift(measurement, scenario.period, E.threshold)
    if not evaluation.steady.periodic:
        # no periodic orbit of the law to sample at the record's times (a law judged over
        # the record's span whose trajectory settles on none): the phases say where
        return out
    # the simulated orbit at the record's steady times: the (zeta, dzeta) plane and w1
    t0 = E.onset
    keep = measurement.t >= t0
    y, f_sim = simulated_at(
        scenario,
        model.law,
        evaluation.steady,
        measurement.t[keep],
        measurement.F[keep],
        time_offset=reference.time_offset,
        tolerances=tolerances,
    )
    zeta, dzeta = y[0] - y[2], y[1] - y[3]
    res = f_sim - measurement.F[keep]
    c = zeta > 0
    if c.sum() >= 16:
        ze = np.linspace(0, zeta[c].max(), 7)
        ve = np.linspace(min(dzeta[c].min(), 0.0), max(dzeta[c].max(), 1e-12), 7)
        iz = np.clip(np.digitize(zeta[c], ze) - 1, 0, 5)
        iv = np.clip(np.digitize(dzeta[c], ve) - 1, 0, 5)
        mean = np.full((6, 6), np.nan)
        for a in range(6):
            for b in range(6):
                m = (iz == a) & (iv == b)
                if m.any():
                    mean[a, b] = float(np.mean(res[c][m]))
        out["plane"] = {"zeta_edges": ze, "dzeta_edges": ve, "mean_residual": mean}
    ch = measurement.channels
    if "w1" in ch:
        w1 = ch["w1"][keep]
        from ..data.noise import estimate_noise

        rng_w = float(np.ptp(w1)) or 1.0
        d = w1 - y[0]
        noise = estimate_noise(w1, order=3)
        rms = float(np.sqrt(np.mean((d - d.mean()) ** 2)))
        out["grid"] = {
            "rms_relative": rms / rng_w,
            "ratio_to_noise": rms / noise if noise > 0 else None,
            "exceeds_noise": bool(noise > 0 and rms > 3 * noise),
        }
    return out
