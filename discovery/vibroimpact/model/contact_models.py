"""The contact models engineers name, each a :class:`ForceLaw` with physical parameters:
the entries of the registry
(:data:`~discovery.vibroimpact.model.contact_registry.CONTACT_MODELS`, whose docstring
lists them), read here without switching on a model's name.

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

from ..._api._validate import Real, Text, check
from ...errors import InputError
from .contact_registry import CONTACT_MODELS, E_RANGE, K_FLOOR, N_RANGE, domain_edges
from .law import ForceLaw

__all__ = [
    "ContactModel",
    "parse_model",
    "parse_law",
    "is_model_text",
    "restitution_ratio",
    "same_force",
]


def _restitution_spec(name):
    """The spec of a model with a restitution relation (an impact-scaled one)."""
    spec = CONTACT_MODELS.get(name)
    if spec is None or spec.ratio is None:
        raise InputError(f"{name!r} is no contact model with a coefficient of restitution")
    return spec


def restitution_ratio(name, e):
    """The damping ratio ``r = lambda v0 / k`` a model gives to a coefficient of
    restitution ``e``."""
    return _restitution_spec(name).ratio(e)


def restitution_from_ratio(name, r):
    """The coefficient of restitution a ratio ``r`` means for a model (``nan`` where the
    model has none: Lankarani-Nikravesh beyond ``r = 3/4``)."""
    return _restitution_spec(name).restitution(max(float(r), 0.0))


def same_force(name, parameters):
    """``(other model, its parameters)`` making exactly the same force as model ``name``
    with ``parameters`` at every impact velocity, or ``None``.

    The models with a restitution relation (Lankarani-Nikravesh and Flores) are one family
    ``k z^n (1 + r dz / v0)``: the same ``k``, ``n`` and ratio ``r`` give the same force,
    so no record, at any operating point, can tell them apart.  A Flores model whose ``r``
    exceeds ``3/4`` (``e < 8/11.75``) has no Lankarani-Nikravesh counterpart.
    """
    spec = CONTACT_MODELS.get(name)
    if spec is None or not spec.impact_scaled:
        return None
    r = spec.ratio(float(parameters["e"]))
    for other in CONTACT_MODELS.values():
        if other.impact_scaled and other.name != name:
            e = restitution_from_ratio(other.name, r)
            if np.isfinite(e):
                k, n = float(parameters["k"]), float(parameters["n"])
                return other.name, {"k": k, "n": n, "e": e}
    return None


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
        if self.name not in CONTACT_MODELS:
            raise InputError(
                f"unknown contact model {self.name!r}; the models: {', '.join(CONTACT_MODELS)}"
            )
        keys = self.spec.parameters
        vals = tuple(float(v) for v in self.values)
        if len(vals) != len(keys) or not all(np.isfinite(vals)):
            raise InputError(
                f"{self.name} takes {len(keys)} finite parameters "
                f"({', '.join(keys)}); got {self.values!r}"
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
    def spec(self):
        """The model's entry in the registry
        (:data:`~discovery.vibroimpact.model.contact_registry.CONTACT_MODELS`)."""
        return CONTACT_MODELS[self.name]

    @property
    def params(self):
        """``{name: value}``, with ``n`` for every model (fixed for some of them)."""
        return self.spec.params(self.values)

    @property
    def coefficients(self):
        """The parameters in the model's order (what a fit varies)."""
        return self.values

    @property
    def names(self):
        """The parameters' names, in order."""
        return list(self.spec.parameters)

    def with_coefficients(self, values):
        """The model with new parameters (``n`` and ``e`` clipped to the ranges a fit may
        reach, the damping to >= 0), so a fit's trial step stays a model."""
        out = []
        for (lo, hi, open_low), v in zip(self.spec.domains.values(), values, strict=True):
            out.append(min(max(float(v), K_FLOOR if open_low else lo), hi))
        return ContactModel(self.name, tuple(out))

    def edges(self):
        """Why the model sits at the edge of what a fit may reach: one line per parameter
        at it (a stiffness at its floor, an exponent or a restitution at its range's end;
        empty when none is).  A fit that ends there is no result, and one heading there is
        not restarted (:func:`~discovery.vibroimpact.fit.optimise._restarted`)."""
        return domain_edges(self.params)

    # ----------------------------------------------------------------- law
    @property
    def law(self):
        """The model as a :class:`ForceLaw` (damping in loading and unloading)."""
        return self.spec.law(self.params)

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
        damping, what = self.spec.damping(self.params), self.spec.damping_name
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
            f"{k}={v!r}" for k, v in zip(self.spec.parameters, self.values, strict=True)
        )

    def format(self, digits=4):
        return f"{self.name}: " + ", ".join(
            f"{k}={v:.{digits}g}" for k, v in zip(self.spec.parameters, self.values, strict=True)
        )

    def __str__(self):
        return self.format()

    def as_dict(self):
        return {
            "model": self.name,
            "parameters": dict(zip(self.spec.parameters, self.values, strict=True)),
            "law": self.law.to_text(),
            "text": self.to_text(),
        }


