"""The map of ``advise``: the smallest pairwise separation over drive amplitude x frequency."""

import numpy as np
from matplotlib.colors import LogNorm

from .._mpl import PRINT_WIDTH, print_sizes, save, subplots

__all__ = ["advise_figure"]


def advise_figure(result, stem):
    """Every evaluated (A, f) coloured by its smallest pair separation (the best over the
    moulding masses when those vary; 1 is where the verdict starts to reject), the points
    outside the safe region and those without a usable prediction marked, points whose
    best pair differs by regime ringed, and the advised point starred.

    Parameters
    ----------
    result : AdviseResult
    stem : str
        Output path without extension (``stem.png`` and ``stem.pdf`` are written).

    Returns
    -------
    list of str
        The two paths.
    """
    m = result.map()
    A, f, s = m["amplitude"], m["frequency"], m["smallest"]
    ok = np.isfinite(s)
    with print_sizes():
        fig, ax = subplots(figsize=(PRINT_WIDTH, 4.2), layout="constrained")
        if ok.any():
            vals = np.clip(s[ok], 1e-2, None)
            lo, hi = float(vals.min()), float(vals.max())
            norm = LogNorm(vmin=min(lo, 0.5), vmax=max(hi, 2.0))
            sc = ax.scatter(A[ok], f[ok], c=vals, norm=norm, cmap="viridis", s=90, marker="s")
            fig.colorbar(sc, ax=ax, label="smallest pair separation (1 = verdict's limit)")
            if ok.sum() >= 4 and np.ptp(A[ok]) > 0 and np.ptp(f[ok]) > 0 and lo < 1 < hi:
                try:
                    ax.tricontour(A[ok], f[ok], vals, levels=[1.0], colors="w", linewidths=1.2)
                except (ValueError, RuntimeError):  # a degenerate triangulation: no line
                    pass
        reg = m["regime"] & ok
        if reg.any():
            ax.scatter(A[reg], f[reg], s=220, facecolors="none", edgecolors="tab:orange", lw=1.4)
        phys = m.get("physics", np.zeros_like(ok)) & ~m["excluded"]
        if phys.any():
            # separated on physics: the separation is infinite, drawn as a square of its own
            inf = phys & ~ok
            ax.scatter(A[inf], f[inf], s=90, marker="s", c="w", edgecolors="tab:red", lw=1.2)
            ax.scatter(A[phys], f[phys], s=320, facecolors="none", edgecolors="tab:red", lw=1.4)
        un = m["unsafe"]
        if un.any():
            ax.scatter(A[un], f[un], marker="x", c="tab:red", s=60)
        ex = m["excluded"] & ~un
        if ex.any():
            ax.scatter(A[ex], f[ex], marker="o", c="0.6", s=40)
        b = result.best
        if b is not None:
            ax.plot(b.amplitude, b.frequency, "*", ms=18, mfc="tab:red", mec="k")
        ax.set_xlabel("drive amplitude A [N]")
        ax.set_ylabel("drive frequency f [Hz]")
        ax.ticklabel_format(axis="x", style="sci", scilimits=(-3, 4), useMathText=True)
        ka, kf = result.knobs.amplitude, result.knobs.frequency
        pa, pf = 0.04 * max(ka[1] - ka[0], abs(ka[0]) * 0.05), 0.04 * max(kf[1] - kf[0], 0.5)
        ax.set_xlim(ka[0] - pa, ka[1] + pa)
        ax.set_ylim(kf[0] - pf, kf[1] + pf)
        ax.set_title(_legend_text(reg.any(), un.any(), ex.any(), b is not None, phys.any()))
        return save(fig, stem)


def _legend_text(regime, unsafe, excluded, best, physics=False):
    parts = []
    if best:
        parts.append("star: advised")
    if regime:
        parts.append("ring: a pair differs by regime")
    if physics:
        parts.append("red ring: a candidate breaks condition (6) there")
    if unsafe:
        parts.append("x: outside the safe region")
    if excluded:
        parts.append("grey: a candidate has no periodic orbit with contact")
    return "; ".join(parts) or "smallest pair separation"
