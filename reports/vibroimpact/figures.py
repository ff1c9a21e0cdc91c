"""Figures as pure functions of result objects (matplotlib Figures, no pyplot).

Each function writes the same figure as PNG and PDF and returns the paths.

Landscapes and identifications are drawn here; fits in :mod:`.fit_figures`, verifications
in :mod:`.verify_figures`, the missing-effect workflow in :mod:`.explain_figures`, with the
labels and views they share in :mod:`.figure_parts` (all importable from here).
"""

import numpy as np

from .._mpl import PRINT_WIDTH, colormap, figure, print_sizes, save
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

_ORDER = ("I1", "I2", "I3", "I4", "I5", "I0")


def _landscape_criteria(land):
    """The criteria the landscape computed, in the paper's order: I1..I4, the motion's I5
    (a record with positions), I0."""
    return [n for n in _ORDER if n in land.values and np.any(np.isfinite(land.values[n]))] or [
        n for n in _ORDER if n in land.values
    ]


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


def _landscape_contours(fig, ax, land, name, axes):
    """Filled contours of criterion ``name`` over ``axes`` (the grid's, scaled) with its
    minimum starred."""
    from matplotlib.ticker import MaxNLocator

    a0, a1 = axes
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
    # the colour bar inside the panel's own cell (a bar the layout placed took its own
    # column's margin and stood apart from its panel)
    fig.colorbar(cs, cax=ax.inset_axes([1.04, 0.0, 0.07, 1.0]))
    i, j = land.argmin(name)
    ax.plot(a0[i], a1[j], "w*", ms=10, mec="k")


def _power_of_ten(values):
    """The power of ten an axis of ``values`` is drawn in (its largest magnitude's)."""
    big = float(np.max(np.abs(values))) if np.size(values) else 0.0
    return int(np.floor(np.log10(big))) if big > 0 and np.isfinite(big) else 0


def _scaled_label(name, power):
    """``coefficient of z`` over ``[10^8 N m^-1]``: the coefficient's axis label with the
    power of ten its values are drawn in."""
    scale = rf"$10^{{{power}}}$ " if power else ""
    return f"coefficient of {name}\n[{scale}{term_unit(name)}]"


def _landscape_info_lines(land, ref_reg, *, exact, floor, cons, truth, inside):
    """The text of the information panel."""
    import textwrap

    a0, a1 = land.axes
    info = getattr(land, "reference", None) or {}
    src = info.get("source", "")
    src = "the scenario's law (exact)" if src in ("law", "") else src
    lines = [
        "Criteria landscape (every criterion dimensionless)",
        f"{a0.size} x {a1.size} points, {land.seconds:.1f} s on {land.workers} processes",
        f"reference: {src}"[:70],
        f"reference regime: {ref_reg}",
    ]
    if not exact and floor:
        lines += textwrap.wrap(
            "noise floor: " + ", ".join(f"{n} {floor[n]:.2g}" for n in _ORDER if n in floor), 72
        )
    counts = land.regime_counts() if hasattr(land, "regime_counts") else {}
    if counts:
        lines.append("regimes: " + ", ".join(f"{k} {v}" for k, v in counts.items()))
    if cons is not None:
        lines.append(f"consistent with the reference at {int(cons.sum())} point(s)")
    fails = getattr(land, "failures", (0, "", None))
    if fails[0]:
        lines.append(f"{fails[0]} simulation(s) failed, the first:")
        lines += ["  " + w for w in textwrap.wrap(fails[1], 70)[:4]]
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
    leg = ax.legend(handles=handles, loc="upper right", facecolor="0.85")
    leg.get_frame().set_edgecolor("0.5")


