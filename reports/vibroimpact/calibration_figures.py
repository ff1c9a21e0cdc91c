"""The figure of ``calibrate``: the force each body's motion implies, with the sheet's
machine and with the record's, against the measured force."""

import numpy as np

from .._mpl import PRINT_WIDTH, print_sizes, save, subplots

__all__ = ["calibration_figure"]

#: drive periods shown (the first ones of the record)
PERIODS = 4


def calibration_figure(result, stem):
    """Two panels over the record's first drive periods, every point one test window:
    the measured force averaged over the window (black), and the force the grid frame's
    (top) and the moulding's (bottom) motions imply through their equations of motion,
    with the scenario's machine (orange) and the calibrated one (blue).  Where the sheet is
    off, its points leave the measured ones; the calibrated ones lie on them.

    Parameters
    ----------
    result : Calibration
        A result made by :func:`~discovery.calibrate` (a loaded one has no series).
    stem : str
        Output path without extension (``stem.png`` and ``stem.pdf`` are written).

    Returns
    -------
    list of str
        The two paths, or ``[]`` when the result has no series (nothing calibrated).
    """
    s = result.series
    if s is None:
        return []
    t = np.asarray(s["t"])
    period = result.sheet[0].period
    keep = t <= t[0] + PERIODS * period
    with print_sizes():
        fig, axes = subplots(2, 1, figsize=(PRINT_WIDTH, 5.2), sharex=True, layout="constrained")
        for ax, body, label in (
            (axes[0], "frame", "grid frame: -(m1 (w1'' + g) + c1 w1' + k1 w1 + A sin)"),
            (axes[1], "moulding", "moulding: m2 (w2'' + g)"),
        ):
            measured = (
                "measured F, its sensor's lag removed" if s.get("lag_removed") else "measured F"
            )
            ax.plot(t[keep], s["measured"][keep] / 1e3, "k.-", lw=0.8, ms=3, label=measured)
            ax.plot(
                t[keep],
                s[body]["sheet"][keep] / 1e3,
                "o",
                mfc="none",
                mec="tab:orange",
                ms=4,
                label="implied, scenario's machine",
            )
            ax.plot(
                t[keep],
                s[body]["record"][keep] / 1e3,
                "x",
                c="tab:blue",
                ms=4,
                label="implied, calibrated machine",
            )
            ax.set_ylabel("window mean force [kN]")
            ax.set_title(label)
        fig.legend(
            *axes[0].get_legend_handles_labels(),
            loc="outside upper center",
            ncols=3,
        )
        axes[1].set_xlabel("t [s]")
        return save(fig, stem)
