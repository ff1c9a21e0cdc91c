"""Figures as pure functions of result objects (matplotlib Figures, no pyplot).

Each function writes the same figure as PNG and PDF and returns the paths.
"""

import numpy as np

from .._mpl import PRINT_WIDTH, colormap, figure, print_sizes, save, subplots

__all__ = ["landscape_figure", "identification_figure", "verify_figure", "explain_figure"]

_ORDER = ("I1", "I2", "I3", "I4", "I0")


def _exp(p):
    return str(int(p)) if float(p).is_integer() else f"{float(p):g}"


def term_unit(name):
    """SI unit of the coefficient of the term ``name`` (``z^a*zd^b``): N m^-a (m/s)^-b,
    as matplotlib mathtext, e.g. ``'z*zd'`` -> ``N m$^{-1}$ (m/s)$^{-1}$``."""
    from discovery.vibroimpact.model.law import Term

    try:
        t = Term.parse(name)
    except Exception:  # not a single term: say what the coefficient multiplies
        return f"N per unit of {name}"
    unit = "N"
    if t.a:
        unit += f" m$^{{-{_exp(t.a)}}}$"
    if t.b:
        unit += f" (m/s)$^{{-{_exp(t.b)}}}$"
    return unit


def coefficient_label(name):
    """Axis label of a coefficient with its unit, e.g. ``coefficient of z [N m^-1]``."""
    return f"coefficient of {name} [{term_unit(name)}]"


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


def _landscape_info_lines(land, ref_reg, exact, floor, cons, truth, inside):
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
        lines = _landscape_info_lines(land, ref_reg, exact, floor, cons, truth, inside)
        ax.text(0.0, 1.0, "\n".join(lines), va="top", fontsize=7, transform=ax.transAxes)
        _landscape_legend(ax, inside, show_cons, marks)
        fig.tight_layout()
        return _save(fig, stem)


def identification_figure(result, measured, impulses, stem, land=None):
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
        ax.plot(path[0, 0], path[0, 1], "s", mfc="none", mec="r", ms=9, mew=1.5, label="start")
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
        ax.legend(fontsize=7)
    ax.set_xlabel("simulations spent (steady states computed)")
    ax.set_ylabel(f"best {crit} so far (dimensionless)")
    ax.set_title(
        f"identified: {crit} = {value:.3g}, {result.n_simulations} simulations in all", fontsize=8
    )
    ax1 = axes[-1]
    ax1.plot(measured.t * 1e3, measured.F / 1e6, "k-", lw=2.5, label="F_E (measured)")
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
    ax1.set_title(f"F_N converging to F_E ({crit} = {value:.3g})", fontsize=8)
    ax1.legend(fontsize=7)
    return _save(fig, stem)


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
    fig, axes = subplots(
        len(measured), 1, figsize=(PRINT_WIDTH, 1.2 + 2.2 * len(measured)), squeeze=False
    )
    sc, unit = _force_unit(max(E.peak for E in measured))
    for r, (E, ax) in enumerate(zip(measured, axes[:, 0], strict=True)):
        sims = [
            (
                labels[k] if k < len(labels) else ", ".join(m.law.names),
                m.evaluations[r].simulated if r < len(m.evaluations) else None,
            )
            for k, m in enumerate(models)
        ]
        forces = [E.F] + [np.interp(E.t, imp.t, imp.F) for _, imp in sims if imp is not None]
        tr, o, (lo, hi) = _contact_view(
            E.t, E.duration, *forces, threshold=max(0.02 * E.peak, 5.0 * E.noise)
        )
        ax.plot(
            tr[o] * 1e3,
            E.F[o] * sc,
            "k-",
            lw=2.5,
            alpha=0.6,
            label=f"measured ({E.n_cycles} cycles)",
        )
        styles = ["-", "--", ":"]
        for k, (label, imp) in enumerate(sims):
            if imp is None:
                continue
            f = np.interp(E.t, imp.t, imp.F)
            ax.plot(
                tr[o] * 1e3,
                f[o] * sc,
                styles[k % 3],
                lw=1.4,
                color=f"C{k}",
                label=terms_math(label),
            )
        ax.set_xlim(lo * 1e3, hi * 1e3)
        ax.set_ylabel(f"contact force [{unit}]")
        name = getattr(refs[r], "source", None) or f"record {r + 1}"
        ax.set_title(
            f"record {r + 1}: {plain(name)}"
            if len(measured) > 1
            else "Measured impulse and the simulated steady states of the best models",
            fontsize=8,
        )
        ax.legend(fontsize=7, loc="best", framealpha=0.8)
    axes[-1, 0].set_xlabel("time since the start of the contact [ms]")
    fig.tight_layout()
    return _save(fig, stem)


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
    fig.tight_layout()
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
                    z * 1e3, mm, style, color=f"C{k}", lw=1.6,
                    label=f"model, impact {imp}" if style == "-" else None,
                )  # fmt: skip
        ax.plot([], [], "k-", lw=1.6, label="model loading (solid)")
        ax.plot([], [], "k--", lw=1.6, label="model unloading (dashed)")
        ax.set_xlabel(r"penetration $\zeta$ [mm]")
        ax.set_ylabel("contact force [kN]")
        ax.set_title("Loading and unloading branches, measured and modelled")
        ax.legend(loc="best", framealpha=0.8)
        fig.tight_layout()
    return _save(fig, stem)


