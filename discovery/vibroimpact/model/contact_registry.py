"""The registry of named contact models: one :class:`ContactModelSpec` a model in
:data:`CONTACT_MODELS`.

A spec holds everything the package knows of its model: the parameters in order (with
their domains, :data:`DOMAINS`), the exponent it fixes, the damping term and the
parameter that sets it, the restitution relation of an impact-scaled model, the model
whose fit starts its own, its force as plain text and as LaTeX, and a line that describes
it.  The models (:class:`~discovery.vibroimpact.model.contact_models.ContactModel`), their
fit, the fit's starts, the reports and the CLI's help read the spec; adding a model is
adding one entry to :data:`CONTACT_MODELS` here.

The shipped models:

======================  =====================================  ===================
name                    force while ``zeta > 0``               parameters
======================  =====================================  ===================
``kelvin-voigt``        ``k z + c dz``                         ``k, c``
``hertz-damper``        ``k z^1.5 + c dz``                     ``k, c``
``hunt-crossley``       ``k z^n + lambda z^n dz``              ``k, n, lambda``
``lankarani-nikravesh`` ``k z^n (1 + 3 (1 - e^2) / 4 dz/v0)``  ``k, n, e``
``flores``              ``k z^n (1 + 8 (1 - e) / (5 e) dz/v0)``  ``k, n, e``
======================  =====================================  ===================

(``dz`` the signed penetration rate, ``v0`` each impact's approach velocity:
:mod:`~discovery.vibroimpact.model.contact_models`.)
"""

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from .law import ForceLaw, Term

__all__ = [
    "ContactModelSpec",
    "CONTACT_MODELS",
    "DOMAINS",
    "N_RANGE",
    "E_RANGE",
    "K_FLOOR",
    "domain_edges",
]

N_RANGE = (0.5, 3.0)  # exponents a fit may reach
E_RANGE = (0.02, 1.0)  # coefficients of restitution a fit may reach
#: each parameter's domain ``(low, high, low_open)``: what a fit may reach (a stiffness stays
#: above 0, the damping at or above it, ``n`` and ``e`` in their ranges)
DOMAINS = {
    "k": (0.0, np.inf, True),
    "c": (0.0, np.inf, False),
    "lambda": (0.0, np.inf, False),
    "n": (*N_RANGE, False),
    "e": (*E_RANGE, False),
}
#: where a stiffness is held above 0 (its open lower bound)
K_FLOOR = 1e-300


def domain_edges(params):
    """Why parameters ``{name: value}`` sit at the edge of what a fit may reach
    (:data:`DOMAINS`): one line per parameter at it, a stiffness at its floor or an exponent
    or a restitution at its range's end (empty when none is)."""
    why = []
    for k, v in params.items():
        lo, hi, open_low = DOMAINS.get(k, (-np.inf, np.inf, False))
        if open_low and not v > 1e-200:  # at (or near) K_FLOOR
            why.append(f"{k} = {v:.3g} sits at its floor")
        elif k in ("n", "e") and (v <= lo * (1 + 1e-9) or (k == "n" and v >= hi * (1 - 1e-9))):
            why.append(f"{k} = {v:.4g} sits at the end of its range [{lo:g}, {hi:g}]")
    return why


