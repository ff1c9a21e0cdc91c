"""Models the records cannot tell apart from the selected one: why (near-collinear terms,
force histories within the noise floor) and what record would separate them."""

import numpy as np


def _collinearity(est, samples, terms, others):
    """R^2 of each of ``terms``' columns regressed on ``others``' along the samples."""
    lib = est.library_
    idx = {t.name: i for i, t in enumerate(lib.terms)}
    theta = lib.transform(samples.X) * np.sqrt(samples.weight)[:, None]
    B = theta[:, [idx[t] for t in others]] if others else np.zeros((theta.shape[0], 0))
    r2 = {}
    for t in terms:
        y = theta[:, idx[t]]
        if B.shape[1]:
            res = y - B @ np.linalg.lstsq(B, y, rcond=None)[0]
        else:
            res = y
        tot = float(y @ y)
        r2[t] = 1.0 - float(res @ res) / tot if tot > 0 else 0.0
    return r2


def _separation(est, a, b):
    """How much two checked models' simulated force histories differ on the recorded
    orbits, and where their laws differ most beyond the recorded range (up to 2x the
    recorded penetration and impact velocity); both relative to the peak force."""
    d_in, peak = 0.0, 1e-300
    for ea, eb in zip(a.evaluations, b.evaluations, strict=True):
        fa, fb = ea.simulated.F, eb.simulated.F
        peak = max(peak, float(np.max(np.abs(fa))))
        d_in = max(d_in, float(np.max(np.abs(fa - fb))))
    box = est.box_
    zz, vv = np.meshgrid(np.linspace(0, 2 * box.zeta_max, 41), np.linspace(0, 2 * box.zd_max, 41))
    d = np.abs(a.law(zz, vv) - b.law(zz, vv)) / peak
    i = np.unravel_index(int(np.argmax(d)), d.shape)
    return d_in / peak, float(d[i]), float(zz[i]), float(vv[i])


def _equivalent(ranking, selected, est, samples, criterion):
    """Consistent models whose criterion is within the noise floor of the selected one's."""
    if not selected.consistent or not selected.criteria:
        return []
    best = selected.criteria[criterion]
    tol = selected.noise_floor.get(criterion, 0.0)
    out = []
    for m in ranking:
        if m is selected or not m.consistent or m.criteria[criterion] > best + tol:
            continue
        sel_t, m_t = set(selected.law.names), set(m.law.names)
        extra = sorted(m_t - sel_t) or sorted(sel_t - m_t)
        base = sorted(sel_t & m_t)
        r2 = _collinearity(est, samples, extra, base) if extra else {}
        near = {t: v for t, v in r2.items() if v > 0.95}
        d_in, d_out, z, v = _separation(est, selected, m)
        differ = (
            " vs ".join(" + ".join(sorted(x)) for x in (sel_t - m_t, m_t - sel_t) if x)
            or "the coefficients"
        )
        if near:
            reason = "near-collinear along the recorded orbit(s): " + ", ".join(
                f"{t} is explained by {' + '.join(base) or 'nothing'} to R^2 = {v:.3f}"
                for t, v in near.items()
            )
        else:
            reason = (
                f"{differ}: their simulated force histories differ by at most "
                f"{100 * d_in:.2g} % of the peak on the recorded orbit(s), within the "
                "noise floor"
            )
        separate = (
            f"their forces differ by {100 * d_out:.0f} % of the recorded peak at "
            f"zeta = {z:.3g} m, zd = {v:.3g} m/s (recorded up to "
            f"{est.box_.zeta_max:.3g} m, {est.box_.zd_max:.3g} m/s): a record with "
            "faster or deeper impacts (larger drive amplitude, another frequency) "
            "would separate them"
            if d_out > 2 * d_in
            else "they differ little anywhere near the recorded range: the data cannot "
            "separate them; prefer the simpler one"
        )
        out.append(
            {
                "terms": list(m.law.names),
                "coefficients": m.law.as_dict(),
                "criteria": m.criteria,
                "consistent": True,
                "reason": reason,
                "separate": separate,
            }
        )
    return out
