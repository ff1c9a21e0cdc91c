"""The equation the Ueda workflows discover: ``x'' = sum_j c_j x^i x'^j + f B cos(nu t)``
over the cubic polynomial library, and its simulation.

:class:`ForcedPolynomial` is an equation (simulable, printable as text, sympy and LaTeX);
:func:`simulate_model` integrates it with the compiled Dormand-Prince kernel of the general
cubic polynomial right-hand side (:mod:`discovery.ueda._kernel`) and returns its strobe
points and largest two Lyapunov exponents.
"""

from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..numerics.tolerances import Tolerances
from . import _kernel as UK
from .system import MODEL

__all__ = ["MONOMIALS", "TERMS", "FORCING", "ForcedPolynomial", "simulate_model"]

#: exponents ``(i, j)`` of the library terms ``x^i x'^j`` (degree <= 3)
MONOMIALS = ((0, 0), (1, 0), (0, 1), (2, 0), (1, 1), (0, 2), (3, 0), (2, 1), (1, 2), (0, 3))
TERMS = ("1", "x", "x'", "x^2", "x x'", "x'^2", "x^3", "x^2 x'", "x x'^2", "x'^3")
FORCING = "B cos(nu t)"


@dataclass(frozen=True)
class ForcedPolynomial:
    """``x'' = sum_j coefficients[j] x^i x'^j (MONOMIALS[j]) + forcing B cos(nu t)``.

    Attributes
    ----------
    coefficients : tuple of 10 floats
        In the order of :data:`TERMS`.
    B, nu : float
        The known forcing (``nu > 0``).
    forcing : float
        Coefficient of ``B cos(nu t)`` (1 for the true equation).
    """

    coefficients: tuple
    B: float
    nu: float
    forcing: float = 1.0

    n_states = 2

    def __post_init__(self):
        c = tuple(float(v) for v in np.asarray(self.coefficients, dtype=float).ravel())
        if len(c) != len(MONOMIALS) or not all(np.isfinite(c)):
            raise InputError(f"need {len(MONOMIALS)} finite coefficients ({', '.join(TERMS)})")
        object.__setattr__(self, "coefficients", c)
        for name in ("B", "nu", "forcing"):
            v = float(getattr(self, name))
            if not np.isfinite(v):
                raise InputError(f"{name} must be finite, got {v}")
            object.__setattr__(self, name, v)
        if self.nu <= 0:
            raise InputError(f"nu must be > 0, got {self.nu}")

    @classmethod
    def from_system(cls, system):
        """The :class:`UedaSystem`'s equation ``x'' = (mu - k) x' - mu gamma x^2 x' - x^3
        + B cos(nu t)``."""
        c = np.zeros(len(MONOMIALS))
        c[TERMS.index("x'")] = system.mu - system.k
        c[TERMS.index("x^2 x'")] = -system.mu * system.gamma
        c[TERMS.index("x^3")] = -1.0
        return cls(tuple(c), system.B, system.nu, 1.0)

    @classmethod
    def from_terms(cls, terms, B, nu, forcing=1.0):
        """From ``{term: coefficient}`` (names of :data:`TERMS`)."""
        c = np.zeros(len(MONOMIALS))
        for k, v in terms.items():
            if k not in TERMS:
                raise InputError(f"unknown term {k!r}; the terms are {', '.join(TERMS)}")
            c[TERMS.index(k)] = v
        return cls(tuple(c), B, nu, forcing)

    @property
    def period(self):
        return 2.0 * np.pi / self.nu

    @property
    def terms(self):
        """``{term: coefficient}`` of the nonzero terms."""
        return {n: c for n, c in zip(TERMS, self.coefficients, strict=True) if c != 0.0}

    def params(self):
        """The compiled kernel's parameter array: the polynomial's code, the divergence
        bound 1e6 on ``|x|`` and ``|x'|``, ``[c_0..c_9, forcing * B, nu]`` (see
        :mod:`discovery.ueda._kernel`)."""
        return np.array([MODEL, 1e6, *self.coefficients, self.forcing * self.B, self.nu])

    def scales(self):
        x = max(1.0, abs(self.forcing * self.B) ** (1.0 / 3.0))
        return np.array([x, x * max(self.nu, 1.0)])

    def accel(self, t, x, v):
        a = self.forcing * self.B * np.cos(self.nu * np.asarray(t))
        for (i, j), c in zip(MONOMIALS, self.coefficients, strict=True):
            if c:
                a = a + c * np.asarray(x) ** i * np.asarray(v) ** j
        return a

    def rhs(self, t, y):
        return np.array([y[1], self.accel(t, y[0], y[1])])

    def sympy(self, digits=4):
        """``Eq(x''(t), ...)`` with the coefficients rounded to ``digits`` significant
        digits."""
        import sympy as sp

        t = sp.Symbol("t")
        x = sp.Function("x")(t)
        v = x.diff(t)
        B, nu = sp.Symbol("B"), sp.Symbol("nu")
        rhs = 0
        for (i, j), c in zip(MONOMIALS, self.coefficients, strict=True):
            if c:
                val = float(f"{c:.{digits}g}")
                # a unit coefficient as the integer: "- x^3", not "- 1.0 x^3"
                k = sp.Integer(int(val)) if abs(val) == 1.0 else sp.Float(val, digits)
                rhs += k * x**i * v**j
        f = sp.Float(float(f"{self.forcing:.{digits}g}"), digits)
        rhs += (f if self.forcing != 1.0 else 1) * B * sp.cos(nu * t)
        return sp.Eq(x.diff(t, 2), rhs)

    def latex(self, digits=4):
        import sympy as sp

        return sp.latex(self.sympy(digits))

    def text(self, digits=4):
        """The equation as readable text: ``x'' = 0.2 x' - x^3 - 1.6 x^2 x' + B cos(nu t)``
        (coefficients to ``digits`` significant digits)."""
        parts = []
        for name, c in zip(TERMS, self.coefficients, strict=True):
            if c:
                mag = f"{abs(c):.{digits}g}"
                body = name if name != "1" else mag
                if name != "1" and mag != "1":
                    body = f"{mag} {name}"
                parts.append(("- " if c < 0 else "+ ") + body)
        f = f"{abs(self.forcing):.{digits}g}"
        parts.append(
            ("- " if self.forcing < 0 else "+ ") + ("" if f == "1" else f + " ") + "B cos(nu t)"
        )
        rhs = " ".join(parts)
        return "x'' = " + (rhs[2:] if rhs.startswith("+ ") else "-" + rhs[2:])

    def __str__(self):
        return self.text()

    def as_dict(self):
        return {"terms": self.terms, "forcing": self.forcing, "B": self.B, "nu": self.nu}

    @classmethod
    def from_dict(cls, d):
        """The equation of :meth:`as_dict`'s document (``None`` for ``None``)."""
        return None if d is None else cls.from_terms(d["terms"], d["B"], d["nu"], d["forcing"])


