"""Figures of a model-term selection study (drawn on matplotlib Figures: no pyplot, so no
backend is switched for a notebook user).

Runs are pooled over every factor a figure does not show (laws, scenarios, motion noise,
...), so the figures read the same whatever else the study varies:

* ``recovery_noise``: exact-support recovery against force noise, one line per selection
  method, one panel per record length, with Wilson 95 % intervals;
* ``recovery_map``: recovery over force noise x record length, one panel per method (the
  phase-transition picture);
* ``coverage``: the share of true coefficients inside their 95 % intervals (exact supports)
  per method and noise level, against the nominal 95 %;
* ``inclusion``: how often each term was selected, per method and noise level, the true
  terms marked.
"""

from __future__ import annotations

import numpy as np

from discovery.vibroimpact.studies.aggregate import wilson

from .._mpl import PRINT_WIDTH, print_sizes, save
from .figures import terms_math

__all__ = ["study_figures"]


_save = save


def _figure(**kw):
    from matplotlib.figure import Figure

    return Figure(**kw)


def _panels(n, row_height, extra, **kw):
    """``(figure, its n axes)``: the panels three to a row, drawn at the width a report
    prints them and no taller than it prints a figure (their text printed as drawn)."""
    ncols = max(1, min(3, n))
    nrows = -(-max(n, 1) // ncols)
    fig = _figure(figsize=(PRINT_WIDTH, min(6.6, extra + row_height * nrows)), layout="constrained")
    axes = list(fig.subplots(nrows, ncols, squeeze=False, **kw).flat)
    for ax in axes[n:]:
        ax.axis("off")
    return fig, axes[:n]


def _levels(runs, cells, name):
    return sorted({cells[r["cell"]][name] for r in runs}, key=lambda v: (str(type(v)), v))


def _group(runs, cells, **fixed):
    return [r for r in runs if all(cells[r["cell"]][k] == v for k, v in fixed.items())]


def _rate(rs):
    n, k = len(rs), sum(bool(r["exact"]) for r in rs)
    lo, hi = wilson(k, n)
    return (k / n if n else np.nan), lo, hi


def _yerr(p, lo, hi):
    """Error bar lengths below and above ``p`` (never negative; 0 where undefined)."""
    return np.nan_to_num(np.clip([p - lo, hi - p], 0.0, None))


def _pct(x):
    return f"{100 * x:g} %"


def recovery_noise_figure(runs, cells, stem):
    methods = _levels(runs, cells, "selection")
    noises = _levels(runs, cells, "force_noise")
    lengths = _levels(runs, cells, "periods")
    fig, axes = _panels(len(lengths), 2.5, 1.1, sharey=True)
    x = np.arange(len(noises))
    for ax, n_per in zip(axes, lengths, strict=True):
        for j, m in enumerate(methods):
            vals = [
                _rate(_group(runs, cells, selection=m, force_noise=s, periods=n_per))
                for s in noises
            ]
            p, lo, hi = (np.array(v) for v in zip(*vals, strict=True))
            dx = (j - (len(methods) - 1) / 2) * 0.06
            ax.errorbar(x + dx, p, yerr=_yerr(p, lo, hi), marker="o", ms=4, capsize=2, label=m)
        ax.set_xticks(x, [_pct(s) for s in noises])
        ax.set_xlabel("force noise (of the peak force)")
        ax.set_title(f"{n_per} periods recorded")
        ax.set_ylim(-0.05, 1.05)
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("exact support recovered")
    fig.legend(*axes[0].get_legend_handles_labels(), loc="outside lower center", ncols=len(methods))
    fig.suptitle("Recovery of the true support (Wilson 95 % intervals)")
    return _save(fig, stem)


def recovery_map_figure(runs, cells, stem):
    methods = _levels(runs, cells, "selection")
    noises = _levels(runs, cells, "force_noise")
    lengths = _levels(runs, cells, "periods")
    fig, axes = _panels(len(methods), 2.4, 0.5)
    im = None
    for ax, m in zip(axes, methods, strict=True):
        grid = np.full((len(lengths), len(noises)), np.nan)
        for i, n_per in enumerate(lengths):
            for j, s in enumerate(noises):
                rs = _group(runs, cells, selection=m, force_noise=s, periods=n_per)
                if rs:
                    grid[i, j] = _rate(rs)[0]
                    ax.text(
                        j,
                        i,
                        f"{sum(bool(r['exact']) for r in rs)}/{len(rs)}",
                        ha="center",
                        va="center",
                        color="white" if grid[i, j] < 0.5 else "black",
                    )
        im = ax.imshow(grid, origin="lower", vmin=0, vmax=1, cmap="viridis", aspect="auto")
        ax.set_xticks(range(len(noises)), [_pct(s) for s in noises])
        ax.set_yticks(range(len(lengths)), [str(n) for n in lengths])
        ax.set_xlabel("force noise")
        ax.set_title(m)
    axes[0].set_ylabel("periods recorded")
    fig.colorbar(im, ax=list(axes), shrink=0.85, label="recovery")
    return _save(fig, stem)


def coverage_figure(runs, cells, stem):
    methods = _levels(runs, cells, "selection")
    noises = _levels(runs, cells, "force_noise")
    fig = _figure(figsize=(PRINT_WIDTH, 3.6), layout="constrained")
    ax = fig.subplots()
    width = 0.8 / max(len(noises), 1)
    for j, s in enumerate(noises):
        p, lo, hi, lab = [], [], [], []
        for m in methods:
            cov = [
                c
                for r in _group(runs, cells, selection=m, force_noise=s)
                for c in (r.get("coverage") or {}).values()
            ]
            k, n = sum(cov), len(cov)
            a, b = wilson(k, n)
            p.append(k / n if n else np.nan)
            lo.append(a)
            hi.append(b)
            lab.append(n)
        p, lo, hi = np.array(p), np.array(lo), np.array(hi)
        xs = np.arange(len(methods)) + (j - (len(noises) - 1) / 2) * width
        ax.bar(xs, p, width * 0.9, yerr=_yerr(p, lo, hi), capsize=2, label=f"noise {_pct(s)}")
        for xx, n in zip(xs, lab, strict=True):
            if n:
                ax.text(xx, 0.02, str(n), ha="center", va="bottom", fontsize=7, rotation=90)
    if not any((r.get("coverage") or {}) for r in runs):
        ax.text(
            0.5,
            0.5,
            "no coefficient intervals in these runs\n(they come from the "
            "refinement: refine = [true])",
            ha="center",
            va="center",
            transform=ax.transAxes,
        )
    ax.set_xlim(-0.6, len(methods) - 0.4)
    ax.axhline(0.95, color="k", ls="--", lw=1, label="nominal 95 %")
    ax.set_xticks(range(len(methods)), methods)
    ax.set_ylim(0, 1.05)
    ax.set_ylabel("true coefficient inside its 95 % interval")
    ax.set_title("Coverage of the coefficient intervals (exact supports; n at the foot)")
    # beside the axes, not over the bars
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)
    return _save(fig, stem)


