"""Figures of a verification (``vidi verify``): measured and simulated force over the orbit,
and the force-penetration loops."""

import textwrap

import numpy as np

from .._mpl import PRINT_WIDTH, figure, save, subplots
from .figure_parts import contact_view, force_unit, law_math

__all__ = ["verify_figure", "loops_figure", "span_view"]

_save = save


_JUDGED = ("I2", "I4", "I5")


def _criterion_text(k, v, ev):
    """A judged criterion with its noise floor and its limit, named apart."""
    floor = (ev.noise_floor or {}).get(k, float("nan"))
    lim = (ev.limits or {}).get(k)
    return f"{k} {v:.3g} (floor {floor:.2g}" + (f", limit {lim:.2g})" if lim is not None else ")")


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
    view = span_view(result)
    if view is not None:
        return _span_figure(result, view, stem)
    loops = force_penetration_loops(result.reference, ev)
    if ev.simulated is None:  # nothing simulated to compare: the measured force alone
        fig, ax = subplots(1, 1, figsize=(PRINT_WIDTH, 3.4))
        axr = None
    elif loops is None:
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
    sc, unit = force_unit(E.peak)
    if ev.simulated is not None:
        c = compare(E, ev.simulated)
        # the contact, not the whole cycle: re-based on its start, not cut by the fold
        tr, o, (lo, hi) = contact_view(
            c.t, E.duration, c.fe, c.fn, threshold=max(2.0 * band, 0.02 * E.peak, 5.0 * E.noise)
        )
        x = tr[o] * ms
        ax.fill_between(
            x,
            (c.fe[o] - band) * sc,
            (c.fe[o] + band) * sc,
            color="0.85",
            label=rf"measured $\pm 2\sigma/\sqrt{{{E.n_cycles}}}$ noise band",
        )
        ax.plot(x, c.fe[o] * sc, "k-", lw=1.0, label=rf"measured $F_E$ ({E.n_cycles} cycles)")
        ax.plot(
            x, c.fn[o] * sc, "C3-", lw=1.0, label=rf"simulated $F_N$ ({ev.regime['simulated']})"
        )
        axr.fill_between(x, -band * sc, band * sc, color="0.85")
        axr.plot(x, (c.fn[o] - c.fe[o]) * sc, "C0-", lw=0.8)
        ax.set_xlim(lo * ms, hi * ms)
    else:
        ax.plot(E.t * ms, E.F * sc, "k-", lw=1.0, label=r"measured $F_E$")
        ax.set_xlabel("time in the folded cycle [ms]")
    crit = ", ".join(_criterion_text(k, v, ev) for k, v in ev.criteria.items() if k in _JUDGED)
    verdict = f"{'consistent' if ev.consistent else 'INCONSISTENT'}: {crit or _why_none(ev)}"
    ax.set_title(
        f"{law_math(result.law)}\n" + textwrap.fill(verdict, 72),
        fontsize=8,
    )
    ax.set_ylabel(f"contact force F [{unit}]")
    ax.legend(fontsize=7, loc="best", framealpha=0.8)
    if axr is not None:
        axr.set_ylabel(f"$F_N - F_E$ [{unit}]")
        axr.set_xlabel("time since the contact's start [ms] (folded)")
        axr.axhline(0.0, color="k", lw=0.5)
    fig.set_layout_engine("tight")  # laid out once, by save()
    return _save(fig, stem)


