"""How a periodic steady state moves with the law's coefficients.

The orbit's state ``y*`` at the strobe time is a fixed point of the period map,
``Phi^n(y*; c) = y*``, so along each coefficient ``c_j``

    dy*/dc_j = (I - M)^-1 dPhi^n/dc_j

with ``M`` the monodromy matrix; one run with the variational equations gives both ``M``
and ``dPhi^n/dc`` (saltation at every event included, :func:`~.simulation.simulate`'s
``sensitivities``).  A second run from ``y*`` with those derivatives as its start carries
them along the orbit: the force's derivative at fixed time, and every event time's.  From
these follow the derivatives of what a designer reads off an impact (peak force, contact
time, largest penetration, the onset's time) and of the force seen from an impact's onset
(:meth:`OrbitSensitivity.from_onset`, what an output-error fit on a force-only record
needs).
"""

from dataclasses import dataclass, field

import numpy as np

from ..._api._printing import readable
from ...errors import InputError
from .kernel import codes as K
from .kernel.forces import force_partials, rhs_at
from .simulation import kernel_params, simulate

__all__ = ["OrbitSensitivity", "orbit_sensitivity"]


@readable
@dataclass(frozen=True)
class OrbitSensitivity:
    """Derivatives of a periodic orbit along the law's coefficients.

    Attributes
    ----------
    names : tuple of str
        The coefficients (loading terms, then ``"unloading: ..."``).
    coefficients : ndarray of shape (m,)
    dy0 : ndarray of shape (4, m)
        Of the orbit's state at ``t0``.
    t : ndarray of shape (k,)
        Times [s] over two orbits from ``t0``.
    force, dforce, force_rate : ndarrays of shape (k,), (m, k), (k,)
        The force, its derivatives at fixed time and its time derivative ``dF/dt``.
    event_t, event_kind : ndarrays of shape (e,)
    devent_t : ndarray of shape (e, m)
        The events' time derivatives.
    impacts : list of dict
        Per contact (onset to loss): ``onset``, ``peak_force``, ``contact_time``,
        ``max_penetration`` and each one's derivatives (``d_...``, one per coefficient).
    """

    names: tuple
    coefficients: np.ndarray
    dy0: np.ndarray
    t: np.ndarray
    force: np.ndarray
    dforce: np.ndarray
    force_rate: np.ndarray
    event_t: np.ndarray
    event_kind: np.ndarray
    devent_t: np.ndarray
    impacts: list
    scenario: object = field(default=None, repr=False)
    law: object = field(default=None, repr=False)
    steady: object = field(default=None, repr=False)
    tolerances: object = field(default=None, repr=False)

    def from_onset(self, onset, s):
        """``(F, dF/dc)`` at times ``s`` after the onset event ``onset`` (an index into
        the events of the first orbit), the onset moving with the coefficients:
        ``dF/dc(t) + F'(t) dt_on/dc`` at ``t = t_on + s`` for sorted ``0 <= s <=`` one
        orbit, the right limit at ``s = 0`` and the left one at a whole orbit (one more run
        from the orbit's start, sampled at exactly those times)."""
        W = self.scenario.period * self.steady.n_periods
        s = np.clip(np.asarray(s, dtype=float), 1e-9 * W, (1.0 - 1e-9) * W)
        tq = self.event_t[onset] + s
        tr = simulate(
            self.scenario,
            self.law,
            (self.t[0], tq[-1]),
            y0=self.steady.y0,
            t_eval=tq,
            tolerances=self.tolerances,
            sensitivities="coefficients",
            sensitivity_start=self.dy0,
        )
        rate = _force_rate(self.scenario, self.law, tq, tr.y, tr.mode)
        return tr.force, tr.force_sensitivity + np.outer(self.devent_t[onset], rate)

    def elasticities(self):
        """Per impact: ``{quantity: {coefficient: (c / q) dq/dc}}`` (relative change of the
        quantity per relative change of the coefficient)."""
        out = []
        for imp in self.impacts:
            row = {}
            for q in ("peak_force", "contact_time", "max_penetration"):
                v = imp[q]
                row[q] = {
                    n: float(c * d / v) if v else float("nan")
                    for n, c, d in zip(self.names, self.coefficients, imp["d_" + q], strict=True)
                }
            out.append(row)
        return out

    def as_dict(self):
        return {
            "coefficients": dict(zip(self.names, map(float, self.coefficients), strict=True)),
            "impacts": [
                {k: (v.tolist() if isinstance(v, np.ndarray) else v) for k, v in imp.items()}
                for imp in self.impacts
            ],
            "elasticities": self.elasticities(),
        }

    def _lines(self):
        lines = ["orbit sensitivities (relative change per relative change of a coefficient):"]
        for k, row in enumerate(self.elasticities()):
            for q, d in row.items():
                vals = ", ".join(f"{n} {v:+.3f}" for n, v in d.items())
                lines.append(f"  impact {k + 1} {q.replace('_', ' ')}: {vals}")
        return lines


def _force_rate(scenario, law, t, y, mode):
    """``dF/dt`` along the motion (``F_z dzeta/dt + F_v d(dzeta)/dt``) at states ``y``, the
    accelerations from the kernel's own right-hand side."""
    coef, ea, eb, br = law.kernel_arrays()
    p = kernel_params(scenario, law)  # no permanent set: no contact state
    dc = np.empty(coef.size)
    f = np.empty(4)
    out = np.zeros(t.size)
    for i in range(t.size):
        if mode[i] not in (K.LOAD, K.UNLOAD):
            continue
        z, v = y[0, i] - y[2, i], y[1, i] - y[3, i]
        fz, fv = force_partials(mode[i], z, v, coef, ea, eb, br, dc)
        rhs_at(t[i], y[:, i].copy(), mode[i], (p, coef, ea, eb, br), f)
        out[i] = fz * v + fv * (f[1] - f[3])
    return out