def is_model_text(text):
    """True when ``text`` names a contact model (``"<model>: k=..., ..."``)."""
    return isinstance(text, str) and text.partition(":")[0].strip().lower() in CONTACT_MODELS


def parse_model(text):
    """A :class:`ContactModel` from text like ``"hunt-crossley: k=2e9, n=1.5, lambda=3e9"``
    (every parameter of the model, once, in any order)."""
    name, sep, rest = text.partition(":")
    name = name.strip().lower()
    if not sep or name not in CONTACT_MODELS:
        raise InputError(
            f"{text!r} names no contact model; give '<model>: k=..., ...' with a model of "
            f"{', '.join(CONTACT_MODELS)}"
        )
    keys = CONTACT_MODELS[name].parameters
    got = {}
    for part in rest.split(","):
        key, eq, value = part.partition("=")
        key = key.strip().lower()
        if not eq or key not in keys or key in got:
            raise InputError(
                f"{text!r}: {name} takes {', '.join(f'{k}=<number>' for k in keys)} "
                "once each, e.g. 'hunt-crossley: k=2e9, n=1.5, lambda=3e9'"
            )
        try:
            if not value.isascii():  # float() reads full-width digits; the law grammar not
                raise ValueError
            got[key] = float(value)
        except ValueError:
            raise InputError(f"{text!r}: {key} needs a number, got {value.strip()!r}") from None
    missing = [k for k in keys if k not in got]
    if missing:
        raise InputError(f"{text!r}: {name} needs {', '.join(missing)} too")
    return ContactModel(name, tuple(got[k] for k in keys))


def parse_law(text):
    """A :class:`ForceLaw` from law text (``ForceLaw.parse``) or from a named model's text
    (``"flores: k=2e9, n=1.5, e=0.6"``): what ``--law`` reads."""
    if is_model_text(text):
        return parse_model(text).law
    # a word and a colon is a named model misspelt (a law's sections follow its terms)
    colon = isinstance(text, str) and ":" in text
    name = text.partition(":")[0].strip().lower() if colon else ""
    if re.fullmatch(r"[a-z][a-z_ -]*", name) and name not in _SECTIONS:
        close = [m for m in CONTACT_MODELS if m.startswith(name)] or difflib.get_close_matches(
            name, CONTACT_MODELS, n=1
        )
        hint = f"did you mean {close[0]!r}? " if close else ""
        raise InputError(
            f"{name!r} is no contact model; {hint}the models are {', '.join(CONTACT_MODELS)} (e.g. "
            "'hunt-crossley: k=2e9, n=1.5, lambda=3e9'), or write a law's terms like "
            "'2.06e8*z + 1.28e7*zd'"
        )
    return ForceLaw.parse(text)


_SECTIONS = ("unloading", "set", "scale")  # the law text's own "name:" parts (after ";")
