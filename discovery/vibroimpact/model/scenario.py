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

from ..._api._validate import Text, check
from ...errors import InputError
from .law import ForceLaw

__all__ = ["Scenario", "builtin_scenarios", "load_scenario", "scale_bounds"]

_FIELDS = {
    "m1": ("kg", True),
    "m2": ("kg", True),
    "k1": ("N/m", False),
    "c1": ("N s/m", False),
    "A": ("N", False),
    "frequency": ("Hz", True),
    "g": ("m/s^2", False),
    "k3": ("N/m^3", False),
    "mass_loss": ("per impact", False),
    "offset": ("m", False),
}
#: parameters that may be negative (|value| <= the limit)
_SIGNED = {"offset"}
#: parameters a scenario file may leave out (their defaults: the paper's machine)
_OPTIONAL = {"g": 9.81, "k3": 0.0, "mass_loss": 0.0, "offset": 0.0}
#: largest accepted value of each parameter: far beyond any vibro-impact machine, and
#: small enough that the simulation's scales (A / (m1 omega^2), k1 / m1, ...) stay finite
LIMITS = {
    "m1": 1e9,
    "m2": 1e9,
    "k1": 1e15,
    "c1": 1e12,
    "A": 1e12,
    "frequency": 1e5,
    "g": 1e3,
    "k3": 1e24,
    "mass_loss": 0.5,
    "offset": 1.0,
}
#: largest accepted |position| [m] and |velocity| [m/s] of the initial state
INITIAL_LIMITS = (1e3, 1e3)

#: the smallest approach velocity of an impact-scaled law, in the machine's velocity scale
#: (:meth:`Scenario.impact_v0_floor`)
IMPACT_V0_FLOOR = 1e-3
#: the tables and keys a scenario file may have
_TABLES = {
    "name": None,
    "machine": tuple(_FIELDS),
    "law": ("text",),
    "initial": ("w1", "v1", "w2", "v2"),
}


