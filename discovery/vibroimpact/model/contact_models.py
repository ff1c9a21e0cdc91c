"""The contact models engineers name, each a :class:`ForceLaw` with physical parameters.

======================  =====================================  ===================
name                    force while ``zeta > 0``               parameters
======================  =====================================  ===================
``kelvin-voigt``        ``k z + c dz``                         ``k, c``
``hertz-damper``        ``k z^1.5 + c dz``                     ``k, c``
``hunt-crossley``       ``k z^n + lambda z^n dz``              ``k, n, lambda``
``lankarani-nikravesh`` ``k z^n (1 + 3 (1 - e^2) / 4 dz/v0)``  ``k, n, e``
``flores``              ``k z^n (1 + 8 (1 - e) / (5 e) dz/v0)``  ``k, n, e``
======================  =====================================  ===================

``dz`` is the signed penetration rate: the damping acts in loading and in unloading (the
law's unloading terms, :mod:`~discovery.vibroimpact.model.law`), and the force is never
adhesive (clipped at 0).  ``v0`` is each impact's own approach velocity, the penetration
rate at the contact's onset (the law's ``impact_scaled`` flag: the kernel and the scipy
path keep it per contact).  Lankarani-Nikravesh and Flores are one force family,
``k z^n (1 + r dz / v0)``: a record fixes the ratio ``r``, and each model reads its own
coefficient of restitution ``e`` from it (Lankarani-Nikravesh only up to ``r = 3/4``).
The paper's conditions (3) and (4) hold by construction; (5) (no effect of a negative
rate) does not, on purpose (damping while unloading); (6) (dissipativity) holds for
``c, lambda >= 0`` and ``e`` in ``(0, 1]``.

Text form: ``"hunt-crossley: k=2e9, n=1.5, lambda=3e9"``, ``"flores: k=2e9, n=1.5,
e=0.6"``, ``"kelvin-voigt: k=2e8, c=1e6"`` (:func:`parse_model`).
"""

import difflib
import re
from dataclasses import dataclass

import numpy as np

from ..._validate import Real, Text, check
from ...errors import InputError
from .law import ForceLaw, Term

__all__ = [
    "MODELS",
    "ContactModel",
    "parse_model",
    "parse_law",
    "is_model_text",
    "restitution_ratio",
    "same_force",
]

#: the models, each with its parameters in order and whether ``n`` is its own
MODELS = {
    "kelvin-voigt": ("k", "c"),
    "hertz-damper": ("k", "c"),
    "hunt-crossley": ("k", "n", "lambda"),
    "lankarani-nikravesh": ("k", "n", "e"),
    "flores": ("k", "n", "e"),
}
_FIXED_N = {"kelvin-voigt": 1.0, "hertz-damper": 1.5}
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


def restitution_ratio(name, e):
    """The damping ratio ``r = lambda v0 / k`` a model gives to a coefficient of
    restitution ``e``."""
    if name == "lankarani-nikravesh":
        return 3.0 * (1.0 - e * e) / 4.0
    return 8.0 * (1.0 - e) / (5.0 * e)


def restitution_from_ratio(name, r):
    """The coefficient of restitution a ratio ``r`` means for a model (``nan`` where the
    model has none: Lankarani-Nikravesh beyond ``r = 3/4``)."""
    r = max(float(r), 0.0)
    if name == "lankarani-nikravesh":
        return float(np.sqrt(1.0 - 4.0 * r / 3.0)) if r <= 0.75 else float("nan")
    return 8.0 / (8.0 + 5.0 * r)


#: the models that are one force family ``k z^n (1 + r dz / v0)``, each reading ``e`` from ``r``
_ONE_FAMILY = ("lankarani-nikravesh", "flores")


def same_force(name, parameters):
    """``(other model, its parameters)`` making exactly the same force as model ``name``
    with ``parameters`` at every impact velocity, or ``None``.

    Lankarani-Nikravesh and Flores are one family: the same ``k``, ``n`` and ratio
    ``r`` give the same force, so no record, at any operating point, can tell them apart.
    A Flores model whose ``r`` exceeds ``3/4`` (``e < 8/11.75``) has no Lankarani-Nikravesh
    counterpart.
    """
    if name not in _ONE_FAMILY:
        return None
    other = _ONE_FAMILY[1 - _ONE_FAMILY.index(name)]
    e = restitution_from_ratio(other, restitution_ratio(name, float(parameters["e"])))
    if not np.isfinite(e):
        return None
    return other, {"k": float(parameters["k"]), "n": float(parameters["n"]), "e": e}