def simulate_model(model, y0, t0=0.0, *, transient=200, periods=2000, batches=20, tolerances=None):
    """Integrate ``model`` (a :class:`ForcedPolynomial`) from ``y0`` at ``t0``: after
    ``transient`` periods, ``periods`` strobe points (at ``t0 + k T``) and the largest
    two Lyapunov exponents (variational equations, batch-means errors).

    Returns ``(strobe, Lyapunov)``; raises :class:`IntegrationError` when the solution
    blows up (``|x|`` or ``|x'|`` above 1e6).
    """
    from ._runs import check
    from ._runs import control as _control
    from .exponents import Lyapunov

    tol = tolerances or Tolerances.default()
    T = model.period
    atol = tol.atol(model.scales())
    hmax = T * tol.hmax_fraction
    p = model.params()
    y = np.asarray(y0, dtype=float).copy()
    if transient > 0:
        status, t, y, _, _ = UK.strobe_run(
            float(t0),
            y,
            p,
            T,
            int(transient),
            0,
            _control(tol, atol, hmax, transient),
            (np.empty(0), np.empty((2, 0))),
            np.empty((0, 2)),
        )
        check(status, t, "the discovered equation")
    n = int(periods)
    logs, trace, strobe = np.empty((n, 2)), np.empty(n), np.empty((n, 2))
    t_start = float(t0) + int(transient) * T
    status, t, _, _ = UK.variational_run(
        t_start,
        y,
        p,
        T,
        n,
        _control(tol, atol, hmax, n),
        tol.atol_variational,
        (logs, trace, strobe),
    )
    check(status, t, "the discovered equation")
    return strobe, Lyapunov.from_logs(logs, trace, T, batches=batches, rtol=tol.rtol)
