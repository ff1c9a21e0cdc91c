"""Figures of a fit (``vidi fit``): the measured impulses against the ranked models' forces,
the force surface of the selected law, and the fit's rounds."""

import numpy as np

from .._mpl import PRINT_WIDTH, print_sizes, save, subplots
from .figure_parts import contact_view, force_unit, law_math, plain, terms_math

__all__ = ["fit_impulse_figure", "fit_surface_figure", "fit_loop_figure"]

_save = save


def fit_impulse_figure(result, impulses, stem, n_models=3):
    """Each record's measured impulse against the simulated ones of the best-ranked models,
    one panel per record, each re-based on its contact.

    Parameters
    ----------
    result : DiscoveryResult
    impulses : list of (label, Impulse)
        Labels of the models to draw (their simulated impulses against the first record);
        the other records' come from each model's evaluations.
    stem : str
    """
    refs = [ref for _, ref in result.references] or [None]  # (scenario, Reference) pairs
    measured = [r.impulse if r is not None else result.measured for r in refs]
    models = [m for m in result.ranking if m.evaluations][:n_models]
    labels = [lab for lab, _ in impulses][: len(models)]
    # one panel per record, two side by side; drawn no taller than the report prints a
    # figure (0.55 of the text height), so its text is printed at the size it is drawn
    n = len(measured)
    ncols = 1 if n == 1 else 2
    nrows = -(-n // ncols)
    with print_sizes():
        fig, axes = subplots(
            nrows,
            ncols,
            figsize=(PRINT_WIDTH, min(4.8, 1.0 + 2.3 * nrows)),
            squeeze=False,
            layout="constrained",
        )
        sc, unit = force_unit(max(E.peak for E in measured))
        for r, (E, ax) in enumerate(zip(measured, axes.flat, strict=False)):
            _impulse_panel(ax, E, models, labels, r, sc=sc)
            ax.set_ylabel(f"contact force [{unit}]")
            name = getattr(refs[r], "source", None) or f"record {r + 1}"
            ax.set_title(
                f"record {r + 1}: {plain(name)}"
                if n > 1
                else "Measured and simulated contact force of the best models"
            )
            if r >= n - ncols:
                ax.set_xlabel("time since the start of the contact [ms]")
        for ax in list(axes.flat)[n:]:
            ax.axis("off")
        # the same models in every panel: one legend, in the first
        axes.flat[0].legend(loc="best", framealpha=0.8)
        return _save(fig, stem)


def _impulse_panel(ax, E, models, labels, r, *, sc):
    """Record ``r``'s measured impulse ``E`` and the models' simulated ones, re-based on its
    contact."""
    sims = [
        (
            labels[k] if k < len(labels) else ", ".join(m.law.names),
            m.evaluations[r].simulated if r < len(m.evaluations) else None,
        )
        for k, m in enumerate(models)
    ]
    forces = [E.F] + [np.interp(E.t, imp.t, imp.F) for _, imp in sims if imp is not None]
    tr, o, (lo, hi) = contact_view(
        E.t, E.duration, *forces, threshold=max(0.02 * E.peak, 5.0 * E.noise)
    )
    ax.plot(
        tr[o] * 1e3, E.F[o] * sc, "k-", lw=2.5, alpha=0.6, label=f"measured ({E.n_cycles} cycles)"
    )
    styles = ["-", "--", ":"]
    for k, (label, imp) in enumerate(sims):
        if imp is None:
            continue
        f = np.interp(E.t, imp.t, imp.F)
        ax.plot(
            tr[o] * 1e3, f[o] * sc, styles[k % 3], lw=1.4, color=f"C{k}", label=terms_math(label)
        )
    ax.set_xlim(lo * 1e3, hi * 1e3)


def fit_surface_figure(result, stem):
    """The selected law over the box in (zeta, zd), with the contact samples."""
    est, s = result.estimator, result.samples
    Z, V = est.box_.zeta_max, est.box_.zd_max
    zz, vv = np.meshgrid(np.linspace(0, Z, 200), np.linspace(0, V, 200))
    F = result.selected.law(zz, vv)
    fig, ax = subplots(figsize=(PRINT_WIDTH, 4.6))
    cs = ax.contourf(zz * 1e3, vv, F / 1e3, levels=25, cmap="magma")
    fig.colorbar(cs, ax=ax, label="F [kN]")
    step = max(1, len(s) // 4000)
    ax.plot(
        s.zeta[::step] * 1e3,
        np.maximum(s.dzeta[::step], 0),
        ".",
        ms=1.5,
        color="c",
        alpha=0.6,
        label="contact samples",
    )
    ax.set_xlabel(r"penetration $\zeta$ [mm]")
    ax.set_ylabel(r"loading velocity $\dot{\zeta}_{+} = \max(\dot{\zeta}, 0)$ [m/s]")
    ax.set_title(law_math(result.selected.law), fontsize=8)
    ax.legend(loc="best", fontsize=7, framealpha=0.8)
    fig.set_layout_engine("tight")  # laid out once, by save()
    return _save(fig, stem)


def fit_loop_figure(result, stem, max_impacts=3):
    """Loading / unloading loops F(zeta) of a few impacts (the paper's Fig. 2a): the
    measured samples, and the model's force at them, loading (solid) and unloading
    (dashed) drawn apart. The impacts shown are among the deeper ones, so every branch
    is visible."""
    s = result.samples
    with print_sizes():
        fig, ax = subplots(figsize=(PRINT_WIDTH, 4.4))
        impacts = np.unique(s.impact)
        depth = np.array([np.max(s.zeta[s.impact == i]) for i in impacts])
        deep = impacts[depth >= 0.5 * depth.max()] if impacts.size else impacts
        pick = deep[np.linspace(0, deep.size - 1, min(max_impacts, deep.size)).astype(int)]
        for k, imp in enumerate(pick):
            m = s.impact == imp
            z, dz = s.zeta[m], s.dzeta[m]
            ax.plot(
                z * 1e3, s.F[m] / 1e3, ".", ms=3, color=f"C{k}", alpha=0.5,
                label=f"measured, impact {imp}",
            )  # fmt: skip
            model = result.selected.law(z, dz) / 1e3
            for branch, style in ((dz > 0, "-"), (dz <= 0, "--")):
                mm = np.where(branch, model, np.nan)
                ax.plot(
                    z * 1e3,
                    mm,
                    style,
                    color=f"C{k}",
                    lw=1.6,
                    zorder=3,
                    label=f"model, impact {imp}" if style == "-" else None,
                )  # fmt: skip  (above every impact's samples: the unloading branch near 0)
        ax.plot([], [], "k-", lw=1.6, label="model loading (solid)")
        ax.plot([], [], "k--", lw=1.6, label="model unloading (dashed)")
        ax.set_xlabel(r"penetration $\zeta$ [mm]")
        ax.set_ylabel("contact force [kN]")
        ax.set_title("Loading and unloading branches, measured and modelled")
        ax.legend(loc="best", framealpha=0.8)
        # laid out once, by save(), its padding in these sizes' font
        fig.set_layout_engine("tight")
        return _save(fig, stem)