@dataclass(frozen=True)
class ContactModel:
    """A named contact model with its parameters (SI units: ``k`` N/m^n, ``c`` N s/m,
    ``lambda`` N s/m^(n+1), ``e`` and ``n`` without unit).

    It is also what :func:`discovery.identify` fits (``coefficients``, ``names``,
    ``with_coefficients``, ``law``): the parameters themselves, by differences of full
    simulations (``exact_jacobian = False``).
    """

    name: str
    values: tuple

    exact_jacobian = False

    def __post_init__(self):
        check("ContactModel: name", self.name, Text())
        check("ContactModel: values", self.values, (tuple, list))
        for v in self.values:
            check("ContactModel: each of values", v, Real())
        if self.name not in MODELS:
            raise InputError(
                f"unknown contact model {self.name!r}; the models: {', '.join(MODELS)}"
            )
        vals = tuple(float(v) for v in self.values)
        if len(vals) != len(MODELS[self.name]) or not all(np.isfinite(vals)):
            raise InputError(
                f"{self.name} takes {len(MODELS[self.name])} finite parameters "
                f"({', '.join(MODELS[self.name])}); got {self.values!r}"
            )
        object.__setattr__(self, "values", vals)
        p = self.params
        if p["k"] <= 0:
            raise InputError(f"{self.name}: the stiffness k must be > 0; got {p['k']:g}")
        if not N_RANGE[0] <= p["n"] <= N_RANGE[1]:
            raise InputError(f"{self.name}: the exponent n must be in {N_RANGE}; got {p['n']:g}")
        if "e" in p and not E_RANGE[0] <= p["e"] <= E_RANGE[1]:
            raise InputError(
                f"{self.name}: the coefficient of restitution e must be in {E_RANGE}; "
                f"got {p['e']:g}"
            )
        for key in ("c", "lambda"):
            if p.get(key, 0.0) < 0:
                raise InputError(
                    f"{self.name}: the damping {key} must be >= 0 (condition (6)); got {p[key]:g}"
                )

    # ----------------------------------------------------------- parameters
    @property
    def params(self):
        """``{name: value}``, with ``n`` for every model (fixed for two of them)."""
        out = dict(zip(MODELS[self.name], self.values, strict=True))
        out.setdefault("n", _FIXED_N.get(self.name, 1.0))
        return out

    @property
    def coefficients(self):
        """The parameters in the model's order (what a fit varies)."""
        return self.values

    @property
    def names(self):
        """The parameters' names, in order."""
        return list(MODELS[self.name])

    def with_coefficients(self, values):
        """The model with new parameters (``n`` and ``e`` clipped to the ranges a fit may
        reach, the damping to >= 0), so a fit's trial step stays a model."""
        out = []
        for key, v in zip(MODELS[self.name], values, strict=True):
            lo, hi, open_low = DOMAINS[key]
            out.append(min(max(float(v), K_FLOOR if open_low else lo), hi))
        return ContactModel(self.name, tuple(out))

    # ----------------------------------------------------------------- law
    @property
    def law(self):
        """The model as a :class:`ForceLaw` (damping in loading and unloading)."""
        p = self.params
        k, n = p["k"], p["n"]
        if self.name in _FIXED_N:
            el, damp, c = Term(n, 0.0), Term(0.0, 1.0), p["c"]
        else:
            el, damp = Term(n, 0.0), Term(n, 1.0)
            c = (
                p["lambda"]
                if self.name == "hunt-crossley"
                else k * restitution_ratio(self.name, p["e"])
            )
        if c == 0:
            return ForceLaw((el,), (k,))
        return ForceLaw(
            (el, damp),
            (k, c),
            (damp,),
            (c,),
            impact_scaled=self.name in ("lankarani-nikravesh", "flores"),
        )

    def apply(self, scenario, record=None):
        """The scenario ``record`` is compared with: unchanged (a model changes no machine
        parameter)."""
        return scenario

    def observe(self):
        """No observation model."""
        return None

    def free_effects(self):
        return []  # no parameter beyond the model's own (identify's bounds)

    def conditions(self):
        """The paper's conditions (3)-(6) for this model: ``{"(3)": {"holds": bool, "why":
        str}, ...}`` (analytic: each follows from the model's form and its parameters)."""
        p = self.params
        if self.name in ("lankarani-nikravesh", "flores"):
            damping, what = (
                self.law.coefficients[-1] if len(self.law.coefficients) > 1 else 0.0,
                "k r(e)",
            )
        else:
            damping, what = p.get("c", p.get("lambda", 0.0)), "c" if "c" in p else "lambda"
        return {
            "(3)": {"holds": True, "why": "no force without contact (F = 0 for zeta <= 0)"},
            "(4)": {"holds": True, "why": "never adhesive (the force is clipped at 0)"},
            "(5)": {
                "holds": damping == 0,
                "why": "the damping also acts while the bodies separate (dzeta < 0): the "
                "model's hysteresis, outside the paper's condition on purpose"
                if damping
                else "no damping: a negative rate has no effect",
            },
            "(6)": {
                "holds": damping >= 0,
                "why": f"dissipative: F(zeta, zd) >= F(zeta, 0) for zd >= 0 as {what} = "
                f"{damping:.4g} >= 0",
            },
        }

    # ----------------------------------------------------------------- text
    def to_text(self):
        """Text that :func:`parse_model` reads back to the same model."""
        return f"{self.name}: " + ", ".join(
            f"{k}={v!r}" for k, v in zip(MODELS[self.name], self.values, strict=True)
        )

    def format(self, digits=4):
        return f"{self.name}: " + ", ".join(
            f"{k}={v:.{digits}g}" for k, v in zip(MODELS[self.name], self.values, strict=True)
        )

    def __str__(self):
        return self.format()

    def as_dict(self):
        return {
            "model": self.name,
            "parameters": dict(zip(MODELS[self.name], self.values, strict=True)),
            "law": self.law.to_text(),
            "text": self.to_text(),
        }