@dataclass(frozen=True)
class ContactModelSpec:
    """One named contact model: its parameters, the force it makes, how its fit starts and
    how it is written.

    Attributes
    ----------
    name : str
        What its text and the CLI call it (``"hunt-crossley"``).
    parameters : tuple of str
        Its parameters in order (what a fit varies, what its text gives); each has a
        domain in :data:`DOMAINS`.
    form : str
        The force while ``zeta > 0`` in plain text (``"k z^n + lambda z^n dz"``).
    latex : str
        The same force in LaTeX, in ``\\zeta`` (the reports' table).
    description : str
        One line on the model (its printout).
    fixed_n : float or None
        The exponent of its spring when the model fixes it (``n`` is no parameter then).
    damper : str or None
        The parameter that sets the damping (``c``, ``lambda``, ``e``); None: a spring.
    damper_with_n : bool
        The damping term is ``z^n dz`` (Hunt-Crossley's), else ``dz`` (a dashpot).
    ratio, restitution : callable or None
        An impact-scaled model ``k z^n (1 + r dz / v0)``: its damping ratio ``r`` of a
        coefficient of restitution ``e``, and ``e`` of a ratio ``r >= 0`` (``nan`` where
        it has none).  Every model with them is one force family (the same ``k``, ``n``
        and ``r`` make the same force).
    seeded_by : str or None
        The model whose fit starts this model's (the same force at the record's impact
        velocity, its damping coefficient read as ``lambda``); it is fitted first.
    """

    name: str
    parameters: tuple
    form: str
    latex: str
    description: str
    fixed_n: float | None = None
    damper: str | None = None
    damper_with_n: bool = False
    ratio: Callable | None = field(default=None, repr=False)
    restitution: Callable | None = field(default=None, repr=False)
    seeded_by: str | None = None

    @property
    def impact_scaled(self):
        """Its damping is scaled by each impact's approach velocity ``v0``."""
        return self.ratio is not None

    @property
    def domains(self):
        """``{parameter: (low, high, low_open)}`` in the parameters' order."""
        return {key: DOMAINS[key] for key in self.parameters}

    @property
    def damping_name(self):
        """How its conditions name its damping coefficient."""
        return "k r(e)" if self.impact_scaled else self.damper or "c"

    def params(self, values):
        """``{name: value}`` of its parameters ``values``, with ``n`` (fixed, or 1)."""
        out = dict(zip(self.parameters, values, strict=True))
        out.setdefault("n", 1.0 if self.fixed_n is None else self.fixed_n)
        return out

    def damping(self, p):
        """The coefficient of the law's damping term for the parameters ``p``
        (:meth:`params`): ``c``, ``lambda``, ``k r(e)``; 0 for a spring."""
        if self.damper is None:
            return 0.0
        if self.impact_scaled:
            return p["k"] * self.ratio(p[self.damper])
        return p[self.damper]

    def law(self, p):
        """The :class:`ForceLaw` of the parameters ``p`` (:meth:`params`): the damping in
        loading and unloading, scaled by each impact's ``v0`` for an impact-scaled model."""
        k, n = p["k"], p["n"]
        el, c = Term(n, 0.0), self.damping(p)
        if c == 0:
            return ForceLaw((el,), (k,))
        damp = Term(n, 1.0) if self.damper_with_n else Term(0.0, 1.0)
        return ForceLaw((el, damp), (k, c), (damp,), (c,), impact_scaled=self.impact_scaled)

    def values(self, k, n, d):
        """Its parameters in order from a stiffness ``k``, an exponent ``n`` (unused when
        fixed) and the damper's value ``d`` (unused for a spring)."""
        p = {"k": k, "n": n}
        if self.damper is not None:
            p[self.damper] = d
        return tuple(p[key] for key in self.parameters)

    def __str__(self):
        return f"{self.name}: {self.form} ({', '.join(self.parameters)}): {self.description}"


def _ln_ratio(e):
    return 3.0 * (1.0 - e * e) / 4.0


def _ln_restitution(r):
    return float(np.sqrt(1.0 - 4.0 * r / 3.0)) if r <= 0.75 else float("nan")


def _flores_ratio(e):
    return 8.0 * (1.0 - e) / (5.0 * e)


def _flores_restitution(r):
    return 8.0 / (8.0 + 5.0 * r)


def _registry(*specs):
    return {s.name: s for s in specs}


#: the named contact models, ``{name: spec}`` in the order they are listed and fitted
CONTACT_MODELS = _registry(
    ContactModelSpec(
        "kelvin-voigt",
        ("k", "c"),
        "k z + c dz",
        r"k\zeta + c\dot\zeta",
        "a linear spring and a dashpot",
        fixed_n=1.0,
        damper="c",
    ),
    ContactModelSpec(
        "hertz-damper",
        ("k", "c"),
        "k z^1.5 + c dz",
        r"k\zeta^{1.5} + c\dot\zeta",
        "Hertz's spring and a dashpot",
        fixed_n=1.5,
        damper="c",
    ),
    ContactModelSpec(
        "hunt-crossley",
        ("k", "n", "lambda"),
        "k z^n + lambda z^n dz",
        r"k\zeta^n + \lambda\zeta^n\dot\zeta",
        "a power-law spring damped in proportion to it",
        damper="lambda",
        damper_with_n=True,
    ),
    ContactModelSpec(
        "lankarani-nikravesh",
        ("k", "n", "e"),
        "k z^n (1 + 3 (1 - e^2) / 4 dz/v0)",
        r"k\zeta^n\left(1 + \tfrac{3(1-e^2)}{4}\,\dot\zeta/v_0\right)",
        "Hunt-Crossley's damping set by a coefficient of restitution and each impact's v0",
        damper="e",
        damper_with_n=True,
        ratio=_ln_ratio,
        restitution=_ln_restitution,
        seeded_by="hunt-crossley",
    ),
    ContactModelSpec(
        "flores",
        ("k", "n", "e"),
        "k z^n (1 + 8 (1 - e) / (5 e) dz/v0)",
        r"k\zeta^n\left(1 + \tfrac{8(1-e)}{5e}\,\dot\zeta/v_0\right)",
        "Lankarani-Nikravesh's force with Flores' restitution relation (any e)",
        damper="e",
        damper_with_n=True,
        ratio=_flores_ratio,
        restitution=_flores_restitution,
        seeded_by="hunt-crossley",
    ),
)
