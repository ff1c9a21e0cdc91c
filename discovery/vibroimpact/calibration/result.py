"""The result of :func:`~discovery.calibrate`: the machine as the record shows it."""

import math
from dataclasses import dataclass, field

from ..._api._printing import fmt, readable
from ..._api._result import Result
from ..model.scenario import Scenario

__all__ = ["Calibration", "UNITS"]

#: each calibrated parameter's unit
UNITS = {
    "m1": "kg",
    "m2": "kg",
    "k1": "N/m",
    "c1": "N s/m",
    "k3": "N/m^3",
    "A": "N",
    "mass_loss": "per contact",
    "force_lag": "s",
}
#: the least relative uncertainty granted the machine's scale: a bias the bootstrap over
#: cycles cannot see (the force's quadrature; noise-free, the contacts' windows leave at
#: most 0.5 % on stiff, heavily damped contacts whose impulse lies in a few samples)
SCALE_FLOOR = 0.01
#: what each parameter is, for the lines a command prints
WHAT = {
    "m1": "grid frame's mass",
    "m2": "moulding mass",
    "k1": "support stiffness",
    "c1": "support damping",
    "k3": "supports' cubic stiffness",
    "A": "drive amplitude",
    "mass_loss": "moulding's mass loss per contact",
    "force_lag": "force sensor's time constant",
}


def _unit(name):
    return UNITS[name.split("[")[0]]


def _what(name):
    base = name.split("[")[0]
    tail = f" (record {name[len(base) + 1 : -1]})" if "[" in name else ""
    return WHAT[base] + tail


def _scenarios(key):
    return lambda d: tuple(Scenario.from_dict(s) for s in d[key])


def found_lag(parameters):
    """The force sensor's time constant [s] a calibration's ``parameters`` (its table, or
    the same table read back from a summary) hold as ``force_lag``, 0 where none."""
    p = parameters.get("force_lag")
    return float(p["record"]) if isinstance(p, dict) and p.get("record") else 0.0


