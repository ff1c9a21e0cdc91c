"""The two-body vibro-impact machine: validated parameters in SI units.

Equations of motion (positions upward, ``zeta = w1 - w2`` the interpenetration)::

    m1 w1'' + c1 w1' + k1 w1 + A sin(2 pi f t) + m1 g + F = 0     (grid frame)
    m2 w2'' + m2 g - F = 0                                        (moulding)

Notation fix: the paper's equation (1) multiplies its ``C1`` by the velocity and
``H1`` by the displacement although its text calls ``C1`` the stiffness of the
supports and ``H1`` the viscosity of the dampers.  We follow the text: ``k1``
(the paper's ``C1``) multiplies the displacement and ``c1`` (``H1``) the velocity.
"""

import math
import tomllib
from dataclasses import asdict, dataclass, field
from importlib import resources
from pathlib import Path

import numpy as np

from .errors import InputError
from .law import ForceLaw

__all__ = ["Scenario", "builtin_scenarios", "load_scenario"]

_FIELDS = {
    "m1": ("kg", True), "m2": ("kg", True), "k1": ("N/m", False), "c1": ("N s/m", False),
    "A": ("N", False), "frequency": ("Hz", True), "g": ("m/s^2", False),
}


@dataclass(frozen=True)
class Scenario:
    """Parameters of the two-body vibro-impact system (SI units).

    Parameters
    ----------
    m1, m2 : float
        Masses of the grid frame and of the moulding [kg], > 0.
    k1 : float
        Total stiffness of the elastic supports [N/m], >= 0.
    c1 : float
        Total viscosity of the dampers [N s/m], >= 0.
    A : float
        Amplitude of the drive ``A sin(2 pi f t)`` [N], >= 0.
    frequency : float
        Drive frequency ``f`` [Hz], > 0.
    g : float
        Gravitational acceleration [m/s^2], >= 0.
    law : ForceLaw or None
        The reference ("true") contact law, if the scenario has one.
    initial : tuple of 4 floats or None
        Initial state ``(w1, v1, w2, v2)`` at ``t = 0``; ``None`` puts both bodies at
        rest, the grid at its static deflection ``-m1 g / k1`` and the moulding just
        touching it.
    name : str
        A label used in reports.
    """

    m1: float
    m2: float
    k1: float
    c1: float
    A: float
    frequency: float
    g: float = 9.81
    law: ForceLaw | None = None
    initial: tuple | None = None
    name: str = "custom"
    source: str = field(default="", compare=False)

    def __post_init__(self):
        for key, (unit, strict) in _FIELDS.items():
            value = getattr(self, key)
            try:
                value = float(value)
            except (TypeError, ValueError):
                raise InputError(
                    f"scenario {key} must be a number in {unit}, got {value!r}"
                ) from None
            if not math.isfinite(value) or value < 0 or (strict and value == 0):
                need = "> 0" if strict else ">= 0"
                raise InputError(
                    f"scenario {key} = {value!r} {unit} is invalid; it must be finite and {need}"
                )
            object.__setattr__(self, key, value)
        if self.initial is not None:
            try:
                init = tuple(float(v) for v in self.initial)
            except (TypeError, ValueError):
                raise InputError("scenario initial must be 4 numbers (w1, v1, w2, v2) in m, "
                                 f"m/s; got {self.initial!r}") from None
            if len(init) != 4 or not all(math.isfinite(v) for v in init):
                raise InputError("scenario initial must be 4 finite numbers (w1, v1, w2, v2)")
            object.__setattr__(self, "initial", init)

    # ------------------------------------------------------------------ derived
    @property
    def omega(self):
        """Drive angular frequency ``2 pi f`` [rad/s]."""
        return 2.0 * math.pi * self.frequency

    @property
    def period(self):
        """Drive period ``T = 1/f`` [s]."""
        return 1.0 / self.frequency

    @property
    def reduced_mass(self):
        """``m1 m2 / (m1 + m2)`` [kg]: the mass seen by the contact."""
        return self.m1 * self.m2 / (self.m1 + self.m2)

    def initial_state(self):
        """Initial state ``[w1, v1, w2, v2]`` (ndarray of shape (4,))."""
        if self.initial is not None:
            return np.array(self.initial, dtype=float)
        w1 = -self.m1 * self.g / self.k1 if self.k1 > 0 else 0.0
        return np.array([w1, 0.0, w1, 0.0])

    def scales(self):
        """Characteristic displacement [m] and velocity [m/s] of the motion."""
        w2 = self.omega**2
        x = max(self.A / (self.m1 * w2), self.g / w2, 1e-9)
        return x, x * self.omega

    def params(self):
        """Parameter vector for the compiled kernel: m1, m2, k1, c1, A, omega, g."""
        return np.array([self.m1, self.m2, self.k1, self.c1, self.A, self.omega, self.g])

    def with_law(self, law):
        """A copy with another reference law."""
        return Scenario(**{**self._fields(), "law": law})

    def _fields(self):
        return {k: getattr(self, k) for k in
                ("m1", "m2", "k1", "c1", "A", "frequency", "g", "law", "initial", "name", "source")}

    def as_dict(self):
        """JSON-ready description (provenance for outputs)."""
        d = {k: v for k, v in asdict(self).items() if k not in ("law", "source")}
        d["law"] = None if self.law is None else self.law.to_text()
        d["source"] = self.source
        return d

    # ------------------------------------------------------------------ loading
    @classmethod
    def from_toml(cls, path):
        """Read a scenario file (``[machine]`` table, optional ``[law] text``)."""
        path = Path(path)
        try:
            data = tomllib.loads(path.read_text())
        except FileNotFoundError:
            raise InputError(
                f"scenario file {str(path)!r} does not exist; give a TOML file or one of "
                f"{', '.join(builtin_scenarios())}"
            ) from None
        except tomllib.TOMLDecodeError as exc:
            raise InputError(f"scenario file {str(path)!r} is not valid TOML: {exc}") from None
        return cls._from_mapping(data, str(path), default_name=path.stem)

    @classmethod
    def _from_mapping(cls, data, source, default_name):
        machine = data.get("machine")
        if not isinstance(machine, dict):
            raise InputError(f"scenario {source!r} needs a [machine] table with m1, m2, k1, c1, A, "
                             "frequency")
        unknown = set(machine) - set(_FIELDS)
        if unknown:
            raise InputError(f"scenario {source!r}: unknown [machine] key(s) {sorted(unknown)}; "
                             f"valid keys are {sorted(_FIELDS)}")
        missing = [k for k in _FIELDS if k != "g" and k not in machine]
        if missing:
            raise InputError(f"scenario {source!r}: [machine] is missing {', '.join(missing)}; "
                             "add them in SI units (kg, N/m, N s/m, N, Hz)")
        law_table = data.get("law") or {}
        if not isinstance(law_table, dict):
            raise InputError(f"scenario {source!r}: law must be a table, write [law] then "
                             "text = \"2.06e8*z + 1.28e7*zd\"")
        law_text = law_table.get("text")
        law = ForceLaw.parse(law_text) if law_text else None
        init = data.get("initial")
        initial = None
        if init is not None:
            try:
                initial = tuple(init[k] for k in ("w1", "v1", "w2", "v2"))
            except (KeyError, TypeError):
                raise InputError(f"scenario {source!r}: [initial] needs w1, v1, w2, v2") from None
        return cls(**machine, law=law, initial=initial,
                   name=str(data.get("name", default_name)), source=source)


def builtin_scenarios():
    """Names of the scenarios shipped with the package."""
    files = resources.files("discovery") / "scenarios"
    return sorted(p.name[:-5] for p in files.iterdir() if p.name.endswith(".toml"))


def load_scenario(name_or_path):
    """A built-in scenario by name (``'paper'``) or a TOML file by path."""
    if isinstance(name_or_path, Scenario):
        return name_or_path
    text = str(name_or_path)
    if text in builtin_scenarios():
        res = resources.files("discovery") / "scenarios" / f"{text}.toml"
        data = tomllib.loads(res.read_text())
        return Scenario._from_mapping(data, f"builtin:{text}", default_name=text)
    return Scenario.from_toml(text)
