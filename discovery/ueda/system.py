"""Ueda's periodically forced oscillators: the system description.

``x'' - (mu (1 - gamma x^2) - k) x' + x^3 = B cos(nu t)``, state ``(x, v = x')``.

Built-in models (every parameter can be set):

* ``negres`` - the forced negative-resistance oscillator of Ueda and Akamatsu (1981),
  ``x'' - mu (1 - gamma x^2) x' + x^3 = B cos(nu t)``; defaults ``mu = 0.2,
  gamma = 8, B = 0.35, nu = 1.02``: the "broken egg" chaotic attractor;
* ``duffing`` - Ueda's classical oscillator ``x'' + k x' + x^3 = B cos t``; defaults
  ``k = 0.05, B = 7.5`` (published largest Lyapunov exponent about 0.103).
"""

from dataclasses import asdict, dataclass, fields, replace

import numpy as np

from ..errors import InputError

#: codes of the vector fields the compiled kernel integrates (``p[0]`` of its parameter
#: array, :mod:`discovery.ueda._kernel`): Ueda's equation, a discovered polynomial model
UEDA, MODEL = 0.0, 1.0

__all__ = ["UedaSystem", "MODELS"]

MODELS = {
    "negres": {"mu": 0.2, "gamma": 8.0, "k": 0.0, "B": 0.35, "nu": 1.02},
    "duffing": {"mu": 0.0, "gamma": 0.0, "k": 0.05, "B": 7.5, "nu": 1.0},
}
_EQUATION = {
    "negres": "x'' - mu (1 - gamma x^2) x' + x^3 = B cos(nu t)",
    "duffing": "x'' + k x' + x^3 = B cos(nu t)",
}


@dataclass(frozen=True)
class UedaSystem:
    """One oscillator: ``x'' - (mu (1 - gamma x^2) - k) x' + x^3 = B cos(nu t)``.

    The system interface the shared machinery needs: ``n_states``, :meth:`rhs`,
    :meth:`jacobian` (and :meth:`trace`), ``period``, :meth:`scales`, :meth:`params`
    (the compiled kernel's parameter array).  A smooth system: no switching functions.

    Parameters
    ----------
    model : str
        ``"negres"`` or ``"duffing"`` (the name; the parameters decide the equation).
    mu, gamma, k, B, nu : float
        Negative resistance, its amplitude dependence, linear damping, forcing amplitude
        and angular frequency (``nu > 0``).
    """

    model: str = "negres"
    mu: float = 0.2
    gamma: float = 8.0
    k: float = 0.0
    B: float = 0.35
    nu: float = 1.02

    n_states = 2

    def __post_init__(self):
        if self.model not in MODELS:
            raise InputError(f"unknown model {self.model!r}; choose one of {', '.join(MODELS)}")
        for name in ("mu", "gamma", "k", "B", "nu"):
            v = getattr(self, name)
            if not (isinstance(v, int | float | np.floating | np.integer) and np.isfinite(v)):
                raise InputError(f"{name} must be a finite number, got {v!r}")
            object.__setattr__(self, name, float(v))
        if self.nu <= 0:
            raise InputError(f"nu must be > 0 (the forcing's angular frequency), got {self.nu}")
        if self.gamma < 0:
            raise InputError(f"gamma must be >= 0, got {self.gamma}")

    @classmethod
    def from_model(cls, model="negres", **overrides):
        """The built-in model with some parameters replaced (``None`` values ignored)."""
        if model not in MODELS:
            raise InputError(f"unknown model {model!r}; choose one of {', '.join(MODELS)}")
        unknown = set(overrides) - set(MODELS[model])
        if unknown:
            raise InputError(
                f"unknown parameter(s) {', '.join(sorted(unknown))}; the "
                f"parameters are {', '.join(MODELS[model])}"
            )
        params = dict(MODELS[model])
        params.update({k: v for k, v in overrides.items() if v is not None})
        return cls(model=model, **params)

    def with_params(self, **changes):
        return replace(self, **changes)

    @property
    def period(self):
        """Forcing period ``2 pi / nu``: the stroboscopic map samples ``t = 2 pi k / nu``."""
        return 2.0 * np.pi / self.nu

    @property
    def equation(self):
        return _EQUATION[self.model]

    def params(self):
        """The compiled kernel's parameter array: this vector field's code, no divergence
        bound, ``[mu, gamma, k, B, nu]`` (see :mod:`discovery.ueda._kernel`)."""
        return np.array([UEDA, np.inf, self.mu, self.gamma, self.k, self.B, self.nu])

    def scales(self):
        """Characteristic ``(x, v)`` for absolute tolerances and distances: the amplitude
        of the cubic oscillator driven by ``B`` (``x ~ max(1, B^(1/3))``, ``v ~ nu x``)."""
        x = max(1.0, abs(self.B) ** (1.0 / 3.0))
        return np.array([x, x * max(self.nu, 1.0)])

    def rhs(self, t, y):
        """``(x', v')`` at time ``t`` (NumPy; the kernels have their own compiled copy)."""
        x, v = y[0], y[1]
        return np.array(
            [
                v,
                (self.mu * (1 - self.gamma * x * x) - self.k) * v
                - x**3
                + self.B * np.cos(self.nu * t),
            ]
        )

    def jacobian(self, t, y):
        """``d(x', v')/d(x, v)``."""
        x, v = y[0], y[1]
        return np.array(
            [
                [0.0, 1.0],
                [
                    -2.0 * self.mu * self.gamma * x * v - 3.0 * x * x,
                    self.mu * (1 - self.gamma * x * x) - self.k,
                ],
            ]
        )

    def trace(self, x):
        """Trace of the Jacobian, ``mu (1 - gamma x^2) - k`` (the phase-volume rate)."""
        return self.mu * (1 - self.gamma * np.asarray(x) ** 2) - self.k

    def as_dict(self):
        return {**asdict(self), "equation": self.equation, "period": self.period}

    @classmethod
    def from_dict(cls, d):
        """The system of :meth:`as_dict`'s document (its derived keys ignored)."""
        return cls(**{f.name: d[f.name] for f in fields(cls) if f.name in d})
