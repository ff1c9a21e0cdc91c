"""Figures of Ueda's oscillators (matplotlib Figures, no pyplot): the attractor (the
paper's Figs. 1-2: stroboscopic points, and a trajectory in the (x, x') plane), the regime
chart, the basins and the verification of a discovered equation (record's strobe points vs
the model's).

Each function writes PNG and PDF and returns the paths.
"""

import numpy as np
from matplotlib.colors import ListedColormap

from .._mpl import PRINT_WIDTH, colormap, save, subplots

__all__ = ["attractor_figure", "chart_figure", "basins_figure", "discover_figure"]

_KIND_COLORS = ("#9ecae1", "#a1d99b", "#fdd0a2", "#e6550d")  # P1, Pn, beat, chaotic
_KIND_LABELS = ("synchronisation (P1)", "subharmonic (Pn)", "beat (quasi-periodic)", "chaos")


_save = save


def _term_math(name):
    r"""A library term (``x^2 x'``, ``1``) as mathtext: ``$x^{2}\,\dot{x}$``."""
    from discovery.ueda.polynomial import MONOMIALS, TERMS

    if name not in TERMS:
        return str(name).replace("$", r"\$")
    i, j = MONOMIALS[TERMS.index(name)]
    parts = ([("x" if i == 1 else f"x^{{{i}}}")] if i else []) + (
        [(r"\dot{x}" if j == 1 else rf"\dot{{x}}^{{{j}}}")] if j else []
    )
    return "$" + (r"\,".join(parts) or "1") + "$"


def _carets(text):
    """Text with its exponents (``x^2``) raised as mathtext, the rest as it is."""
    import re

    return re.sub(r"\^(\d+)", r"$^{\1}$", str(text).replace("$", r"\$"))


def _sci(v):
    from reports.lawtex import sci

    return sci(v, 4)


def _equation_math(model):
    """``x'' = ...`` of a discovered model as mathtext, coefficients to 4 digits."""
    parts = []
    for k, v in model.terms.items():
        sym = "" if k == "1" else _term_math(k).strip("$")
        parts.append(("-" if v < 0 else "+") + rf" {_sci(abs(v))}\,{sym}")
    f = model.forcing
    parts.append(("-" if f < 0 else "+") + rf" {_sci(abs(f))}\,B\cos\nu t")
    rhs = " ".join(parts)
    return r"$\ddot{x} = " + (rhs[2:] if rhs.startswith("+ ") else rhs) + "$"


def attractor_figure(att, stem):
    """(a) the stroboscopic points ``(x, x')`` at ``t = 2 pi k / nu``; (b) a stretch of
    trajectory in the ``(x, x')`` plane with the strobe points on it."""
    s = att.system
    fig, axes = subplots(1, 2, figsize=(PRINT_WIDTH, 3.4), layout="constrained")
    ax = axes[0]
    ax.plot(att.strobe[:, 0], att.strobe[:, 1], ".", ms=1.2, color="k")
    ax.set_xlabel("x")
    ax.set_ylabel("x'")
    L = att.lyapunov
    ax.set_title(
        f"(a) stroboscopic points ({att.n_points}), {att.regime.regime}\n"
        rf"$\lambda_1$ = {L.value:.4f} $\pm$ {L.stderr:.4f}, $\lambda_2$ = {L.second:.4f}",
        fontsize=8,
    )
    ax = axes[1]
    ax.plot(att.x, att.v, lw=0.5, color="tab:blue")
    k = min(att.n_points, 30)
    ax.plot(
        att.strobe[-k:, 0], att.strobe[-k:, 1], ".", ms=4, color="tab:red", label="strobe points"
    )
    ax.set_xlabel("x")
    ax.set_ylabel("x'")
    ax.legend(loc="upper right", fontsize=8)
    ax.set_title(
        f"(b) trajectory in the (x, x') plane, {att.t[-1] - att.t[0]:.0f} time units", fontsize=9
    )
    pars = (
        rf"$\mu$ = {s.mu:g}, $\gamma$ = {s.gamma:g}, B = {s.B:g}, $\nu$ = {s.nu:g}"
        if s.model == "negres"
        else rf"k = {s.k:g}, B = {s.B:g}, $\nu$ = {s.nu:g}"
    )
    fig.suptitle(f"{s.model}: {_carets(s.equation)};  {pars}", fontsize=8)
    for a in axes:
        a.grid(alpha=0.3)
    return _save(fig, stem)


