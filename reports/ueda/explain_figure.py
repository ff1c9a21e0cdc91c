"""Figure of the missing-effect workflow for Ueda's oscillators (``vidi ueda explain``):
(a) the score statistics of the catalogue's effects at every iteration against the
Bonferroni gate, (b) the record's stroboscopic points over the start model's, (c) over the
final model's.  Writes PNG and PDF and returns the paths.
"""

import numpy as np
from matplotlib.figure import Figure
from matplotlib.patches import Patch
from scipy.stats import chi2

from .._mpl import PRINT_WIDTH, colormap, print_sizes, save
from .figures import _equation_math, _term_math

_save = save

__all__ = ["explain_figure"]


def _strobe_panel(ax, ver, label, color, title):
    if ver is None:
        ax.text(0.5, 0.5, "not simulated", ha="center", va="center", transform=ax.transAxes)
        ax.set_title(title, fontsize=9)
        return
    ms, rs = ver.model_strobe, ver.record_strobe
    if len(ms):
        few = len(np.unique(np.round(ms / (np.ptp(rs, axis=0) + 1e-12), 3), axis=0)) < 50
        ax.plot(
            ms[:, 0],
            ms[:, 1],
            "x" if few else ".",
            ms=9 if few else 1.5,
            mew=2,
            color=color,
            alpha=0.9 if few else 0.6,
            label=f"{label} ({len(ms)}, {ver.regime_model})",
        )
    ax.plot(
        rs[:, 0], rs[:, 1], ".", ms=4, color="k", label=f"record ({len(rs)}, {ver.regime_record})"
    )
    lo, hi = rs.min(axis=0), rs.max(axis=0)
    span = hi - lo + 1e-9
    finite = ms[np.all(np.isfinite(ms), axis=1)] if len(ms) else ms
    far = False
    if len(finite):  # the model's points in view, unless it went far (diverged)
        mlo, mhi = finite.min(axis=0), finite.max(axis=0)
        if np.all(mlo > lo - 10 * span) and np.all(mhi < hi + 10 * span):
            lo, hi = np.minimum(lo, mlo), np.maximum(hi, mhi)
        else:
            far = True
    pad = 0.15 * (hi - lo) + 1e-9
    if far:
        ax.text(
            0.02,
            0.02,
            f"{label}: points far outside this view (e.g. x = "
            f"{finite[0, 0]:.3g}, x' = {finite[0, 1]:.3g})",
            transform=ax.transAxes,
            fontsize=7,
            color=color,
        )
    ax.set_xlim(lo[0] - pad[0], hi[0] + pad[0])  # a diverged or far model stays readable
    ax.set_ylim(lo[1] - pad[1], hi[1] + pad[1])
    ax.set_xlabel("x")
    ax.set_ylabel("x'")
    ax.legend(loc="best", fontsize=7, framealpha=0.8)
    if ver.diverged:
        gap = "model diverged"
    else:
        gap = (
            f"energy distance {ver.energy_distance:.3g}\n(floor q95 {ver.floor_q95:.3g}): "
            f"{'consistent' if ver.consistent else 'INCONSISTENT'}"
        )
    ax.set_title(f"{title}\n{gap}", fontsize=8)
    ax.grid(alpha=0.3)


def explain_figure(ex, stem):
    """The figure of an :class:`~discovery.ueda.explanation.Explanation`, drawn at the width it
    is printed (its text 7 to 8 pt): the score tests above, the start and final models'
    strobe points below."""
    with print_sizes():
        return _draw(ex, stem)


def _draw(ex, stem):
    fig = Figure(figsize=(PRINT_WIDTH, 6.6), layout="constrained")
    axd = fig.subplot_mosaic([["a", "a"], ["b", "c"]], height_ratios=[1, 1.15])
    axes = [axd["a"], axd["b"], axd["c"]]
    ax = axes[0]
    its = ex.iterations
    ids = [s["effect"] for s in its[0].scores] if its else []
    for it in its[1:]:
        ids += [s["effect"] for s in it.scores if s["effect"] not in ids]
    width = 0.8 / max(len(ids), 1)
    colors = colormap("tab10")
    for k, it in enumerate(its):
        for s in it.scores:
            j = ids.index(s["effect"])
            edge = "k" if s["effect"] == it.effect else "none"
            ax.bar(
                k - 0.4 + (j + 0.5) * width,
                max(s["lm"], 1e-2),
                width,
                color=colors(j % 10),
                edgecolor=edge,
                lw=1.5,
            )
        if it.scores:
            gate = it.evidence.get("gate", 0.01 / len(it.scores))
            ax.hlines(chi2.isf(gate, 1), k - 0.45, k + 0.45, colors="r", linestyles="--")
    ax.set_yscale("log")
    ax.set_xticks(
        np.arange(len(its)),
        [f"{k + 1}: {(it.effect or 'none named').replace('_', ' ')}" for k, it in enumerate(its)],
        fontsize=8,
    )
    ax.set_ylabel(r"score statistic LM ($\chi^2(1)$)")
    ax.legend(
        [Patch(color=colors(j % 10)) for j in range(len(ids))],
        [i.replace("_", " ") for i in ids],
        fontsize=7,
        loc="upper left",
        bbox_to_anchor=(1.01, 1.0),
        borderaxespad=0.0,
    )
    ax.set_title(
        "(a) score tests of the catalogue's effects per iteration\n(red dashes: the "
        "Bonferroni gate; black edge: the effect named)",
        fontsize=8,
    )
    ax.grid(alpha=0.3, axis="y")
    start = ", ".join(_term_math(t) for t in ex.start_terms) or "none"
    _strobe_panel(
        axes[1], ex.start_verification, "start model", "tab:orange", f"(b) start model ({start})"
    )
    _strobe_panel(
        axes[2],
        ex.final_verification,
        "final model",
        "tab:blue",
        "(c) final model\n(+ "
        + (", ".join(e.replace("_", " ") for e in ex.effects_added) or "nothing")
        + ")",
    )
    fig.suptitle(f"final: {_equation_math(ex.final_model)}", fontsize=8)
    return _save(fig, stem)