def span_view(result):
    """The last compared block of a record-span verification, unfolded: the samples of its
    last whole contact (onset to loss, padded by a fifth of its length each side) and every
    contact sample of the block, measured and simulated; None for a steady-orbit
    comparison or a loaded result (its simulations are not saved).

    A record in a transient (or a shedding machine) has contacts at another phase in each
    cycle: the fold of several cycles averages them into a staircase, so the verdict's own
    comparison, sample by sample on the record's span, is what is shown.

    Returns
    -------
    dict or None
        ``t`` (times since the contact's onset [s]), ``fm``, ``fn`` (forces [N]) and, with
        positions, ``zm``, ``zn`` (penetrations [m]) over the contact's window;
        ``loop``: ``(zm, fm, zn, fn)`` over every contact sample of the block; ``sigma``:
        the force's noise [N]; ``cycles``: the block's cycles.
    """
    from discovery.vibroimpact.verify.motion import contact_runs, contact_samples_of

    ev = result.evaluation
    span = getattr(result.reference, "span", None)
    if ev.comparison != "record span" or not ev.histories or span is None:
        return None
    blk = span.blocks[-1]
    td = np.asarray(blk.fold.td, dtype=float)
    fm, fn = np.asarray(blk.F, dtype=float), np.asarray(ev.histories[-1], dtype=float)
    if fn.shape != fm.shape or td.size < 8:
        return None
    sigma = float(span.sigma_f)
    inside = contact_samples_of(blk, fn, sigma)
    runs = contact_runs(inside, max(3, int(0.1 * blk.fold.period / np.median(np.diff(td)))))
    if not runs:
        return None
    whole = [r for r in runs if r[0] > 0 and r[1] < td.size] or runs
    a, b = whole[-1]
    pad = max(5, (b - a) // 5)
    w = slice(max(a - pad, 0), min(b + pad, td.size))
    zm = zn = None
    if ev.penetration and span.sigma_z > 0:
        zm, zn = np.asarray(blk.Z, dtype=float), np.asarray(ev.penetration[-1], dtype=float)
    loop = None if zm is None else (zm[inside], fm[inside], zn[inside], fn[inside])
    return {
        "t": td[w] - td[a],
        "fm": fm[w],
        "fn": fn[w],
        "zm": None if zm is None else zm[w],
        "zn": None if zn is None else zn[w],
        "loop": loop,
        "sigma": sigma,
        "cycles": int(blk.fold.n_cycles),
    }


def _span_figure(result, view, stem):
    """The verify figure of a record-span comparison (:func:`span_view`): the last contact's
    measured and simulated force on the record's samples with the noise band and the
    residual; with positions, the loop over the block's contact samples and both
    penetrations over the contact."""
    ev = result.evaluation
    ms = 1e3
    x = view["t"] * ms
    band = 2.0 * view["sigma"]
    sc, unit = force_unit(max(float(np.max(np.abs(view["fm"]))), 1e-300))
    if view["loop"] is None:
        fig, (ax, axr) = subplots(
            2, 1, figsize=(PRINT_WIDTH, 4.8), sharex=True, gridspec_kw={"height_ratios": [3, 1.3]}
        )
    else:
        fig = figure(figsize=(PRINT_WIDTH, 5.6))
        grid = fig.add_gridspec(2, 2, height_ratios=[3, 2], width_ratios=[1.5, 1])
        ax = fig.add_subplot(grid[0, 0])
        axr = fig.add_subplot(grid[1, 0], sharex=ax)
        axl, axz = fig.add_subplot(grid[0, 1]), fig.add_subplot(grid[1, 1], sharex=ax)
        zm, fm, zn, fn = view["loop"]
        axl.plot(zm * ms, fm * sc, "k.", ms=1.5, label="measured")
        axl.plot(zn * ms, fn * sc, "C3.", ms=1.5, label="simulated")
        axl.axvline(0.0, color="0.6", lw=0.5)
        axl.set_title(f"force-penetration loop ({view['cycles']} cycles)", fontsize=8)
        axl.set_xlabel("penetration w1 - w2 [mm]")
        axl.set_ylabel(f"F [{unit}]")
        axl.legend(fontsize=7, loc="best", framealpha=0.8, markerscale=4)
        _penetrations(axz, x, view["zm"] * ms, view["zn"] * ms, ev)
        axz.set_xlabel("since the onset [ms]")
    ax.fill_between(
        x,
        (view["fm"] - band) * sc,
        (view["fm"] + band) * sc,
        color="0.85",
        label=r"measured $\pm 2\sigma$ noise band",
    )
    ax.plot(x, view["fm"] * sc, "k-", lw=1.0, label=r"measured $F_E$ (the record's samples)")
    ax.plot(x, view["fn"] * sc, "C3-", lw=1.0, label=r"simulated $F_N$ from the measured state")
    axr.fill_between(x, -band * sc, band * sc, color="0.85")
    axr.plot(x, (view["fn"] - view["fm"]) * sc, "C0-", lw=0.8)
    axr.axhline(0.0, color="k", lw=0.5)
    axr.set_ylabel(f"$F_N - F_E$ [{unit}]")
    axr.set_xlabel("time since the last contact's onset [ms]")
    crit = ", ".join(_criterion_text(k, v, ev) for k, v in ev.criteria.items() if k in _JUDGED)
    verdict = f"{'consistent' if ev.consistent else 'INCONSISTENT'}: {crit or _why_none(ev)}"
    ax.set_title(f"{law_math(result.law)}\n" + textwrap.fill(verdict, 72), fontsize=8)
    ax.set_ylabel(f"contact force F [{unit}]")
    ax.legend(fontsize=7, loc="best", framealpha=0.8)
    fig.set_layout_engine("tight")  # laid out once, by save()
    return _save(fig, stem)


def _penetrations(axz, t, zm, zn, ev):
    """Both penetrations [mm] over time, with I5 and its limit in the title."""
    axz.plot(t, zm, "k-", lw=0.8)
    axz.plot(t, zn, "C3-", lw=0.8)
    axz.axhline(0.0, color="0.6", lw=0.5)
    i5, lim = ev.criteria.get("I5"), (ev.limits or {}).get("I5")
    if i5 is not None:
        axz.set_title(
            f"I5 {i5:.3g}" + (f" (limit {lim:.3g})" if lim is not None else ""), fontsize=8
        )
    axz.set_ylabel("w1 - w2 [mm]")


def _why_none(ev):
    """Why a verification has no simulated force to show."""
    if ev.status == "failed":
        return "the law's simulation failed, nothing to compare"
    if ev.status == "nonperiodic":
        return "the law has no stable periodic steady state, nothing to compare"
    if ev.status == "no-contact":
        return "the simulated bodies never touch, nothing to compare"
    return str(ev.status)


def loops_figure(loops, evaluation, stem, law, what, *, note=""):
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
    note : str
        A second title line: what the model adds beside its law (a machine change, an
        observation model).
    """
    fig, (ax, axz) = subplots(1, 2, figsize=(PRINT_WIDTH, 3.0))
    _loops_panel(ax, axz, loops, evaluation)
    fig.suptitle(f"{what}: {law_math(law)}" + (f"\n{note}" if note else ""), fontsize=8)
    fig.set_layout_engine("tight")  # laid out once, by save()
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
    sc, unit = force_unit(max(float(np.nanmax(np.abs(fm))), 1e-300))
    ax.plot(zm * 1e3, fm * sc, "k.-", lw=0.8, ms=2, label="measured")
    ax.plot(zn * 1e3, fn * sc, "C3.-", lw=0.8, ms=2, label="simulated")
    ax.set_title("force-penetration loop", fontsize=8)
    ax.set_xlabel("penetration w1 - w2 [mm]")
    ax.set_ylabel(f"F [{unit}]")
    ax.axvline(0.0, color="0.6", lw=0.5)
    ax.legend(fontsize=7, loc="best", framealpha=0.8)
    _penetrations(axz, t, zm * 1e3, zn * 1e3, ev)
    axz.set_xlabel("time in the compared cycles [ms]")
