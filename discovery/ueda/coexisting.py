"""Coexisting attractors of Ueda's oscillators: those reached from a grid of initial
states, with the fraction of the grid in each basin (a frozen result)."""

from dataclasses import dataclass

import numpy as np

from .._api._printing import fmt, readable
from .._api._validate import Array, Real, params
from ..numerics.tolerances import Tolerances
from .exponents import Lyapunov
from .regimes import Regime, classify
from .system import UedaSystem

__all__ = ["Basins", "basins"]


@readable
@dataclass(frozen=True)
class Basins:
    """Coexisting attractors found from a grid of initial states.

    Attributes
    ----------
    system : UedaSystem
    x0, v0 : ndarray
        The grid's axes.
    label : ndarray of shape (len(v0), len(x0))
        Index of the attractor each initial state reaches.
    attractors : list of dict
        ``regime``, ``fraction`` (of the grid), ``lyapunov``, ``centre`` and ``points``
        (strobe points of a representative), ``example_y0``.
    """

    system: UedaSystem
    x0: np.ndarray
    v0: np.ndarray
    label: np.ndarray
    attractors: list

    def as_dict(self):
        return {
            "grid": [int(self.x0.size), int(self.v0.size)],
            "x0_range": [float(self.x0[0]), float(self.x0[-1])],
            "v0_range": [float(self.v0[0]), float(self.v0[-1])],
            "attractors": [{k: v for k, v in a.items() if k != "points"} for a in self.attractors],
        }

    def _lines(self):
        out = [
            f"{len(self.attractors)} attractor(s) from a {self.x0.size}x{self.v0.size} grid of "
            f"initial states (x0 {fmt(self.x0[0], 3)} to {fmt(self.x0[-1], 3)}, v0 "
            f"{fmt(self.v0[0], 3)} to {fmt(self.v0[-1], 3)})"
        ]
        for i, a in enumerate(self.attractors):
            out.append(
                f"  {i}: {a.get('regime')}, {100 * float(a.get('fraction', 0)):.1f} % of the "
                f"grid, largest Lyapunov exponent {fmt(a.get('lyapunov'), 3)}"
            )
        return out


@dataclass(frozen=True, eq=False)
class _Reached:
    """What one initial state of the grid reached: its regime, strobe points of shape
    ``(n, 2)``, exponents and the initial state ``(x0, v0)``."""

    regime: Regime
    strobe: np.ndarray
    lyapunov: Lyapunov
    y0: tuple


def _same_attractor(a, b, scale, tol=1e-3):
    """Whether two :class:`_Reached` are the same attractor: the same regime and, for a
    periodic one, the same cycle of strobe points in any phase (to ``tol`` of ``scale``);
    for beat and chaos, the same set of points."""
    reg_a, reg_b = a.regime, b.regime
    a, b = a.strobe, b.strobe
    if reg_a.regime != reg_b.regime:
        return False
    if reg_a.period:  # periodic: the same cycle of points, in any phase
        A, Bp = a[-reg_a.period :] / scale, b[-reg_b.period :] / scale
        return all(np.min(np.max(np.abs(Bp - p), axis=1)) < tol for p in A)
    # beat / chaotic: the same set - the points of each lie as close to the other's as
    # they lie to their own neighbours (median nearest-neighbour distances)
    a, b = a[-400:] / scale, b[-400:] / scale

    def nn(p, q, same=False):
        d = np.sqrt(((p[:, None, :] - q[None, :, :]) ** 2).sum(axis=2))
        if same:
            np.fill_diagonal(d, np.inf)
        return np.median(d.min(axis=1))

    own = max(nn(a, a, True), nn(b, b, True), tol)
    return bool(max(nn(a, b), nn(b, a)) < 3.0 * own)


@params(
    system=UedaSystem,
    x_range=Array(1),
    v_range=Array(1),
    n=Real(1, integer=True),
    transient=Real(0, integer=True),
    periods=Real(1, integer=True),
    tolerances=(Tolerances, None),
)
def basins(
    system,
    x_range=(-1.0, 1.0),
    v_range=(-1.0, 1.0),
    n=10,
    *,
    transient=300,
    periods=200,
    tolerances=None,
):
    """Attractors reached from an ``n x n`` grid of initial states, with basin fractions.

    Parameters
    ----------
    system : UedaSystem
    x_range, v_range : (low, high)
        The grid's extent in ``x`` and ``x'``.
    n : int
        Points per axis.
    transient, periods : int
        Each start's discarded and observed periods (:func:`~discovery.ueda.classify`).
    tolerances : Tolerances, optional

    Returns
    -------
    Basins
    """
    x0 = np.linspace(*x_range, int(n))
    v0 = np.linspace(*v_range, int(n))
    label = np.full((v0.size, x0.size), -1, dtype=int)
    found = []  # _Reached, one per attractor
    scale = system.scales()
    for i, vv in enumerate(v0):
        for j, xx in enumerate(x0):
            reg, lyap, strobe = classify(
                system, (xx, vv), transient=transient, periods=periods, tolerances=tolerances
            )
            new = _Reached(regime=reg, strobe=strobe, lyapunov=lyap, y0=(float(xx), float(vv)))
            for k, old in enumerate(found):
                if _same_attractor(old, new, scale):
                    label[i, j] = k
                    break
            else:
                found.append(new)
                label[i, j] = len(found) - 1
    total = label.size
    atts = []
    for k, r in enumerate(found):
        s = r.strobe
        atts.append(
            {
                "regime": r.regime.regime,
                "fraction": float(np.sum(label == k) / total),
                "lyapunov": r.lyapunov.value,
                "lyapunov_stderr": r.lyapunov.stderr,
                "centre": [float(c) for c in s.mean(axis=0)],
                "example_y0": list(r.y0),
                "points": s[-min(len(s), 400) :],
            }
        )
    return Basins(system=system, x0=x0, v0=v0, label=label, attractors=atts)
