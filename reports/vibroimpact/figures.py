"""Figures as pure functions of result objects (matplotlib Figures, no pyplot).

Each function writes the same figure as PNG and PDF and returns the paths.

Landscapes and identifications are drawn here; fits in :mod:`.fit_figures`, verifications
in :mod:`.verify_figures`, the missing-effect workflow in :mod:`.explain_figures`, with the
labels and views they share in :mod:`.figure_parts` (all importable from here).
"""

import numpy as np

from .._mpl import PRINT_WIDTH, colormap, print_sizes, save, subplots
from .explain_figures import explain_figure
from .figure_parts import (
    coefficient_label,
    contact_view,
    force_unit,
    law_math,
    plain,
    term_unit,
    terms_math,
)
from .fit_figures import fit_impulse_figure, fit_loop_figure, fit_surface_figure
from .verify_figures import loops_figure, verify_figure

__all__ = [
    "landscape_figure",
    "identification_figure",
    "verify_figure",
    "loops_figure",
    "explain_figure",
    "fit_impulse_figure",
    "fit_surface_figure",
    "fit_loop_figure",
    "coefficient_label",
    "contact_view",
    "force_unit",
    "law_math",
    "plain",
    "term_unit",
    "terms_math",
]

_ORDER = ("I1", "I2", "I3", "I4", "I0")
_save = save


def _landscape_marks(reg, ref_reg):
    """``[(mask, marker style, legend label), ...]`` of the points with another regime, no
    periodic orbit, no contact or a failed simulation (the non-empty ones)."""
    physical = ("no-contact", "nonperiodic", "failed")
    marks = [
        (
            (reg != ref_reg) & ~np.isin(reg, physical),
            dict(ls="none", marker="x", color="r", ms=4),
            f"periodic, not {ref_reg}",
        ),
        (reg == "nonperiodic", dict(ls="none", marker="+", color="orange", ms=5), "nonperiodic"),
        (reg == "no-contact", dict(ls="none", marker=".", color="0.6", ms=4), "no contact"),
        (
            reg == "failed",
            dict(ls="none", marker="s", mfc="none", mec="k", ms=4),
            "simulation failed",
        ),
    ]
    return [m for m in marks if m[0].any()]


def _landscape_contours(fig, ax, land, name):
    """Filled contours of criterion ``name`` with its minimum starred."""
    from matplotlib.ticker import MaxNLocator

    a0, a1 = land.axes
    v = land.values[name]
    ok = np.isfinite(v)
    if not ok.any():
        ax.text(
            0.5,
            0.5,
            "no periodic contact\nanywhere in this range",
            transform=ax.transAxes,
            ha="center",
            va="center",
        )
        return
    lo, hi = float(v[ok].min()), float(v[ok].max())
    levels = MaxNLocator(20).tick_values(lo, hi if hi > lo else lo + 1e-12)
    cs = ax.contourf(a0, a1, v.T, levels=levels, cmap="viridis")
    if hi > lo:
        ax.contour(a0, a1, v.T, levels=levels[::2], colors="k", linewidths=0.4)
    fig.colorbar(cs, ax=ax, label=f"{name} (dimensionless)")
    i, j = land.argmin(name)
    ax.plot(a0[i], a1[j], "w*", ms=10, mec="k")


def _landscape_info_lines(land, ref_reg, *, exact, floor, cons, truth, inside):
    """The text of the information panel."""
    import textwrap

    a0, a1 = land.axes
    info = getattr(land, "reference", None) or {}
    src = info.get("source", "")
    src = "the scenario's law (exact)" if src in ("law", "") else src
    lines = [
        "Criteria landscape",
        f"{a0.size} x {a1.size} points, {land.seconds:.1f} s on {land.workers} processes",
        f"reference: {src}"[:70],
        f"reference regime: {ref_reg}",
    ]
    if not exact and floor:
        lines.append("noise floor: " + ", ".join(f"{n} {floor[n]:.2g}" for n in _ORDER))
    counts = land.regime_counts() if hasattr(land, "regime_counts") else {}
    if counts:
        lines.append("regimes: " + ", ".join(f"{k} {v}" for k, v in counts.items()))
    if cons is not None:
        lines.append(f"consistent with the reference at {int(cons.sum())} point(s)")
    fails = getattr(land, "failures", (0, "", None))
    if fails[0]:
        lines.append(f"{fails[0]} simulation(s) failed, the first:")
        lines += ["  " + w for w in textwrap.wrap(fails[1], 62)[:4]]
    if truth is not None and not inside:
        lines.append("the reference law lies outside this range")
    return lines


