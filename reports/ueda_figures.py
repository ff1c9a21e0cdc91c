"""Figures of Ueda's oscillators (matplotlib, Agg): the attractor (the paper's Figs. 1-2:
stroboscopic points, and a trajectory in the (x, x') plane) and the regime chart.

Each function writes PNG and PDF and returns the paths.
"""

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.colors import ListedColormap  # noqa: E402

__all__ = ["attractor_figure", "chart_figure", "basins_figure"]

_KIND_COLORS = ("#9ecae1", "#a1d99b", "#fdd0a2", "#e6550d")  # P1, Pn, beat, chaotic
_KIND_LABELS = ("synchronisation (P1)", "subharmonic (Pn)", "beat (quasi-periodic)", "chaos")


def _save(fig, stem):
    paths = [f"{stem}.png", f"{stem}.pdf"]
    fig.savefig(paths[0], dpi=130, bbox_inches="tight")
    fig.savefig(paths[1], bbox_inches="tight")
    plt.close(fig)
    return paths


def attractor_figure(att, stem):
    """(a) the stroboscopic points ``(x, x')`` at ``t = 2 pi k / nu``; (b) a stretch of
    trajectory in the ``(x, x')`` plane with the strobe points on it."""
    s = att.system
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.8))
    ax = axes[0]
    ax.plot(att.strobe[:, 0], att.strobe[:, 1], ".", ms=1.2, color="k")
    ax.set_xlabel("x")
    ax.set_ylabel("x'")
    L = att.lyapunov
    ax.set_title(f"(a) stroboscopic points ({att.n_points}), {att.regime.regime}\n"
                 f"lambda1 = {L.value:.4f} +- {L.stderr:.4f}, lambda2 = {L.second:.4f}",
                 fontsize=9)
    ax = axes[1]
    ax.plot(att.x, att.v, lw=0.5, color="tab:blue")
    k = min(att.n_points, 30)
    ax.plot(att.strobe[-k:, 0], att.strobe[-k:, 1], ".", ms=4, color="tab:red",
            label="strobe points")
    ax.set_xlabel("x")
    ax.set_ylabel("x'")
    ax.legend(loc="upper right", fontsize=8)
    ax.set_title(f"(b) trajectory in the (x, x') plane, {att.t[-1] - att.t[0]:.0f} time units",
                 fontsize=9)
    pars = (f"mu = {s.mu:g}, gamma = {s.gamma:g}, B = {s.B:g}, nu = {s.nu:g}"
            if s.model == "negres" else f"k = {s.k:g}, B = {s.B:g}, nu = {s.nu:g}")
    fig.suptitle(f"{s.model}: {s.equation};  {pars}", fontsize=10)
    for a in axes:
        a.grid(alpha=0.3)
    return _save(fig, stem)


def chart_figure(ch, stem):
    """Regions over ``(nu, B)`` (synchronisation, subharmonic, beat, chaos) with the
    boundaries between regions drawn (the bifurcation sets, to the grid's resolution)."""
    kind = np.where(ch.kind < 0, np.nan, ch.kind.astype(float))
    fig, ax = plt.subplots(figsize=(8, 6.4))
    nu, B = ch.nu, ch.B

    def edges(a):
        if a.size == 1:
            return np.array([a[0] - 0.5, a[0] + 0.5])
        m = 0.5 * (a[1:] + a[:-1])
        return np.concatenate([[a[0] - (m[0] - a[0])], m, [a[-1] + (a[-1] - m[-1])]])

    en, eb = edges(nu), edges(B)
    ax.pcolormesh(en, eb, kind, cmap=ListedColormap(_KIND_COLORS), vmin=-0.5, vmax=3.5,
                  shading="flat")
    # boundaries: cell edges between different regimes (period changes included)
    lab = np.where(ch.kind < 0, -1, ch.kind * 100 + ch.period)
    segs = []
    for i in range(lab.shape[0]):
        for j in range(lab.shape[1] - 1):
            if lab[i, j] != lab[i, j + 1]:
                segs.append([(en[j + 1], eb[i]), (en[j + 1], eb[i + 1])])
    for i in range(lab.shape[0] - 1):
        for j in range(lab.shape[1]):
            if lab[i, j] != lab[i + 1, j]:
                segs.append([(en[j], eb[i + 1]), (en[j + 1], eb[i + 1])])
    if segs:
        from matplotlib.collections import LineCollection

        ax.add_collection(LineCollection(segs, colors="k", linewidths=0.4))
    from matplotlib.patches import Patch

    fr = ch.fractions()
    handles = [Patch(color=c, label=f"{lbl} {100 * fr[k]:.0f} %")
               for c, lbl, k in zip(_KIND_COLORS, _KIND_LABELS, ("P1", "Pn", "beat", "chaotic"),
                                    strict=True)]
    ax.legend(handles=handles, loc="upper left", fontsize=8, framealpha=0.9)
    ax.set_xlabel("nu (forcing frequency)")
    ax.set_ylabel("B (forcing amplitude)")
    s = ch.system
    ax.set_title(f"{s.model}: regimes over (nu, B), {nu.size}x{B.size}, "
                 f"{ch.seconds:.0f} s on {ch.workers} processes\n"
                 "black lines: boundaries between regimes (or periods), to the grid's "
                 "resolution", fontsize=9)
    ax.set_xlim(en[0], en[-1])
    ax.set_ylim(eb[0], eb[-1])
    return _save(fig, stem)


def basins_figure(bas, stem):
    """The grid of initial states coloured by the attractor each reaches, beside the
    attractors' strobe points."""
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.8))
    n = len(bas.attractors)
    cmap = plt.get_cmap("tab10")
    ax = axes[0]
    ax.pcolormesh(bas.x0, bas.v0, bas.label, cmap=ListedColormap([cmap(k) for k in range(n)]),
                  vmin=-0.5, vmax=n - 0.5, shading="nearest")
    ax.set_xlabel("x(0)")
    ax.set_ylabel("x'(0)")
    ax.set_title(f"(a) basins on a {bas.x0.size}x{bas.v0.size} grid", fontsize=9)
    ax = axes[1]
    for k, a in enumerate(bas.attractors):
        p = np.asarray(a["points"])
        ax.plot(p[:, 0], p[:, 1], "o" if len(np.unique(p.round(6), axis=0)) < 10 else ".",
                ms=5 if len(p) < 10 else 1.5, color=cmap(k),
                label=f"{a['regime']} ({100 * a['fraction']:.0f} %)")
    ax.legend(fontsize=8)
    ax.set_xlabel("x")
    ax.set_ylabel("x'")
    ax.set_title("(b) the attractors' strobe points", fontsize=9)
    return _save(fig, stem)