@readable
@dataclass(frozen=True, eq=False)
class Calibration(Result):
    """The machine's parameters estimated from a record's own motions and force.

    Attributes
    ----------
    sheet : tuple of Scenario
        The scenario given with each record (the designer's sheet).
    scenarios : tuple of Scenario
        The machine used for each record: the sheet with the parameters the record
        determines replaced by the record's values.
    parameters : dict
        ``{name: {"unit", "sheet", "record", "low", "high", "determined", "used"}}``:
        ``record`` the estimate with its 95 % interval ``[low, high]`` (bootstrap over the
        record's cycles), ``determined`` whether the record pins it (its interval within
        +-25 % of it), ``used`` the value the machine takes (the record's when determined,
        else the sheet's).  Several records of one machine share ``m1, m2, k1, c1, k3``;
        each has its own drive amplitude ``A[1]``, ``A[2]``, ...
    phase : tuple
        Per record ``(deg, low, high)``: the drive's phase at the record's ``t = 0``
        fitted free (0 on the drive's clock).
    residual : dict
        ``{"frame": {"sheet", "record"}, "moulding": {...}}``: the equations' weak-form
        residual relative to the force, with the sheet's machine and with the record's.
    calibrated : bool
        False when the record holds no motions to calibrate from (the sheet is used).
    notes : tuple of str
    settings : dict
    seconds : float
    series : dict or None
        For the figure, over the first record's test windows: ``t`` (their centres [s]),
        ``measured`` (the measured force, averaged over each window [N]) and the force
        each body's motion implies, ``frame`` / ``moulding``, each ``{"sheet", "record"}``.
        Not in the document (``None`` on a loaded result).
    """

    sheet: tuple
    scenarios: tuple
    parameters: dict
    phase: tuple = ()
    residual: dict = field(default_factory=dict)
    calibrated: bool = True
    notes: tuple = ()
    settings: dict = field(default_factory=dict)
    seconds: float = 0.0
    series: dict = field(default=None, repr=False)

    KIND = "calibrate"
    _LOAD = {
        "sheet": _scenarios("sheet"),
        "scenarios": _scenarios("scenarios"),
        "phase": lambda d: tuple(tuple(p) for p in d.get("phase", ())),
        "notes": lambda d: tuple(d.get("notes", ())),
    }

    @property
    def scale_range(self):
        """``(low, high)``: the factors within which the calibrated machine's scale is
        uncertain (``m1``'s 95 % interval, at least +-:data:`SCALE_FLOOR`), or ``None``
        when ``m1`` was not calibrated (held, loose, or nothing calibrated).  The ratios
        are known far better (see :mod:`~discovery.vibroimpact.calibration.estimate`);
        ``verify(..., machine_scale=...)`` takes it."""
        p = self.parameters.get("m1")
        if not self.calibrated or not p or not p["determined"] or p["low"] is None:
            return None
        half = max((p["high"] - p["low"]) / 2 / p["used"], SCALE_FLOOR)
        return (1.0 - half, 1.0 + half)

    @property
    def sensor_lag(self):
        """The force sensor's time constant [s] the records show (``force_lag``), 0 where
        none was found: what ``discover``, ``verify`` and ``explain`` read the simulated
        force through."""
        return found_lag(self.parameters) if self.calibrated else 0.0

    @property
    def scenario(self):
        """The machine of the (first) record."""
        return self.scenarios[0]

    def as_dict(self):
        return {
            "calibrated": self.calibrated,
            "sheet": [s.as_dict() for s in self.sheet],
            "scenarios": [s.as_dict() for s in self.scenarios],
            "parameters": self.parameters,
            "phase": [list(p) for p in self.phase],
            "residual": self.residual,
            "scale_range": None if self.scale_range is None else list(self.scale_range),
            "disagreements": self.disagreements(),
            "notes": list(self.notes),
            "settings": self.settings,
            "seconds": self.seconds,
        }

    def summary_line(self):
        """The machine used, in one line (``m1 9.05 t, c1 8.04e+04 N s/m, ...``)."""
        return ", ".join(f"{n} {_quantity(p['used'], n)}" for n, p in self.parameters.items())

    def disagreements(self):
        """One line for each parameter the record determines whose sheet value lies
        outside its interval ("the record's moulding mass is 6.31 t +- 0.05 t; the
        scenario says 6 t")."""
        out = []
        for name, p in self.parameters.items():
            if not p["determined"] or p["low"] is None or p["high"] is None:
                continue
            if p["low"] <= p["sheet"] <= p["high"]:
                continue
            half = (p["high"] - p["low"]) / 2
            out.append(
                f"the record's {_what(name)} is {_quantity(p['record'], name)} +- "
                f"{_quantity(half, name, like=p['record'])}; the scenario says "
                f"{_quantity(p['sheet'], name)}"
            )
        return out

    def _lines(self):
        head = "calibration: the machine as the record shows it"
        if not self.calibrated:
            return [f"{head}: not calibrated", *[f"  note: {n}" for n in self.notes]]
        width = max(15, *(len(f"{n} [{_unit(n)}]") + 1 for n in self.parameters))
        rows = [
            head,
            f"  {'parameter':<{width}}{'sheet':>11}   {'record [95 % interval]':<34}used",
        ]
        for name, p in self.parameters.items():
            rec = (
                f"{fmt(p['record'])} [{fmt(p['low'])}, {fmt(p['high'])}]"
                if p["low"] is not None and p["low"] != p["high"]
                else fmt(p["record"])
            )
            used = "record" if p["determined"] else "sheet (the record leaves it loose)"
            if p.get("held"):
                used = "sheet (held)"
            label = f"{name} [{_unit(name)}]"
            rows.append(f"  {label:<{width}}{fmt(p['sheet']):>11}   {rec:<34}{used}")
        res = self.residual
        if res:
            rows.append(
                "  equations' residual, share of the force: frame "
                f"{_pct(res['frame']['record'])} (sheet {_pct(res['frame']['sheet'])}), "
                f"moulding {_pct(res['moulding']['record'])} "
                f"(sheet {_pct(res['moulding']['sheet'])})"
            )
        rows += [f"  {line}" for line in self.disagreements()]
        rows += [f"  note: {n}" for n in self.notes]
        return rows


def _pct(x):
    return "--" if x is None or not math.isfinite(x) else f"{100 * x:.2g} %"


def _quantity(value, name, like=None):
    """A parameter's value in readable units (a mass in t from a tonne up, or in the unit
    of the value ``like``)."""
    unit = _unit(name)
    if unit == "kg" and abs(value if like is None else like) >= 1000:
        return f"{value / 1000:.3g} t"
    return f"{value:.3g} {unit}"