def _number(value, what, unit):
    """A float from a number (not a boolean, not text) or raise naming ``what``."""
    if isinstance(value, bool | np.bool_) or not isinstance(value, int | float | np.number):
        got = (
            "a boolean"
            if isinstance(value, bool | np.bool_)
            else (f"text {value!r}" if isinstance(value, str) else type(value).__name__)
        )
        raise InputError(
            f"{what} must be a number in {unit}, got {got}; write a number such "
            "as 1.0e4 (no quotes)"
        )
    try:
        return float(value)
    except OverflowError:
        return math.inf


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
    k3 : float
        Cubic stiffness of the supports [N/m^3], >= 0: their force is ``k1 w1 + k3 w1^3``
        (stiffening supports; 0 for the paper's linear springs).
    mass_loss : float
        Fraction of the moulding's mass shed at each impact, in [0, 0.5] (sand falling
        out of the flask); 0 for the paper's constant mass.  With a loss the motion
        drifts and has no periodic steady state: it is simulated over a record's span.
    offset : float
        Contact offset ``delta0`` [m], ``|delta0| <= 1``: contact starts where the
        *recorded* penetration ``w1 - w2`` reaches ``delta0`` (a clearance, or a zero
        offset of the position sensors); 0 when the sensors' zero is the contact.  The
        moulding moves freely between contacts, so the offset shifts the recorded moulding
        position against the model's and changes no dynamics: it enters wherever a
        simulation starts from, or is compared with, recorded positions.
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
    k3: float = 0.0
    mass_loss: float = 0.0
    offset: float = 0.0

    def __post_init__(self):
        check("Scenario: name", self.name, Text(200))
        check("Scenario: source", self.source, Text(4096, empty=True))
        check("Scenario: law", self.law, (ForceLaw, None))
        for key, (unit, strict) in _FIELDS.items():
            value = _number(getattr(self, key), f"scenario {key}", unit)
            lim = LIMITS[key]
            low = -lim if key in _SIGNED else 0.0
            if not (math.isfinite(value) and low <= value <= lim) or (strict and value == 0):
                need = "> 0" if strict else (f">= {low:g}" if low else ">= 0")
                raise InputError(
                    f"scenario {key} = {value:g} {unit} is invalid; it must be finite, {need} "
                    f"and <= {lim:g} {unit}"
                )
            object.__setattr__(self, key, value)
        if self.initial is not None:
            if (
                isinstance(self.initial, str | bytes)
                or not hasattr(self.initial, "__len__")
                or len(self.initial) != 4
            ):
                raise InputError(
                    "scenario initial must be 4 numbers (w1, v1, w2, v2) in m, "
                    f"m/s; got {self.initial!r}"
                )
            init = tuple(
                _number(v, f"scenario initial {k}", u)
                for v, k, u in zip(
                    self.initial, ("w1", "v1", "w2", "v2"), ("m", "m/s", "m", "m/s"), strict=True
                )
            )
            wmax, vmax = INITIAL_LIMITS
            if (
                not all(math.isfinite(v) for v in init)
                or max(abs(init[0]), abs(init[2])) > wmax
                or max(abs(init[1]), abs(init[3])) > vmax
            ):
                raise InputError(
                    "scenario initial must be 4 finite numbers (w1, v1, w2, v2) "
                    f"with |w| <= {wmax:g} m and |v| <= {vmax:g} m/s"
                )
            object.__setattr__(self, "initial", init)
        if self.law is not None and not isinstance(self.law, ForceLaw):
            raise InputError(
                f"scenario law must be a ForceLaw, got {type(self.law).__name__}; "
                "use ForceLaw.parse(text)"
            )

    def __str__(self):
        """The machine in a few lines, with units (``repr`` stays what one would type)."""
        lines = [f"scenario {self.name!r}" + (f" ({self.source})" if self.source else "")]
        for key, (unit, _) in _FIELDS.items():
            value = getattr(self, key)
            if key in _OPTIONAL and value == _OPTIONAL[key] and key != "g":
                continue  # an optional part left out
            lines.append(f"  {key:<10}{value:.6g} {unit}")
        if self.initial is not None:
            lines.append("  initial   " + ", ".join(f"{v:.6g}" for v in self.initial))
        lines.append(f"  law       {self.law if self.law is not None else '(none)'}")
        return "\n".join(lines)

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
        if self.k3 > 0:
            # the real root of k1 w + k3 w^3 + m1 g = 0 (stiffening supports sag less)
            roots = np.roots([self.k3, 0.0, self.k1, self.m1 * self.g])
            w1 = float(np.real(roots[np.argmin(np.abs(np.imag(roots)))]))
        return np.array([w1, 0.0, w1, 0.0])

    def model_state(self, y):
        """A recorded state ``(w1, v1, w2, v2)`` in the model's coordinates: the moulding's
        position shifted by the contact :attr:`offset` (a copy, ndarray of shape (4,))."""
        y = np.array(y, dtype=float)
        y[2] += self.offset
        return y

    def recorded_penetration(self, zeta):
        """The model's penetration ``zeta`` [m] as the position sensors record it
        (``zeta + offset``), ndarray."""
        return np.asarray(zeta, dtype=float) + self.offset

    def mass_after(self, impacts, loss=None):
        """The moulding's mass after ``impacts`` impacts (a number or an array), each shedding
        ``loss`` (default :attr:`mass_loss`) of it: ``m2 (1 - loss)^impacts``."""
        return self.m2 * (1.0 - (self.mass_loss if loss is None else loss)) ** impacts

    def scales(self):
        """Characteristic displacement [m] and velocity [m/s] of the motion."""
        w2 = self.omega**2
        x = max(self.A / (self.m1 * w2), self.g / w2, 1e-9)
        return x, x * self.omega

    def impact_v0_floor(self):
        """The smallest approach velocity [m/s] an impact-scaled law (Lankarani-Nikravesh,
        Flores) divides its velocity terms by: :data:`IMPACT_V0_FLOOR` of the velocity scale.
        A contact that begins without an approach velocity (the moulding lying on the frame
        at rest, a grazing onset) has no impact to scale by; over the ``1e-12`` m/s it was
        given, its damping made the run stall (a Flores law from rest on a machine whose
        moulding rests on the frame: the step budget spent in 0.034 s).  Impacts faster than
        the floor, every impact these laws describe, are unchanged."""
        return IMPACT_V0_FLOOR * self.scales()[1]

    def params(self):
        """Parameter vector for the compiled kernel: m1, m2, k1, c1, A, omega, g, k3,
        mass_loss."""
        return np.array(
            [
                self.m1,
                self.m2,
                self.k1,
                self.c1,
                self.A,
                self.omega,
                self.g,
                self.k3,
                self.mass_loss,
            ]
        )

    def replace(self, **changes):
        """A copy with some parameters changed (validated like the original)."""
        return Scenario(**{**self._fields(), **changes})

    def scaled(self, factor):
        """A copy with every force-carrying parameter (``m1, m2, k1, c1, A, k3``) times
        ``factor``: the same machine's motion under forces ``factor`` times larger.  A
        calibration from a record knows the machine's ratios far better than its scale
        (:func:`~discovery.calibrate`)."""
        keys = ("m1", "m2", "k1", "c1", "A", "k3")
        return self.replace(**{k: getattr(self, k) * factor for k in keys})

    def with_law(self, law):
        """A copy with another reference law."""
        return Scenario(**{**self._fields(), "law": law})

    def _fields(self):
        return {
            k: getattr(self, k)
            for k in (
                "m1",
                "m2",
                "k1",
                "c1",
                "A",
                "frequency",
                "g",
                "law",
                "initial",
                "name",
                "source",
                "k3",
                "mass_loss",
                "offset",
            )
        }

    def as_dict(self):
        """JSON-ready description (provenance for outputs)."""
        d = {k: v for k, v in asdict(self).items() if k not in ("law", "source")}
        d["law"] = None if self.law is None else self.law.to_text()
        d["source"] = self.source
        return d

    def to_toml(self):
        """The scenario as the text of a scenario file (:meth:`from_toml` reads it back)."""
        lines = [f"name = {_toml_text(self.name)}", "", "[machine]"]
        for key, (unit, _) in _FIELDS.items():
            value = getattr(self, key)
            if key in _OPTIONAL and value == _OPTIONAL[key] and key != "g":
                continue
            lines.append(f"{key} = {value!r}  # {unit}")
        if self.law is not None:
            lines += ["", "[law]", f"text = {_toml_text(self.law.to_text())}"]
        if self.initial is not None:
            lines += ["", "[initial]"]
            lines += [f"{k} = {v!r}" for k, v in zip(_TABLES["initial"], self.initial, strict=True)]
        return "\n".join(lines) + "\n"

    @classmethod
    def from_dict(cls, d):
        """The scenario an :meth:`as_dict` document describes."""
        d = dict(d)
        law = d.pop("law", None)
        if d.get("initial") is not None:
            d["initial"] = tuple(d["initial"])
        return cls(**d, law=None if law is None else ForceLaw.parse(law))

    # ------------------------------------------------------------------ loading
    @classmethod
    def from_toml(cls, path):
        """Read a scenario file (``[machine]`` table, optional ``[law] text``, optional
        ``[initial]``, optional top-level ``name``); every table and key is checked (see
        :meth:`_from_mapping`)."""
        path = Path(path)
        hint = f"give a TOML file or one of {', '.join(builtin_scenarios())}"
        if path.exists() and not path.is_dir() and not path.is_file():
            # a device (/dev/zero) would be read until memory runs out
            raise InputError(f"scenario {str(path)!r} is not a regular file; {hint}")
        if path.is_file() and path.stat().st_size > MAX_SCENARIO_BYTES:
            raise InputError(
                f"scenario file {str(path)!r} is over {MAX_SCENARIO_BYTES // 2**20} MB; a "
                f"scenario is a few lines of TOML: {hint}"
            )
        try:
            raw = path.read_bytes()
        except FileNotFoundError:
            raise InputError(f"scenario file {str(path)!r} does not exist; {hint}") from None
        except IsADirectoryError:
            raise InputError(f"scenario {str(path)!r} is a directory; {hint}") from None
        except PermissionError:
            raise InputError(
                f"scenario file {str(path)!r} cannot be read (permission denied); "
                "fix its permissions"
            ) from None
        except OSError as exc:
            raise InputError(
                f"cannot read scenario file {str(path)!r} ({exc.strerror or exc}); {hint}"
            ) from None
        try:
            text = raw.decode("utf-8-sig")
        except UnicodeDecodeError as exc:
            raise InputError(
                f"scenario file {str(path)!r} is not UTF-8 text (byte "
                f"0x{raw[exc.start]:02x} at offset {exc.start}); re-save it as "
                "UTF-8"
            ) from None
        try:
            data = tomllib.loads(text)
        except tomllib.TOMLDecodeError as exc:
            raise InputError(f"scenario file {str(path)!r} is not valid TOML: {exc}") from None
        return cls._from_mapping(data, str(path), default_name=path.stem)

    @classmethod
    def _from_mapping(cls, data, source, default_name):
        """Validate a parsed scenario file: unknown tables and keys are refused (a typo
        would otherwise silently fall back to a default), every value is type-checked
        (a boolean or a quoted number is not a number) and range-checked."""
        unknown = sorted(set(data) - set(_TABLES))
        if unknown:
            raise InputError(
                f"scenario {source!r}: unknown table(s) or key(s) "
                f"{', '.join(unknown)}; valid are name, [machine], [law], [initial]"
            )
        for table in ("machine", "law", "initial"):
            if table in data and not isinstance(data[table], dict):
                raise InputError(
                    f"scenario {source!r}: {table} must be a table; write "
                    f"[{table}] on its own line followed by its keys"
                )
            extra = sorted(set(data.get(table, {})) - set(_TABLES[table]))
            if extra:
                raise InputError(
                    f"scenario {source!r}: unknown [{table}] key(s) "
                    f"{', '.join(extra)}; valid keys are "
                    f"{', '.join(_TABLES[table])}"
                )
        machine = data.get("machine")
        if machine is None:
            raise InputError(
                f"scenario {source!r} needs a [machine] table with m1, m2, k1, c1, A, frequency"
            )
        missing = [k for k in _FIELDS if k not in _OPTIONAL and k not in machine]
        if missing:
            raise InputError(
                f"scenario {source!r}: [machine] is missing {', '.join(missing)}; "
                "add them in SI units (kg, N/m, N s/m, N, Hz)"
            )
        values = {k: _number(v, f"scenario {k}", _FIELDS[k][0]) for k, v in machine.items()}
        law = None
        if "law" in data:
            law_text = data["law"].get("text")
            if not isinstance(law_text, str) or not law_text.strip():
                raise InputError(
                    f'scenario {source!r}: [law] needs text = "2.06e8*z + '
                    '1.28e7*zd" (a quoted, non-empty law), or remove the table'
                )
            law = ForceLaw.parse(law_text)
        initial = None
        if "initial" in data:
            init = data["initial"]
            if set(init) != set(_TABLES["initial"]):
                raise InputError(f"scenario {source!r}: [initial] needs w1, v1, w2, v2")
            initial = tuple(
                _number(init[k], f"scenario initial {k}", u)
                for k, u in zip(_TABLES["initial"], ("m", "m/s", "m", "m/s"), strict=True)
            )
        name = data.get("name", default_name)
        if not isinstance(name, str) or not name.strip():
            raise InputError(
                f'scenario {source!r}: name must be non-empty text, e.g. name = "my-grid"'
            )
        return cls(**values, law=law, initial=initial, name=name, source=source)