def _landscape_legend(ax, inside, show_cons, marks):
    from matplotlib.lines import Line2D

    handles = [Line2D([], [], ls="none", marker="*", mfc="w", mec="k", ms=10, label="minimum")]
    if inside:
        handles.append(
            Line2D([], [], ls="none", marker="o", mfc="none", mec="r", ms=10, label="reference law")
        )
    if show_cons:
        handles.append(
            Line2D([], [], color="w", ls="--", lw=1.2, label="consistent region (boundary)")
        )
    handles += [Line2D([], [], label=label, **style) for _, style, label in marks]
    leg = ax.legend(handles=handles, loc="lower left", fontsize=8, facecolor="0.85")
    leg.get_frame().set_edgecolor("0.5")


def landscape_figure(land, stem, truth=None):
    """Contours of I1..I4 and I0 (the paper's Figs. 4-5), with the points that have no
    criteria or another regime marked, the consistent region outlined and the
    reference's noise floor.

    Parameters
    ----------
    land : Landscape
    stem : str
        Output path without extension.
    truth : (float, float), optional
        Reference coefficients, circled (when inside the grid).
    """
    a0, a1 = land.axes
    reg = np.asarray(land.regime, dtype=str)
    ref_reg = (getattr(land, "reference", None) or {}).get("regime", "P1")
    exact = (getattr(land, "reference", None) or {}).get("exact", True)
    floor = getattr(land, "noise_floor", None)
    cons = getattr(land, "consistent", None)
    marks = _landscape_marks(reg, ref_reg)
    inside = truth is not None and a0[0] <= truth[0] <= a0[-1] and a1[0] <= truth[1] <= a1[-1]
    show_cons = cons is not None and cons.sum() >= 2  # one point: hidden by the star
    with print_sizes():  # drawn at the width it is printed: its text 7 to 8 pt
        fig, axes = subplots(3, 2, figsize=(PRINT_WIDTH, 7.2))
        for ax, name in zip(axes.flat, _ORDER, strict=False):
            _landscape_contours(fig, ax, land, name)
            if show_cons:
                ax.contour(
                    a0,
                    a1,
                    cons.T.astype(float),
                    levels=[0.5],
                    colors="w",
                    linestyles="--",
                    linewidths=1.2,
                )
            for mask, style, _ in marks:
                ij = np.argwhere(mask)
                ax.plot(a0[ij[:, 0]], a1[ij[:, 1]], **style)
            if inside:
                ax.plot(*truth, "o", mfc="none", mec="r", ms=10, mew=1.5)
            ax.set_xlim(a0[0], a0[-1])
            ax.set_ylim(a1[0], a1[-1])
            ax.set_xlabel(coefficient_label(land.terms[0]))
            ax.set_ylabel(coefficient_label(land.terms[1]))
            ax.ticklabel_format(style="sci", scilimits=(-3, 4), useMathText=True)
            title = name if exact or not floor else f"{name} (noise floor {floor[name]:.3g})"
            ax.set_title(title)
        ax = axes.flat[5]
        ax.axis("off")
        lines = _landscape_info_lines(
            land, ref_reg, exact=exact, floor=floor, cons=cons, truth=truth, inside=inside
        )
        ax.text(0.0, 1.0, "\n".join(lines), va="top", fontsize=7, transform=ax.transAxes)
        _landscape_legend(ax, inside, show_cons, marks)
        fig.tight_layout()
        return _save(fig, stem)


def _mark_start(ax, start, names, path):
    """The start law given (``ForceLaw`` or dict) on the path's axes, joined dotted to the
    path's first point when the search began elsewhere (a cycle-by-cycle refit)."""
    given = start if isinstance(start, dict) else start.as_dict()
    s0 = [float(given[n]) for n in names[:2]]
    if not np.allclose(s0, path[0, :2]):
        ax.plot([s0[0], path[0, 0]], [s0[1], path[0, 1]], ":", color="r", lw=1)
    ax.plot(*s0, "s", mfc="none", mec="r", ms=9, mew=1.5, label="start (given)")