def _monomial_math(term, unloading=False):
    zd = r"|\dot{\zeta}|" if unloading else r"\dot{\zeta}_{+}"
    parts = []
    if term.a:
        parts.append(r"\zeta" if term.a == 1 else rf"\zeta^{{{_exp(term.a)}}}")
    if term.b:
        parts.append(zd if term.b == 1 else rf"{zd}^{{{_exp(term.b)}}}")
    return r"\,".join(parts)


def law_math(law):
    r"""A law as matplotlib mathtext: ``$F = 2.06\cdot 10^{8}\,\zeta + ...$`` (the
    unloading terms after a semicolon)."""
    from reports.lawtex import sci

    def poly(coefs, terms, unloading=False):
        out = [
            ("-" if c < 0 else "+") + rf" {sci(abs(c))}\,{_monomial_math(t, unloading)}"
            for c, t in zip(coefs, terms, strict=True)
        ]
        text = " ".join(out)
        return text[2:] if text.startswith("+ ") else text

    text = f"$P = {poly(law.coefficients, law.terms)}$"
    if law.unloading:
        text += f"; unloading $Q = {poly(law.unloading_coefficients, law.unloading, True)}$"
    if law.permanent_set:
        text += f"; set {law.permanent_set:.3g}"
    return text


def terms_math(text):
    """User or label text with its term names (``z^2*zd``) as mathtext, the rest plain."""
    from discovery.vibroimpact.model.law import Term
    from reports.lawtex import _TERMISH

    text = plain(text)
    out, pos = [], 0
    for m in _TERMISH.finditer(text):
        try:
            term = Term.parse(m.group(0))
        except Exception:  # not a term after all
            continue
        out.append(text[pos : m.start()] + f"${_monomial_math(term)}$")
        pos = m.end()
    return "".join(out) + text[pos:]


def plain(text):
    """User text (a file or scenario name) for a figure: matplotlib would read ``$...$`` as
    mathtext (and fail on a broken one)."""
    return str(text).replace("$", r"\$")


def _force_unit(peak):
    """``(scale, unit)`` to draw forces without an offset label: N, kN or MN."""
    peak = abs(float(peak)) if np.isfinite(peak) else 0.0
    if peak >= 1e6:
        return 1e-6, "MN"
    if peak >= 1e3:
        return 1e-3, "kN"
    return 1.0, "N"


def _contact_view(t, period, *forces, threshold=0.0):
    """Times of a folded cycle re-based on the contact: ``(t', order, (lo, hi))`` with
    ``t'`` the time since the first sample of the contact (the end of the longest stretch
    where every force is at most ``threshold``), wrapped so the contact is not cut by the
    fold, and the x-range around it (the whole cycle when contact fills most of it)."""
    t = np.asarray(t, dtype=float)
    active = np.zeros(t.size, dtype=bool)
    for f in forces:
        active |= np.abs(np.asarray(f, dtype=float)) > threshold
    # a noise spike is not a contact: keep only runs of at least 3 samples
    active &= (
        (np.roll(active, 1) & np.roll(active, -1))
        | (np.roll(active, 1) & np.roll(active, 2))
        | (np.roll(active, -1) & np.roll(active, -2))
    )
    n = t.size
    if not active.any() or active.all():
        return t - t[0], np.arange(n), (0.0, float(period))
    # the longest run of inactive samples on the circle
    doubled = np.concatenate([~active, ~active])
    best_len, best_end, run = 0, 0, 0
    for i, free in enumerate(doubled):
        run = run + 1 if free else 0
        if run > best_len and run <= n:
            best_len, best_end = run, i
    start = (best_end + 1) % n  # first active sample after the longest gap
    tr = np.mod(t - t[start], period)
    span = float(period) * (n - best_len) / n
    margin = 0.15 * span
    tr = np.where(tr > period - margin, tr - period, tr)
    order = np.argsort(tr)
    if span > 0.6 * period:
        return tr, order, (float(tr.min()), float(tr.max()))
    return tr, order, (-margin, span + 2.0 * margin)


