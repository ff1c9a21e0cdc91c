"""The simulated response of a law: steady state and exact impulse.

To compare with a measurement, the exact impulse is "sampled like the
measurement" with :meth:`~discovery.vibroimpact.data.impulse.Impulse.resampled_like`: evaluated at
the measurement's sample times since its onset, and its support taken with the
measurement's contact threshold.
"""

from dataclasses import dataclass

import numpy as np

from ..._api._printing import readable
from ..._api._validate import Instance, Real, params
from ...errors import InputError
from ..data.impulse import Impulse
from ..model.law import ForceLaw
from ..model.scenario import Scenario
from . import Tolerances
from .kernel import codes as K
from .simulation import simulate
from .steady_states import steady_state

__all__ = ["Response", "response", "impulse_from_steady_state"]


@readable
@dataclass(frozen=True)
class Response:
    """A law's steady state and its impulse (``None`` if nonperiodic or no contact)."""

    steady: object
    impulse: Impulse | None

    @property
    def regime(self):
        return self.steady.regime

    def like(self, measured):
        """The impulse sampled like ``measured`` (``None`` if there is none)."""
        if self.impulse is None:
            return None
        return self.impulse.resampled_like(measured)

    def _lines(self):
        head = self.steady._lines()[0]
        impulse = self.impulse._lines()[0] if self.impulse is not None else "no impulse"
        return [f"response: {head}", f"  {impulse}"]


@params(
    scenario=Scenario,
    law=ForceLaw,
    tolerances=(Tolerances, None),
    points_per_period=Real(16, integer=True),
)
def response(scenario, law, *, tolerances=None, points_per_period=2000, **steady_kwargs):
    """Steady state of ``law`` in ``scenario`` and its exact impulse.

    Parameters
    ----------
    scenario : Scenario
    law : ForceLaw
    tolerances : Tolerances, optional
    points_per_period : int
        Resolution of the exact impulse.
    **steady_kwargs
        Passed to :func:`~discovery.vibroimpact.dynamics.steady_states.steady_state`.

    Returns
    -------
    Response
    """
    ss = steady_state(scenario, law, tolerances=tolerances, **steady_kwargs)
    if not ss.periodic:
        return Response(ss, None)
    return Response(ss, impulse_from_steady_state(scenario, law, ss, points_per_period, tolerances))


# ------------------------------------------------ the exact impulse of a steady state
def _orbit_events(scenario, law, ss, tolerances):
    T = scenario.period
    t0 = ss.t0
    n = ss.n_periods
    tr = simulate(
        scenario,
        law,
        (t0, t0 + n * T),
        y0=ss.y0,
        tolerances=tolerances,
        t_eval=np.linspace(t0, t0 + n * T, 400 * n + 1),
        zeta_max0=ss.zeta_max0,
        impact_v0=ss.impact_v0,
    )
    return tr


def _main_onset(tr, law, scenario, n):
    """Index (into tr events) of the onset followed by the largest impulse."""
    onsets = np.flatnonzero(tr.event_kind == K.EV_ONSET)
    if len(onsets) == 0:
        return None
    if len(onsets) == 1:
        return onsets[0]
    best, best_j = -1.0, onsets[0]
    times = tr.event_t[onsets]
    for j, t_on in zip(onsets, times, strict=True):
        later = times[times > t_on]
        t_end = later[0] if len(later) else t_on + n * scenario.period
        m = (tr.t >= t_on) & (tr.t < t_end)
        imp = np.trapezoid(tr.force[m], tr.t[m]) if m.sum() > 1 else 0.0
        if imp > best:
            best, best_j = imp, j
    return best_j


@params(
    scenario=Scenario,
    law=ForceLaw,
    ss=Instance("discovery.vibroimpact.dynamics.steady_states", "SteadyState"),
    tolerances=(Tolerances, None),
    points_per_period=Real(16, integer=True),
)
def impulse_from_steady_state(scenario, law, ss, points_per_period=2000, tolerances=None):
    """The exact steady-state impulse of a periodic orbit.

    The cycle is integrated again from the located onset, so ``F(0+)`` and every
    later event are exact (to integrator tolerance), with one-sided limits at jumps.

    Parameters
    ----------
    scenario, law
        As used for ``ss``.
    ss : SteadyState
        A periodic steady state (``ss.periodic`` must be true).
    points_per_period : int
        Uniform output points per drive period (events are added to them).
    tolerances : Tolerances, optional

    Returns
    -------
    Impulse
        ``None`` when the orbit has no contact onset (the moulding never leaves the
        grid, or never touches it).
    """
    if not ss.periodic:
        raise InputError(f"no periodic steady state ({ss.regime}); an impulse needs one")
    n, T = ss.n_periods, scenario.period
    tr = _orbit_events(scenario, law, ss, tolerances)
    j = _main_onset(tr, law, scenario, n)
    if j is None:
        return None
    t_on, y_on, mode_on = tr.event_t[j], tr.event_y[j], tr.event_modes[j, 1]
    W = n * T
    grid = np.linspace(0.0, W, points_per_period * n + 1)
    tr2 = simulate(
        scenario,
        law,
        (t_on, t_on + W),
        y0=y_on,
        mode0=mode_on,
        t_eval=t_on + grid,
        tolerances=tolerances,
    )
    F = tr2.force  # at t_on the kernel reports the mode after the onset: F(0+)
    # periodicity: F(W-) = F(0-), the force just before the onset (the kernel may have
    # crossed the next onset a whisker before W)
    F[-1] = tr.event_forces(law)[j, 0]
    # insert events (left and right limits) into the grid
    ev_rel = tr2.event_t - t_on
    lim = tr2.event_forces(law)
    # events within a whisker of W belong to the next cycle (orbit closes to ~1e-9 T)
    keep = (ev_rel > 0) & (ev_rel < W * (1.0 - 1e-6))
    t_all = np.concatenate([grid, ev_rel[keep], ev_rel[keep]])
    f_all = np.concatenate([F, lim[keep, 0], lim[keep, 1]])
    rank = np.concatenate([np.full(grid.size, 1), np.zeros(keep.sum()), np.full(keep.sum(), 2)])
    order = np.lexsort((rank, t_all))
    t_all, f_all, rank = t_all[order], f_all[order], rank[order]
    # a grid point that coincides with an event time is replaced by its limits
    drop = (rank == 1) & np.isin(t_all, ev_rel[keep])
    t_all, f_all = t_all[~drop], f_all[~drop]
    # the last point closes the cycle with the left limit at W
    support = _support_from_events(ev_rel[keep], tr2.event_modes[keep], W)
    on = tr2.event_kind == K.EV_ONSET
    onsets = np.concatenate([[0.0], ev_rel[on & keep]])
    return Impulse(
        t=t_all, F=f_all, duration=W, support=support, n_periods=n, onset=t_on, onsets=onsets
    )


def _support_from_events(ev_rel, modes, W):
    """Intervals where the contact force is on: mode LOAD/UNLOAD."""
    on = True
    start = 0.0
    out = []
    for t, (m0, m1) in zip(ev_rel, modes, strict=True):
        was = m0 in (K.LOAD, K.UNLOAD)
        now = m1 in (K.LOAD, K.UNLOAD)
        if was and not now and on:
            out.append((start, t))
            on = False
        elif now and not was and not on:
            start, on = t, True
    if on:
        out.append((start, W))
    return np.array(out, dtype=float).reshape(-1, 2)


# -------------------------------------------------------------------- samples