def chart_figure(ch, stem):
    """Regions over ``(nu, B)`` (synchronisation, subharmonic, beat, chaos) with the
    boundaries between regions drawn (the bifurcation sets, to the grid's resolution),
    the periods of the larger subharmonic regions written in them, and, for a chart swept
    in both directions, the points where the two sweeps ended on different attractors
    (coexisting attractors: hysteresis) marked ``x``."""
    kind = np.where(ch.kind < 0, np.nan, ch.kind.astype(float))
    fig, ax = subplots(figsize=(PRINT_WIDTH, 5.2), layout="constrained")
    nu, B = ch.nu, ch.B

    def edges(a):
        if a.size == 1:
            return np.array([a[0] - 0.5, a[0] + 0.5])
        m = 0.5 * (a[1:] + a[:-1])
        return np.concatenate([[a[0] - (m[0] - a[0])], m, [a[-1] + (a[-1] - m[-1])]])

    en, eb = edges(nu), edges(B)
    ax.pcolormesh(
        en, eb, kind, cmap=ListedColormap(_KIND_COLORS), vmin=-0.5, vmax=3.5, shading="flat"
    )
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
    # periods: in every subharmonic cell on a coarse grid, else once per larger region (at
    # its cell nearest the median); bold, outlined in white, to read on any colour
    from matplotlib import patheffects

    outline = [patheffects.withStroke(linewidth=2.2, foreground="white")]
    coarse = ch.kind.size <= 31 * 31
    least = 1 if coarse else max(3, int(0.002 * ch.kind.size))
    size = 9 if ch.kind.size <= 15 * 15 else (7 if coarse else 8)
    for n in np.unique(ch.period[ch.period > 1]):
        cells = np.argwhere(ch.period == n)
        if len(cells) < least:
            continue
        if not coarse:
            med = np.median(cells, axis=0)
            cells = cells[[np.argmin(((cells - med) ** 2).sum(axis=1))]]
        for i, j in cells:
            ax.text(
                nu[j],
                B[i],
                f"P{int(n)}",
                fontsize=size,
                fontweight="bold",
                ha="center",
                va="center",
                color="#08306b",
                path_effects=outline,
            )
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    fr = ch.fractions()
    handles = [
        Patch(color=c, label=f"{lbl} {100 * fr[k]:.0f} %")
        for c, lbl, k in zip(
            _KIND_COLORS, _KIND_LABELS, ("P1", "Pn", "beat", "chaotic"), strict=True
        )
    ]
    coex = getattr(ch, "coexisting", None)
    if coex is not None:
        ii, jj = np.nonzero(coex)
        size = float(np.clip(2500.0 / max(nu.size, B.size) ** 1.5, 1.0, 30.0))
        ax.scatter(nu[jj], B[ii], s=size, marker="x", c="k", linewidths=0.5)
        handles.append(
            Line2D(
                [],
                [],
                ls="",
                marker="x",
                color="k",
                label=f"coexisting: the sweeps up and down in nu differ "
                f"({100 * coex.mean():.1f} %)",
            )
        )
    ax.legend(handles=handles, loc="upper left", fontsize=8, framealpha=0.9)
    ax.set_xlabel("nu (forcing frequency)")
    ax.set_ylabel("B (forcing amplitude)")
    s = ch.system
    sweep = "sweeps up and down in nu (colours: up)" if coex is not None else "sweep up in nu"
    maxp = ch.settings.get("max_period", 8)
    ax.set_title(
        f"{s.model}: regimes over (nu, B), {nu.size}x{B.size}, {sweep}, "
        f"{ch.seconds:.0f} s on {ch.workers} processes\n"
        f"black lines: boundaries between regimes (or periods), to the grid's "
        f"resolution; numbers: periods (up to {maxp})",
        fontsize=8,
    )
    ax.set_xlim(en[0], en[-1])
    ax.set_ylim(eb[0], eb[-1])
    return _save(fig, stem)


def basins_figure(bas, stem):
    """The grid of initial states coloured by the attractor each reaches, beside the
    attractors' strobe points."""
    fig, axes = subplots(1, 2, figsize=(PRINT_WIDTH, 3.4), layout="constrained")
    n = len(bas.attractors)
    cmap = colormap("tab10")
    ax = axes[0]
    ax.pcolormesh(
        bas.x0,
        bas.v0,
        bas.label,
        cmap=ListedColormap([cmap(k) for k in range(n)]),
        vmin=-0.5,
        vmax=n - 0.5,
        shading="nearest",
    )
    ax.set_xlabel("x(0)")
    ax.set_ylabel("x'(0)")
    ax.set_title(f"(a) basins on a {bas.x0.size}x{bas.v0.size} grid", fontsize=8)
    ax = axes[1]
    for k, a in enumerate(bas.attractors):
        p = np.asarray(a["points"])
        ax.plot(
            p[:, 0],
            p[:, 1],
            "o" if len(np.unique(p.round(6), axis=0)) < 10 else ".",
            ms=5 if len(p) < 10 else 1.5,
            color=cmap(k),
            label=f"{a['regime']} ({100 * a['fraction']:.0f} %)",
        )
    ax.legend(fontsize=8)
    ax.set_xlabel("x")
    ax.set_ylabel("x'")
    ax.set_title("(b) the attractors' strobe points", fontsize=8)
    return _save(fig, stem)