def verify_figure(result, stem):
    """Measured and simulated force over the whole orbit, the noise band, the residual.

    Parameters
    ----------
    result : discovery.vibroimpact.verify.VerifyResult
    stem : str
        Output path without extension (PNG and PDF are written).
    """
    from discovery.vibroimpact.verify.criteria import compare
    from discovery.vibroimpact.verify.motion import force_penetration_loops

    ev = result.evaluation
    E = result.reference.impulse
    loops = force_penetration_loops(result.reference, ev)
    if loops is None:
        fig, (ax, axr) = subplots(
            2, 1, figsize=(PRINT_WIDTH, 4.8), sharex=True, gridspec_kw={"height_ratios": [3, 1.3]}
        )
    else:  # the force-penetration loops beside the force histories
        fig = figure(figsize=(PRINT_WIDTH, 5.6))
        grid = fig.add_gridspec(2, 2, height_ratios=[3, 2], width_ratios=[1.5, 1])
        ax = fig.add_subplot(grid[0, 0])
        axr = fig.add_subplot(grid[1, 0], sharex=ax)
        _loops_panel(fig.add_subplot(grid[0, 1]), fig.add_subplot(grid[1, 1]), loops, ev)
    band = 2.0 * result.reference.noise.get("F", 0.0) / np.sqrt(max(E.n_cycles, 1))
    ms = 1e3
    sc, unit = _force_unit(E.peak)
    if ev.simulated is not None:
        c = compare(E, ev.simulated)
        # the contact, not the whole cycle: re-based on its start, not cut by the fold
        tr, o, (lo, hi) = _contact_view(
            c.t, E.duration, c.fe, c.fn, threshold=max(2.0 * band, 0.02 * E.peak, 5.0 * E.noise)
        )
        x = tr[o] * ms
        ax.fill_between(
            x,
            (c.fe[o] - band) * sc,
            (c.fe[o] + band) * sc,
            color="0.85",
            label=f"measured +-2 sigma/sqrt({E.n_cycles}) noise band",
        )
        ax.plot(x, c.fe[o] * sc, "k-", lw=1.0, label=f"measured F_E ({E.n_cycles} cycles)")
        ax.plot(x, c.fn[o] * sc, "C3-", lw=1.0, label=f"simulated F_N ({ev.regime['simulated']})")
        axr.fill_between(x, -band * sc, band * sc, color="0.85")
        axr.plot(x, (c.fn[o] - c.fe[o]) * sc, "C0-", lw=0.8)
        ax.set_xlim(lo * ms, hi * ms)
    else:
        ax.plot(E.t * ms, E.F * sc, "k-", lw=1.0, label="measured F_E")
    crit = ", ".join(
        f"{k} {v:.3g} (floor {ev.noise_floor.get(k, float('nan')):.2g})"
        for k, v in ev.criteria.items()
        if k in ("I2", "I4", "I5")
    )
    ax.set_title(
        f"{law_math(result.law)}\n"
        f"{'consistent' if ev.consistent else 'INCONSISTENT'}: {crit or ev.status}",
        fontsize=8,
    )
    ax.set_ylabel(f"contact force F [{unit}]")
    ax.legend(fontsize=7, loc="best", framealpha=0.8)
    axr.set_ylabel(f"F_N - F_E [{unit}]")
    axr.set_xlabel("time since the contact's start [ms] (folded)")
    axr.axhline(0.0, color="k", lw=0.5)
    fig.tight_layout()
    return _save(fig, stem)


