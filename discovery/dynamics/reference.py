"""Independent slow path: scipy ``solve_ivp`` restarted at every contact event.

Written separately from the compiled kernel (its own right-hand side, force
evaluation and mode logic in plain numpy) so that agreement between the two is
evidence, not tautology.  Used by the tests and the benchmarks only.
"""

import numpy as np
from scipy.integrate import solve_ivp

from ..errors import IntegrationError

__all__ = ["reference_simulate"]


def _poly(law, z, zd):
    return float(sum(c * np.sign(z) ** (t.a > 0) * abs(z) ** t.a * np.sign(zd) ** (t.b > 0)
                     * abs(zd) ** t.b for c, t in zip(law.coefficients, law.terms, strict=True)))


def _force(law, mode, z, v):
    if mode == "load":
        return _poly(law, z, v)
    if mode == "unload":
        return _poly(law, z, 0.0)
    return 0.0


def _mode_of(law, y):
    z, v = y[0] - y[2], y[1] - y[3]
    if z < 0 or (z == 0 and v <= 0):
        return "free"
    if v > 0:
        return "load" if _poly(law, max(z, 0.0), v) >= 0 else "clipped"
    return "unload" if _poly(law, z, 0.0) > 0 else "clipped"


def _events(law, mode):
    """(function, direction, next-mode rule) for each switching surface of a mode."""
    zeta = lambda t, y: y[0] - y[2]  # noqa: E731
    dz = lambda t, y: y[1] - y[3]  # noqa: E731
    out = []
    if mode == "free":
        out.append((zeta, 1.0, "onset"))
    else:
        out.append((zeta, -1.0, "loss"))
    if mode == "load":
        out += [(dz, -1.0, "unload"),
                (lambda t, y: _poly(law, y[0] - y[2], y[1] - y[3]), -1.0, "release")]
    elif mode == "unload":
        out += [(dz, 1.0, "reload"), (lambda t, y: _poly(law, y[0] - y[2], 0.0), -1.0, "release")]
    elif mode == "clipped":
        out.append((lambda t, y: _poly(law, max(y[0] - y[2], 0.0), max(y[1] - y[3], 0.0)), 1.0,
                    "resume"))
    return out


def _after(law, kind, y):
    z, v = max(y[0] - y[2], 0.0), y[1] - y[3]
    if kind == "loss":
        return "free"
    if kind == "release":
        return "clipped"
    if kind == "resume":  # P crossed to positive: the force is on again
        return "load" if v > 0 else "unload"
    if kind == "unload" or (kind in ("onset", "resume") and v <= 0):
        return "unload" if _poly(law, z, 0.0) >= 0 else "clipped"
    return "load" if _poly(law, z, max(v, 0.0)) >= 0 else "clipped"


def reference_simulate(scenario, law, t_span, y0=None, t_eval=None, rtol=1e-10, atol=None,
                       method="DOP853", max_events=100_000):
    """Simulate with scipy, restarting at events.

    Returns
    -------
    dict
        ``t``, ``y`` (4, n), ``force`` at ``t_eval``; ``events`` list of
        ``(t, kind, y)``; ``y_final``; ``nfev``.
    """
    m1, m2, k1, c1, A, om, g = scenario.params()
    y = scenario.initial_state() if y0 is None else np.array(y0, dtype=float)
    if atol is None:
        x, v = scenario.scales()
        atol = rtol * 1e-3 * np.array([x, v, x, v])
    t, t1 = float(t_span[0]), float(t_span[1])
    te = np.zeros(0) if t_eval is None else np.asarray(t_eval, dtype=float)
    out_y = np.full((4, te.size), np.nan)
    out_f = np.full(te.size, np.nan)
    mode = _mode_of(law, y)
    events, nfev = [], 0
    while t < t1:
        def rhs(tt, yy, mode=mode):
            f = _force(law, mode, yy[0] - yy[2], yy[1] - yy[3])
            return [yy[1], -(c1 * yy[1] + k1 * yy[0] + A * np.sin(om * tt) + m1 * g + f) / m1,
                    yy[3], f / m2 - g]

        evs = _events(law, mode)
        fns = []
        for fn, direction, _ in evs:
            def ev(tt, yy, fn=fn):
                return fn(tt, yy)
            ev.terminal, ev.direction = True, direction
            fns.append(ev)
        sol = solve_ivp(rhs, (t, t1), y, method=method, rtol=rtol, atol=atol, events=fns,
                        dense_output=True, max_step=scenario.period * 0.02)
        nfev += sol.nfev
        if sol.status == -1:
            raise IntegrationError(f"reference integration failed: {sol.message}")
        t_end = sol.t[-1]
        mask = (te >= t) & (te <= t_end)
        if mask.any():
            ys = sol.sol(te[mask])
            out_y[:, mask] = ys
            out_f[mask] = [_force(law, mode, w1 - w2, v1 - v2) for w1, v1, w2, v2 in ys.T]
        y = sol.y[:, -1].copy()
        if sol.status == 1:
            fired = [i for i, tev in enumerate(sol.t_events) if len(tev)]
            i = min(fired, key=lambda i: (sol.t_events[i][0], i))
            kind = evs[i][2]
            events.append((t_end, kind, y.copy()))
            mode = _after(law, kind, y)
            if len(events) > max_events:
                raise IntegrationError("reference integration: too many events")
        t = t_end
    return {"t": te, "y": out_y, "force": out_f, "events": events, "y_final": y, "nfev": nfev}