def is_model_text(text):
    """True when ``text`` names a contact model (``"<model>: k=..., ..."``)."""
    return isinstance(text, str) and text.partition(":")[0].strip().lower() in MODELS


def parse_model(text):
    """A :class:`ContactModel` from text like ``"hunt-crossley: k=2e9, n=1.5, lambda=3e9"``
    (every parameter of the model, once, in any order)."""
    name, sep, rest = text.partition(":")
    name = name.strip().lower()
    if not sep or name not in MODELS:
        raise InputError(
            f"{text!r} names no contact model; give '<model>: k=..., ...' with a model of "
            f"{', '.join(MODELS)}"
        )
    got = {}
    for part in rest.split(","):
        key, eq, value = part.partition("=")
        key = key.strip().lower()
        if not eq or key not in MODELS[name] or key in got:
            raise InputError(
                f"{text!r}: {name} takes {', '.join(f'{k}=<number>' for k in MODELS[name])} "
                "once each, e.g. 'hunt-crossley: k=2e9, n=1.5, lambda=3e9'"
            )
        try:
            if not value.isascii():  # float() reads full-width digits; the law grammar not
                raise ValueError
            got[key] = float(value)
        except ValueError:
            raise InputError(f"{text!r}: {key} needs a number, got {value.strip()!r}") from None
    missing = [k for k in MODELS[name] if k not in got]
    if missing:
        raise InputError(f"{text!r}: {name} needs {', '.join(missing)} too")
    return ContactModel(name, tuple(got[k] for k in MODELS[name]))


def parse_law(text):
    """A :class:`ForceLaw` from law text (``ForceLaw.parse``) or from a named model's text
    (``"flores: k=2e9, n=1.5, e=0.6"``): what ``--law`` reads."""
    if is_model_text(text):
        return parse_model(text).law
    # a word and a colon is a named model misspelt (a law's sections follow its terms)
    colon = isinstance(text, str) and ":" in text
    name = text.partition(":")[0].strip().lower() if colon else ""
    if re.fullmatch(r"[a-z][a-z_ -]*", name) and name not in _SECTIONS:
        close = [m for m in MODELS if m.startswith(name)] or difflib.get_close_matches(
            name, MODELS, n=1
        )
        hint = f"did you mean {close[0]!r}? " if close else ""
        raise InputError(
            f"{name!r} is no contact model; {hint}the models are {', '.join(MODELS)} (e.g. "
            "'hunt-crossley: k=2e9, n=1.5, lambda=3e9'), or write a law's terms like "
            "'2.06e8*z + 1.28e7*zd'"
        )
    return ForceLaw.parse(text)


_SECTIONS = ("unloading", "set", "scale")  # the law text's own "name:" parts (after ";")