def loops_figure(loops, evaluation, stem, law, what):
    """The force-penetration loop and both penetrations over the contacts of a model
    against a record (:func:`discovery.vibroimpact.verify.motion.force_penetration_loops`),
    e.g. explain's final model.

    Parameters
    ----------
    loops : dict
    evaluation : Evaluation
        Its I5 and limit go in the title.
    stem : str
        Output path without extension (PNG and PDF are written).
    law : ForceLaw
    what : str
        What the law is, for the title (e.g. "final model").
    """
    fig, (ax, axz) = subplots(1, 2, figsize=(PRINT_WIDTH, 3.0))
    _loops_panel(ax, axz, loops, evaluation)
    fig.suptitle(f"{what}: {law_math(law)}", fontsize=8)
    fig.tight_layout()
    return _save(fig, stem)


def _loops_panel(ax, axz, loops, ev):
    """The force against the penetration over the contacts (the loop), and both
    penetrations over time there (what I5 compares)."""
    t = loops["phase"] * 1e3
    # the window's separate runs (a cycle's end, another contact) are not joined by a line
    gap = np.flatnonzero(np.diff(t) > 5.0 * np.median(np.diff(t))) + 1 if t.size > 2 else []

    def runs(v):
        return np.insert(np.asarray(v, dtype=float), gap, np.nan)

    zm, fm = (runs(v) for v in loops["measured"])
    zn, fn = (runs(v) for v in loops["simulated"])
    t = runs(t)
    sc, unit = _force_unit(max(float(np.nanmax(np.abs(fm))), 1e-300))
    ax.plot(zm * 1e3, fm * sc, "k.-", lw=0.8, ms=2, label="measured")
    ax.plot(zn * 1e3, fn * sc, "C3.-", lw=0.8, ms=2, label="simulated")
    ax.set_title("force-penetration loop", fontsize=8)
    ax.set_xlabel("penetration w1 - w2 [mm]")
    ax.set_ylabel(f"F [{unit}]")
    ax.axvline(0.0, color="0.6", lw=0.5)
    ax.legend(fontsize=7, loc="best", framealpha=0.8)
    axz.plot(t, zm * 1e3, "k-", lw=0.8)
    axz.plot(t, zn * 1e3, "C3-", lw=0.8)
    axz.axhline(0.0, color="0.6", lw=0.5)
    i5, lim = ev.criteria.get("I5"), (ev.limits or {}).get("I5")
    if i5 is not None:
        axz.set_title(
            f"I5 {i5:.3g}" + (f" (limit {lim:.3g})" if lim is not None else ""), fontsize=8
        )
    axz.set_xlabel("time in the cycle [ms]")
    axz.set_ylabel("w1 - w2 [mm]")


def _explain_forces(ax, iteration, measured, k):
    """The force before and after the named effect, against the record."""
    E = measured
    ax.plot(E.t * 1e3, E.F / 1e3, "k-", lw=2, label="measured")
    if iteration.simulated_before is not None:
        ax.plot(
            E.t * 1e3,
            iteration.simulated_before.F / 1e3,
            "-",
            color="tab:red",
            label=terms_math(f"before ({' + '.join(iteration.model_before.law.names)})"),
        )
    if iteration.effect and iteration.simulated_after is not None:
        ax.plot(
            E.t * 1e3,
            iteration.simulated_after.F / 1e3,
            "-",
            color="tab:blue",
            label=f"after (+ {iteration.effect.replace('_', ' ')})",
        )
    if len(E.support):
        a, b = E.support[0]
        ax.set_xlim(max(a - 0.1 * (b - a), 0) * 1e3, (b + 0.3 * (b - a)) * 1e3)
    ax.set_xlabel("time since onset [ms]")
    ax.set_ylabel("contact force [kN]")
    i2b = iteration.criteria_before.get("I2", float("nan"))
    i2a = iteration.criteria_after.get("I2", float("nan"))
    ax.set_title(
        f"iteration {k}: I2 {i2b:.3g} -> {i2a:.3g}\n(noise floor "
        f"{iteration.noise_floor.get('I2', float('nan')):.2g})",
    )
    ax.legend(loc="best", framealpha=0.8)