def landscape_figure(land, stem, truth=None):
    """Contours of I1..I4, I5 (when the landscape computed it) and I0 (the paper's Figs.
    4-5), with the points that have no criteria or another regime marked, the consistent
    region outlined and the reference's noise floor; three panels a row, the run's
    information and the legend below them.

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
    ref = getattr(land, "reference", None) or {}
    ref_reg, exact = ref.get("regime", "P1"), ref.get("exact", True)
    floor = getattr(land, "noise_floor", None)
    cons = getattr(land, "consistent", None)
    marks = _landscape_marks(reg, ref_reg)
    inside = truth is not None and a0[0] <= truth[0] <= a0[-1] and a1[0] <= truth[1] <= a1[-1]
    show_cons = cons is not None and cons.sum() >= 2  # one point: hidden by the star
    names = _landscape_criteria(land)
    lines = _landscape_info_lines(
        land, ref_reg, exact=exact, floor=floor, cons=cons, truth=truth, inside=inside
    )
    rows = -(-len(names) // 3)
    cells = [names[3 * r : 3 * r + 3] for r in range(rows)]
    mosaic = [c + [f"empty{k}" for k in range(3 - len(c))] for c in cells]
    mosaic.append(["info", "info", "legend"])
    info_h = 0.12 * len(lines) + 0.2
    # the coefficients drawn in powers of ten named in the labels (no offset text to
    # collide with a label); a label where no panel is beside (y) or below (x)
    p0, p1 = _power_of_ten(a0), _power_of_ten(a1)
    s0, s1 = a0 / 10.0**p0, a1 / 10.0**p1
    mark = None if not inside else (truth[0] / 10.0**p0, truth[1] / 10.0**p1)
    with print_sizes():  # drawn at the width it is printed: its text 7 to 8 pt
        fig = figure(figsize=(PRINT_WIDTH, 2.1 * rows + info_h), layout="constrained")
        axd = fig.subplot_mosaic(mosaic, height_ratios=[2.1] * rows + [info_h])
        for k, name in enumerate(names):
            ax = axd[name]
            _landscape_contours(fig, ax, land, name, (s0, s1))
            if show_cons:
                ax.contour(
                    s0, s1, cons.T.astype(float), levels=[0.5], colors="w", linestyles="--",
                    linewidths=1.2,
                )  # fmt: skip
            for where, style, _ in marks:
                ij = np.argwhere(where)
                ax.plot(s0[ij[:, 0]], s1[ij[:, 1]], **style)
            if mark is not None:
                ax.plot(*mark, "o", mfc="none", mec="r", ms=10, mew=1.5)
            ax.set_xlim(s0[0], s0[-1])
            ax.set_ylim(s1[0], s1[-1])
            if k + 3 >= len(names):
                ax.set_xlabel(_scaled_label(land.terms[0], p0))
            if k % 3 == 0:
                ax.set_ylabel(_scaled_label(land.terms[1], p1))
            known = not exact and floor and name in floor
            ax.set_title(f"{name} (noise floor {floor[name]:.3g})" if known else name)
        for key, ax in axd.items():
            if key not in names:
                ax.axis("off")
        axd["info"].text(0.0, 1.0, "\n".join(lines), va="top", transform=axd["info"].transAxes)
        _landscape_legend(axd["legend"], inside, show_cons, marks)
        return _save(fig, stem)


def _started_elsewhere(start, names, path):
    """Whether the search's path begins away from the ``start`` given (the search first
    fitted it cycle by cycle); False without a start."""
    if start is None:
        return False
    given = start if isinstance(start, dict) else start.as_dict()
    return not np.allclose([float(given[n]) for n in names[:2]], path[0, :2])


def _path_panel(fig, ax, result, path, *, land=None, start=None):
    """The path of the best law so far over the first two coefficients: the path the search
    took, from its first law. A start the search replaced (its cycle-by-cycle fit began
    elsewhere) is named in the title, not drawn: nothing joins it to a path not taken."""
    names = list(result.law.names)
    crit = result.criterion
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
    elsewhere = _started_elsewhere(start, names, path)
    if start is not None and not elsewhere:
        ax.plot(*path[0, :2], "s", mfc="none", mec="r", ms=9, mew=1.5, label="start (given)")
    final = result.law.as_dict()
    ax.plot(final[names[0]], final[names[1]], "r*", ms=13, mec="k", label="identified")
    ax.set_xlabel(coefficient_label(names[0]))
    ax.set_ylabel(coefficient_label(names[1]))
    ax.ticklabel_format(style="sci", scilimits=(-3, 4), useMathText=True, useOffset=True)
    lines = [f"{result.method}: path of the best law so far"]
    if len(names) > 2:
        lines.append(f"(first two of {len(names)} terms)")
    if elsewhere:
        lines.append("from the cycle-by-cycle fit of the given start")
    ax.set_title("\n".join(lines))
    ax.legend(loc="best", framealpha=0.8)


def _history_panel(ax, result, value):
    """The best criterion so far against the simulations spent: a log axis over a decade or
    more, else a linear one whose labels carry an offset (a search that barely moves has
    tick labels that differ only past their sixth digit)."""
    from matplotlib.ticker import ScalarFormatter

    crit = result.criterion
    its = list(result.iterations)
    if its:
        sims = np.array([it["n_simulations"] for it in its], dtype=float)
        vals = np.array([it["value"] for it in its], dtype=float)
        xs = np.append(sims, max(result.n_simulations, sims[-1]))
        ax.step(
            xs, np.append(vals, vals[-1]), where="post", color="C0", lw=1.2,
            label=f"best {crit} so far",
        )  # fmt: skip
        ax.plot(sims, vals, "o", color="C0", ms=3.5, label="new best (a step or a probe)")
        if np.all(vals > 0) and vals.max() >= 10 * vals.min():
            ax.set_yscale("log")
        else:
            fmt = ScalarFormatter(useMathText=True, useOffset=True)
            fmt.set_powerlimits((-3, 4))
            ax.yaxis.set_major_formatter(fmt)
        ax.legend(loc="best", framealpha=0.8)
    ax.set_xlabel("simulations spent (steady states computed)")
    ax.set_ylabel(f"best {crit} so far (dimensionless)")
    # the search's value and the final check's (what the report's criteria table shows)
    # differ by the check's own evaluation: both are named where they do
    done = [ev.criteria[crit] for ev in result.checks if crit in (ev.criteria or {})]
    checked = float(np.mean(done)) if done else value
    n = f"{result.n_simulations} simulations in all"
    ax.set_title(
        f"identified: {crit} = {value:.3g} in the search,\n{checked:.3g} in the final check; {n}"
        if done
        else f"identified: {crit} = {value:.3g}\n{n}"
    )
    return checked


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
        The start law the search was given (the values the report lists): marked where
        the path begins when the search began from it. When the search first fitted it
        cycle by cycle (the path begins elsewhere), the title says so and the start is not
        drawn: only the path searched is.
    """
    names = list(result.law.names)
    its = list(result.iterations)
    path = np.array([[it["coefficients"][n] for n in names] for it in its])
    two = len(names) >= 2 and path.size > 0
    from matplotlib.figure import Figure

    with print_sizes():  # drawn at the width it is printed: its text 7 to 8 pt
        fig = Figure(figsize=(PRINT_WIDTH, 6.4 if two else 3.4), layout="constrained")
        if two:  # the path and the history side by side, the forces below at full width
            axd = fig.subplot_mosaic([["a", "b"], ["c", "c"]])
            axes = [axd["a"], axd["b"], axd["c"]]
            _path_panel(fig, axes[0], result, path, land=land, start=start)
        else:
            axes = list(fig.subplots(1, 2))
        crit = result.criterion
        # the identified law's value (result.value can belong to a standard-error probe)
        value = result.criteria.get(crit, result.value)
        checked = _history_panel(axes[1] if two else axes[0], result, value)
        _forces_panel(axes[-1], measured, impulses, f"{crit} = {checked:.3g}")
        return _save(fig, stem)


def _forces_panel(ax1, measured, impulses, checked):
    """F_N of selected laws converging to the measured F_E."""
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
    ax1.set_title(f"$F_N$ converging to $F_E$ ({checked} in the final check)")
    ax1.legend(loc="best", framealpha=0.8)