#: the largest scenario file read
MAX_SCENARIO_BYTES = 2**20


def scale_bounds(bounds, where="machine_scale"):
    """``(low, high)``, the factors within which a machine's scale is uncertain
    (:meth:`Scenario.scaled`), as floats; one :class:`InputError` unless
    ``0 < low <= 1 <= high``."""
    try:
        lo, hi = (float(b) for b in bounds)
    except (TypeError, ValueError):
        lo = hi = math.nan
    if not 0 < lo <= 1 <= hi:
        raise InputError(f"{where} must be (low, high) with 0 < low <= 1 <= high; got {bounds!r}")
    return lo, hi


def _toml_text(text):
    """``text`` as a TOML basic string."""
    out = str(text).replace("\\", "\\\\").replace('"', '\\"')
    return '"' + "".join(c if c.isprintable() else f"\\u{ord(c):04x}" for c in out) + '"'


def builtin_scenarios():
    """Names of the scenarios shipped with the package."""
    files = resources.files("discovery.vibroimpact.model") / "scenarios"
    return sorted(p.name[:-5] for p in files.iterdir() if p.name.endswith(".toml"))


def load_scenario(name_or_path):
    """A built-in scenario by name (``'paper'``) or a TOML file by path."""
    if isinstance(name_or_path, Scenario):
        return name_or_path
    text = str(name_or_path)
    if not text.strip():
        raise InputError(
            "the scenario is empty; give a built-in name "
            f"({', '.join(builtin_scenarios())}) or a TOML file"
        )
    if text in builtin_scenarios():
        res = resources.files("discovery.vibroimpact.model") / "scenarios" / f"{text}.toml"
        data = tomllib.loads(res.read_text())
        return Scenario._from_mapping(data, f"builtin:{text}", default_name=text)
    return Scenario.from_toml(text)