def _strobe_panel(ax, ver):
    """(a) The record's stroboscopic points over the model's."""
    ms, rs = ver.model_strobe, ver.record_strobe
    if len(ms):
        ax.plot(
            ms[:, 0],
            ms[:, 1],
            ".",
            ms=1.5,
            color="tab:orange",
            alpha=0.6,
            label=f"discovered model ({len(ms)}, {ver.regime_model})",
        )
    ax.plot(
        rs[:, 0], rs[:, 1], ".", ms=4, color="k", label=f"record ({len(rs)}, {ver.regime_record})"
    )
    ax.set_xlabel("x")
    ax.set_ylabel("x'")
    ax.legend(loc="upper right", fontsize=8)
    L = ver.lyapunov
    lyap = (
        rf"model $\lambda_1$ = {L['value']:.4f} $\pm$ {L['stderr']:.4f}"
        if L
        else f"model diverged: {ver.diverged}"
    )
    ax.set_title(f"(a) stroboscopic points at $t = 2\\pi k / \\nu$\n{lyap}", fontsize=8)
    ax.grid(alpha=0.3)


def _coefficient_panel(ax, disc):
    """(b) The coefficients with their standard errors (bars: 2 SE)."""
    names = list(disc.coefficients)
    c = np.array([disc.coefficients[k] for k in names])
    se = np.array([disc.standard_errors[k] for k in names])
    y = np.arange(len(names))
    ax.barh(y, c, xerr=2 * se, color="tab:blue", alpha=0.7, capsize=3)
    ax.set_yticks(y, [_term_math(k) for k in names], fontsize=8)
    span = float(np.max(np.abs(c))) if len(c) else 1.0
    for yi, ci, si in zip(y, c, se, strict=True):  # the value beside its bar, inside the axes
        ax.text(
            0.02 * span if ci < 0 else -0.02 * span,
            yi,
            rf"{ci:.4g} $\pm$ {si:.2g}",
            ha="left" if ci < 0 else "right",
            va="center",
            fontsize=7,
        )
    ax.set_xlim(
        -1.15 * span if np.any(c < 0) else -0.6 * span, 1.15 * span if np.any(c > 0) else 0.6 * span
    )
    ax.axvline(0, color="k", lw=0.5)
    ax.set_title(
        "(b) coefficients of $\\ddot{x}$ = ...\n(error bars: 2 SE, block bootstrap)", fontsize=9
    )
    ax.grid(alpha=0.3, axis="x")


def _distance_panel(ax, ver):
    """(c) The energy distance against its noise floor."""
    hi = max(
        ver.floor_q95 * 1.5, ver.energy_distance * 1.1 if np.isfinite(ver.energy_distance) else 0.0
    )
    hi = hi if np.isfinite(hi) and hi > 0 else 1.0
    if ver.floor_samples is not None and len(ver.floor_samples):
        ax.hist(
            ver.floor_samples,
            bins=30,
            range=(0, hi),
            color="tab:green",
            alpha=0.4,
            label="floor: record half vs half",
        )
        ax.hist(
            ver.test_samples,
            bins=30,
            range=(0, hi),
            color="tab:red",
            alpha=0.4,
            label="record half vs model",
        )
    ax.axvline(
        ver.floor_q95, color="tab:green", ls="--", label=f"noise floor q95 {ver.floor_q95:.3g}"
    )
    ax.axvline(
        ver.floor_median,
        color="tab:green",
        lw=0.8,
        label=f"noise floor median {ver.floor_median:.3g}",
    )
    if np.isfinite(ver.energy_distance):
        ax.axvline(
            ver.energy_distance,
            color="tab:red",
            lw=2,
            label=f"record vs model {ver.energy_distance:.3g}",
        )
    ax.set_xlim(0, hi)
    ax.set_ylabel("resamples")
    ax.legend(fontsize=7, loc="upper right", framealpha=0.8)
    ax.set_xlabel("energy distance of strobe points\n(scaled by the record's sd)", fontsize=8)
    verdict = "consistent" if ver.consistent else "INCONSISTENT"
    ax.set_title(
        f"(c) {verdict}\n(rule: median distance <= floor q95,\nand the same regime)", fontsize=8
    )


def discover_figure(disc, ver, stem):
    """(a) the record's stroboscopic points over the discovered model's; (b) the
    coefficients with their standard errors (bars: 2 SE); (c) the energy distance
    against its noise floor (random halves of the record)."""
    from matplotlib.figure import Figure

    from .._mpl import PRINT_WIDTH, print_sizes

    with print_sizes():  # drawn at the width it is printed: its text 7 to 8 pt on paper
        fig = Figure(figsize=(PRINT_WIDTH, 6.6), layout="constrained")
        axd = fig.subplot_mosaic([["a", "a"], ["b", "c"]], height_ratios=[1.1, 1])
        _strobe_panel(axd["a"], ver)
        _coefficient_panel(axd["b"], disc)
        _distance_panel(axd["c"], ver)
        fig.suptitle(
            f"discovered: {_equation_math(disc.model)};  $B$ = {disc.model.B:g}, "
            f"$\\nu$ = {disc.model.nu:g}",
            fontsize=8,
        )
        return _save(fig, stem)