def identification_figure(result, measured, impulses, stem, *, land=None, start=None):
    """Identification path (Fig. 6), the criterion against the simulations spent, and F_N
    converging to F_E (Fig. 7).

    ``result.iterations`` lists every simulated law that was the best so far when it was
    simulated.  Those are not all optimiser steps: with ``least-squares`` most are
    finite-difference probes of the Jacobian (and the standard-error Jacobian can add one
    after the search).  So the history is drawn against the simulations spent, each new
    best marked, and nothing is counted as an iteration or an improvement.

    Parameters
    ----------
    result : IdentificationResult
    measured : Impulse
        ``F_E``.
    impulses : list of (label, Impulse)
        Simulated impulses of selected laws (e.g. the start, some of the best-so-far laws,
        the identified law).
    stem : str
    land : Landscape, optional
        Background contours of the identified criterion (two-term laws).
    start : ForceLaw or dict, optional
        The start law the search was given (the values the report lists): marked as the
        start.  The first best-so-far law is not it when the search first fitted the start
        cycle by cycle; without ``start`` no start is marked.
    """
    names = list(result.law.names)
    its = list(result.iterations)
    path = np.array([[it["coefficients"][n] for n in names] for it in its])
    two = len(names) >= 2 and path.size > 0
    from matplotlib.figure import Figure

    fig = Figure(figsize=(PRINT_WIDTH, 6.6 if two else 3.4), layout="constrained")
    if two:  # the path and the history side by side, the forces below at full width
        axd = fig.subplot_mosaic([["a", "b"], ["c", "c"]])
        axes = [axd["a"], axd["b"], axd["c"]]
    else:
        axes = list(fig.subplots(1, 2))
    crit = result.criterion
    # the identified law's value (result.value can belong to a standard-error probe)
    value = result.criteria.get(crit, result.value)
    if two:
        ax = axes[0]
        if land is not None and crit in land.values:
            a0, a1 = land.axes
            cs = ax.contourf(a0, a1, land.values[crit].T, levels=20, cmap="viridis")
            fig.colorbar(cs, ax=ax, label=f"{crit} (dimensionless)")
        ax.plot(
            path[:, 0],
            path[:, 1],
            "o-",
            color="w" if land is not None else "C0",
            mec="k",
            ms=3.5,
            lw=1,
            label="best law so far",
        )
        if start is not None:
            _mark_start(ax, start, names, path)
        final = result.law.as_dict()
        ax.plot(final[names[0]], final[names[1]], "r*", ms=13, mec="k", label="identified")
        ax.set_xlabel(coefficient_label(names[0]))
        ax.set_ylabel(coefficient_label(names[1]))
        ax.ticklabel_format(style="sci", scilimits=(-3, 4), useMathText=True)
        more = f" (first two of {len(names)} terms)" if len(names) > 2 else ""
        ax.set_title(f"{result.method}: path of the best law so far{more}", fontsize=8)
        ax.legend(fontsize=7, loc="best")
    ax = axes[1] if two else axes[0]
    if its:
        sims = np.array([it["n_simulations"] for it in its], dtype=float)
        vals = np.array([it["value"] for it in its], dtype=float)
        xs = np.append(sims, max(result.n_simulations, sims[-1]))
        ax.step(
            xs,
            np.append(vals, vals[-1]),
            where="post",
            color="C0",
            lw=1.2,
            label=f"best {crit} so far",
        )
        ax.plot(
            sims,
            vals,
            "o",
            color="C0",
            ms=3.5,
            label="new best (an optimiser step or a finite-difference probe)",
        )
        if np.all(vals > 0):
            ax.set_yscale("log")
        # the best value only falls: the upper right is clear of the curve
        ax.legend(fontsize=7, loc="upper right")
    ax.set_xlabel("simulations spent (steady states computed)")
    ax.set_ylabel(f"best {crit} so far (dimensionless)")
    # the search's value and the final check's (what the report's criteria table shows)
    # differ by the check's own evaluation: both are named where they do
    done = [ev.criteria[crit] for ev in result.checks if crit in (ev.criteria or {})]
    checked = float(np.mean(done)) if done else value
    both = f" in the search, {checked:.3g} in the final check" if done else ""
    ax.set_title(
        f"identified: {crit} = {value:.3g}{both}\n{result.n_simulations} simulations in all",
        fontsize=8,
    )
    ax1 = axes[-1]
    ax1.plot(measured.t * 1e3, measured.F / 1e6, "k-", lw=2.5, label=r"$F_E$ (measured)")
    for k, (label, imp) in enumerate(impulses):
        if imp is not None:
            ax1.plot(
                imp.t * 1e3,
                imp.F / 1e6,
                "-",
                lw=1,
                color=colormap("plasma")(k / max(1, len(impulses))),
                label=label,
            )
    end = measured.support[:, 1].max() if len(measured.support) else measured.duration
    ax1.set_xlim(-0.05 * end * 1e3, min(measured.duration, 1.4 * end) * 1e3)
    ax1.set_xlabel("time since onset t - t* [ms]")
    ax1.set_ylabel("contact force [MN]")
    ax1.set_title(
        f"$F_N$ converging to $F_E$ ({crit} = {checked:.3g} in the final check)", fontsize=8
    )
    ax1.legend(fontsize=7)
    return _save(fig, stem)
