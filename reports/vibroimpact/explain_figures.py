"""The figure of one iteration of the missing-effect workflow (``vidi explain``): forces
before and after, phases, the coefficient plane and the effects' scores."""

import textwrap

import numpy as np

from .._mpl import PRINT_WIDTH, print_sizes, save, subplots
from .figure_parts import contact_view, terms_math

__all__ = ["explain_figure"]

_save = save


def _explain_forces(ax, iteration, measured, k):
    """The force before and after the named effect, against the record, over the contact:
    its times re-based on the contact's start, so a contact that crosses the fold's end is
    shown whole (:func:`~.figure_parts.contact_view`), not its tail alone."""
    E = measured
    curves = [(E.F, {"color": "k", "lw": 2, "label": "measured"})]
    if iteration.simulated_before is not None:
        names = " + ".join(iteration.model_before.law.names)
        label = terms_math(f"before ({names})")
        curves.append((iteration.simulated_before.F, {"color": "tab:red", "label": label}))
    if iteration.effect and iteration.simulated_after is not None:
        label = f"+ {iteration.effect.replace('_', ' ')}"
        curves.append((iteration.simulated_after.F, {"color": "tab:blue", "label": label}))
    tr, o, (lo, hi) = contact_view(
        E.t, E.duration, *(F for F, _ in curves), threshold=max(0.02 * E.peak, 5.0 * E.noise)
    )
    for F, style in curves:
        ax.plot(tr[o] * 1e3, np.asarray(F)[o] / 1e3, "-", **style)
    ax.set_xlim(lo * 1e3, hi * 1e3)
    ax.set_xlabel("time since onset [ms]")
    ax.set_ylabel("contact force [kN]")
    i2b = iteration.criteria_before.get("I2", float("nan"))
    i2a = iteration.criteria_after.get("I2", float("nan"))
    ax.set_title(
        f"iteration {k}: I2 {i2b:.3g} -> {i2a:.3g}\n(noise floor before "
        f"{iteration.noise_floor.get('I2', float('nan')):.2g})",
    )
    # room above the curves for the legend, which then covers none of them
    lo, hi = ax.get_ylim()
    ax.set_ylim(lo, hi + 0.55 * (hi - lo))
    # narrow enough for the panel (a wider legend runs over the force's tick labels)
    ax.legend(loc="upper right", framealpha=0.8, handlelength=1.5)


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
    """What decides the name: each refitted effect's criterion after its refit (lower is
    better; the named one green), beside the criterion before and its noise floor; the
    effects whose score test was not significant are not refitted and listed by name."""
    key = next(
        (x.gap for x in iteration.scores if x.gap),
        "I2",
    )
    refit = [x for x in iteration.scores if np.isfinite((x.criteria_after or {}).get(key, np.nan))]
    refit.sort(key=lambda x: -x.criteria_after[key])  # the best at the top
    if refit:
        ax.barh(
            # long names on two lines: the column's width goes to the plots, not the labels
            [textwrap.fill(x.effect.replace("_", " "), 20) for x in refit],
            [max(x.criteria_after[key], 1e-6) for x in refit],
            color=["tab:green" if x.effect == iteration.effect else "tab:orange" for x in refit],
        )
        before = (iteration.criteria_before or {}).get(key)
        floor = (iteration.noise_floor or {}).get(key)
        if before is not None and np.isfinite(before):
            ax.axvline(before, color="k", lw=1.0, ls="--", label=f"{key} before")
        if floor is not None and np.isfinite(floor):
            ax.axvline(floor, color="0.5", lw=1.0, ls=":", label="noise floor")
        vals = [x.criteria_after[key] for x in refit] + [v for v in (before, floor) if v]
        if max(vals) > 30 * max(min(vals), 1e-12):
            ax.set_xscale("log")
        else:
            ax.set_xlim(0.0, 1.05 * max(vals))
        ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.3), ncol=2, frameon=False)
    else:
        ax.text(0.5, 0.5, "no effect refitted", ha="center", transform=ax.transAxes)
    shown = {id(x) for x in refit}
    skipped = [x.effect.replace("_", " ") for x in iteration.scores if id(x) not in shown]
    note = f"\nnot refitted (score not significant): {len(skipped)}" if skipped else ""
    ax.set_xlabel(f"{key} after refitting the effect (lower is better){note}")
    ax.set_title("candidate effects refitted\n(green: named; orange: refitted, not named)")


def explain_figure(iteration, measured, stem, k=1):
    """One iteration of the missing-effect loop: the force before and after adding the
    named effect against the record, the residual's share by impact phase (and its ratio
    to the noise), the mean residual over the simulated (zeta, dzeta) plane, and every
    refitted candidate effect's criterion after its refit (what names the effect)."""
    with print_sizes():  # drawn at the width it is printed: its text 7 to 8 pt on paper
        fig, axes = subplots(2, 2, figsize=(PRINT_WIDTH, 6.6), layout="constrained")
        _explain_forces(axes[0, 0], iteration, measured, k)
        _explain_phases(axes[0, 1], iteration)
        _explain_plane(fig, axes[1, 0], iteration)
        _explain_scores(axes[1, 1], iteration)
        return _save(fig, stem)