def _impacts(t, tr, t_end):
    """Peak force and contact time of each contact (onset to loss) and their derivatives
    (at an interior maximum the derivative at fixed time is the maximum's), and when its
    penetration is largest (the first switch to unloading).

    Parameters
    ----------
    t : ndarray of shape (k,)
        The times [s] ``tr`` was sampled at.
    tr : Trajectory
        A run with coefficient sensitivities (its force, the force's and the events'
        derivatives).
    t_end : float
        End [s] of the first orbit: only its onsets are summarised.
    """
    F, dF = tr.force, tr.force_sensitivity
    ev_t, ev_k, dev = tr.event_t, tr.event_kind, tr.event_time_sensitivity
    out = []
    on = np.flatnonzero((ev_k == K.EV_ONSET) & (ev_t < t_end))  # onsets of the first orbit
    for j in on:
        later = np.flatnonzero((ev_k == K.EV_LOSS) & (ev_t > ev_t[j]))
        if not later.size:
            continue
        e = later[0]
        m = (t > ev_t[j]) & (t < ev_t[e])
        if not m.any():
            continue
        idx = np.flatnonzero(m)
        ip = idx[np.argmax(F[m])]
        turn = np.flatnonzero((ev_k == K.EV_UNLOAD) & (ev_t > ev_t[j]) & (ev_t < ev_t[e]))
        out.append(
            {
                "onset": float(ev_t[j]),
                "d_onset": dev[j].copy(),
                "peak_force": float(F[ip]),
                "d_peak_force": dF[:, ip].copy(),
                "contact_time": float(ev_t[e] - ev_t[j]),
                "d_contact_time": dev[e] - dev[j],
                "t_max_penetration": float(ev_t[turn[0]] if turn.size else t[ip]),
            }
        )
    return out


def orbit_sensitivity(scenario, law, ss, *, impacts=True, points_per_period=4000, tolerances=None):
    """The derivatives of the periodic orbit ``ss`` of ``law`` along its coefficients (see
    the module docstring).

    Parameters
    ----------
    scenario : Scenario
    law : ForceLaw
        Without a permanent set.
    ss : SteadyState
        A periodic steady state of ``law``.
    impacts : bool
        Also sample the orbit (two orbits' worth, ``points_per_period`` per drive period)
        for the impacts' peak force, contact time and largest penetration; without, one
        run gives the start's and the events' derivatives (what
        :meth:`OrbitSensitivity.from_onset` needs: an output-error Jacobian).
    points_per_period : int
    tolerances : Tolerances, optional

    Returns
    -------
    OrbitSensitivity
    """
    if not ss.periodic:
        raise InputError(f"no periodic steady state ({ss.regime}): nothing to differentiate")
    T, n = scenario.period, ss.n_periods
    span = (ss.t0, ss.t0 + n * T)
    first = simulate(scenario, law, span, y0=ss.y0, tolerances=tolerances, sensitivities="all")
    M, P = first.sensitivity[:, :4], first.sensitivity[:, 4:]
    dy0 = np.linalg.solve(np.eye(4) - M, P)
    # the events' derivatives along the orbit: along the start's move and the coefficients
    tau = first.event_time_sensitivity
    out = {
        "names": first.sensitivity_names[4:],
        "coefficients": np.array(law.coefficients + law.unloading_coefficients, dtype=float),
        "dy0": dy0,
        "t": np.array(span),
        "force": np.zeros(2),
        "dforce": np.zeros((P.shape[1], 2)),
        "force_rate": np.zeros(2),
        "event_t": first.event_t,
        "event_kind": first.event_kind,
        "devent_t": tau[:, :4] @ dy0 + tau[:, 4:],
        "impacts": [],
    }
    if impacts:
        out.update(
            _sampled(
                scenario,
                law,
                ss,
                dy0,
                span,
                points_per_period=points_per_period,
                tolerances=tolerances,
            )
        )
    return OrbitSensitivity(**out, scenario=scenario, law=law, steady=ss, tolerances=tolerances)


def _sampled(scenario, law, ss, dy0, span, *, points_per_period, tolerances):
    """Two orbits sampled with their derivatives (a contact under way at ``t0`` ends in the
    second), and each contact of the first orbit's summary."""
    n = ss.n_periods
    span2 = (span[0], span[0] + 2 * (span[1] - span[0]))
    te = np.linspace(*span2, 2 * points_per_period * n + 1)
    tr = simulate(
        scenario,
        law,
        span2,
        y0=ss.y0,
        t_eval=te,
        tolerances=tolerances,
        sensitivities="coefficients",
        sensitivity_start=dy0,
    )
    dev = tr.event_time_sensitivity
    impacts = _impacts(te, tr, span[1])
    for imp in impacts:
        # the largest penetration is where the bodies stop closing (dzeta = 0): its
        # derivative is the penetration's at that fixed time, from a run that ends there
        to = simulate(
            scenario,
            law,
            (ss.t0, imp.pop("t_max_penetration")),
            y0=ss.y0,
            tolerances=tolerances,
            sensitivities="coefficients",
            sensitivity_start=dy0,
        )
        imp["max_penetration"] = float(to.y_final[0] - to.y_final[2])
        imp["d_max_penetration"] = to.sensitivity[0] - to.sensitivity[2]
    return {
        "t": te,
        "force": tr.force,
        "dforce": tr.force_sensitivity,
        "force_rate": _force_rate(scenario, law, te, tr.y, tr.mode),
        "event_t": tr.event_t,
        "event_kind": tr.event_kind,
        "devent_t": dev,
        "impacts": impacts,
    }