def inclusion_figure(runs, cells, stem, truth_terms):
    methods = _levels(runs, cells, "selection")
    noises = _levels(runs, cells, "force_noise")
    ok = [r for r in runs if r["status"] == "ok"]
    terms = sorted({t for r in ok for t in r["selected"]} | set(truth_terms))
    fig, axes = _panels(len(methods), 0.3 * len(terms) + 1.0, 0.4, sharey=True)
    im = None
    for ax, m in zip(axes, methods, strict=True):
        grid = np.full((len(terms), len(noises)), np.nan)
        for j, s in enumerate(noises):
            rs = _group(ok, cells, selection=m, force_noise=s)
            for i, t in enumerate(terms):
                if rs:
                    grid[i, j] = np.mean([t in r["selected"] for r in rs])
        im = ax.imshow(grid, origin="upper", vmin=0, vmax=1, cmap="Blues", aspect="auto")
        ax.set_xticks(range(len(noises)), [_pct(s) for s in noises])
        ax.set_yticks(
            range(len(terms)),
            [terms_math(t) + (" (true)" if t in truth_terms else "") for t in terms],
        )
        ax.set_xlabel("force noise")
        ax.set_title(m)
    fig.colorbar(im, ax=list(axes), shrink=0.85, label="selected in this share of runs")
    return _save(fig, stem)


def study_figures(config, runs, out):
    """Draw the study's figures into ``out``; returns the paths (PNG and PDF of each)."""
    cells = config.cells
    truth = set()
    for r in runs:
        from discovery.vibroimpact.model.law import ForceLaw

        truth |= set(ForceLaw.parse(r["law"]).names)
    paths = []
    with print_sizes():  # drawn at the width they are printed: their text 7 to 8 pt
        paths += recovery_noise_figure(runs, cells, str(out / "recovery_noise"))
        paths += recovery_map_figure(runs, cells, str(out / "recovery_map"))
        if any((r.get("coverage") or {}) for r in runs):  # no intervals: no empty chart
            paths += coverage_figure(runs, cells, str(out / "coverage"))
        paths += inclusion_figure(runs, cells, str(out / "inclusion"), truth)
    return paths