def _explain_phases(ax, iteration):
    """The residual's share by impact phase, and its ratio to the noise."""
    ph = iteration.localisation["phases"]
    names = list(ph)
    shares = [ph[n]["share"] for n in names]
    x = np.arange(len(names))
    bars = ax.bar(
        x, shares, color=["tab:red" if ph[n]["exceeds_noise"] else "tab:gray" for n in names]
    )
    # phase names are long next to each other: rotated, anchored at their tick
    ax.set_xticks(
        x, [n.replace("_", " ") for n in names], rotation=30, ha="right", rotation_mode="anchor"
    )
    for bar, n in zip(bars, names, strict=True):
        r = ph[n]["ratio_to_noise"]
        if r is not None:
            ax.text(
                bar.get_x() + bar.get_width() / 2,
                bar.get_height(),
                f"{r:.0f}x" if r >= 10 else f"{r:.1f}x",
                ha="center",
                va="bottom",
            )
    ax.margins(y=0.12)  # room for the numbers above the tallest bar
    ax.set_xlabel("impact phase")
    ax.set_ylabel("share of the residual energy\nabove the noise")
    ax.set_title(
        "where the model disagrees, by impact phase\n(red: above the noise;\n"
        "number: residual energy / noise energy)",
    )


def _explain_plane(fig, ax, iteration):
    """The mean residual over the simulated (zeta, dzeta) plane."""
    plane = iteration.localisation.get("plane")
    if plane is not None:
        ze, ve = plane["zeta_edges"], plane["dzeta_edges"]
        m = plane["mean_residual"]
        lim = np.nanmax(np.abs(m)) if np.isfinite(m).any() else 1.0
        # an empty bin (NaN: no sample fell in it) is gray, a zero residual white
        ax.set_facecolor("0.8")
        im = ax.pcolormesh(
            ze * 1e3,
            ve,
            np.ma.masked_invalid(m / 1e3).T,
            cmap="RdBu_r",
            vmin=-lim / 1e3,
            vmax=lim / 1e3,
            shading="flat",
        )
        fig.colorbar(im, ax=ax, label=r"mean residual $F_N - F_E$ [kN]")
        ax.set_xlabel(r"$\zeta$ [mm] (simulated)")
        ax.set_ylabel(r"$\dot{\zeta}$ [m/s] (simulated)")
    else:
        ax.text(0.5, 0.5, "no positions in the record", ha="center", transform=ax.transAxes)
    ax.set_title(r"residual over the ($\zeta$, $\dot{\zeta}$) plane" + "\n(gray: no samples)")


def _explain_scores(ax, iteration):
    """Every candidate effect's score test."""
    sc = [x for x in iteration.scores if x.get("lm") is not None]
    unscored = [x for x in iteration.scores if x.get("lm") is None and "criteria_after" in x]
    if sc or unscored:
        lm = [max(x["lm"], 1e-3) for x in sc]
        ax.barh(
            [x["effect"].replace("_", " ") for x in sc],
            lm,
            color=[
                "tab:green"
                if x["effect"] == iteration.effect
                else ("tab:orange" if x["significant"] else "tab:gray")
                for x in sc
            ],
        )
        # an effect whose small step changes the regime has no score, only its refit
        for x in unscored:
            ax.barh(
                [x["effect"].replace("_", " ")],
                [max(lm, default=1.0)],
                fill=False,
                hatch="//",
                edgecolor="tab:green" if x["effect"] == iteration.effect else "tab:gray",
            )
        ax.set_xscale("log")
    ax.set_xlabel("score-test (LM) statistic\n(hatched: no local score, refitted)")
    ax.set_title("candidate effects\n(green: named; orange: significant;\ngray: not significant)")


def explain_figure(iteration, measured, stem, k=1):
    """One iteration of the missing-effect loop: the force before and after adding the
    named effect against the record, the residual's share by impact phase (and its ratio
    to the noise), the mean residual over the simulated (zeta, dzeta) plane, and every
    candidate effect's score test."""
    with print_sizes():  # drawn at the width it is printed: its text 7 to 8 pt on paper
        fig, axes = subplots(2, 2, figsize=(PRINT_WIDTH, 6.6), layout="constrained")
        _explain_forces(axes[0, 0], iteration, measured, k)
        _explain_phases(axes[0, 1], iteration)
        _explain_plane(fig, axes[1, 0], iteration)
        _explain_scores(axes[1, 1], iteration)
        return _save(fig, stem)
