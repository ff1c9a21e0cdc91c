"""Shared pieces of the command modules: option help texts and small parsers."""

import numpy as np

from ..errors import InputError
from ..law import ForceLaw
from ..scenario import builtin_scenarios

SCENARIO_HELP = (f"built-in scenario ({', '.join(builtin_scenarios())}) or a TOML file "
                 "(default: paper)")
LAW_HELP = "force law, e.g. '2.06e8*z + 1.28e7*zd' (default: the scenario's law)"


def law_or_default(text, scenario, what="--law"):
    if text:
        return ForceLaw.parse(text)
    if scenario.law is None:
        raise InputError(f"scenario {scenario.name!r} has no reference law; pass {what}")
    return scenario.law


def parse_range(text, default, name):
    if text is None:
        return default
    try:
        lo, hi = (float(v) for v in text.split(":"))
    except ValueError:
        raise InputError(f"{name} {text!r} must look like LOW:HIGH, e.g. 1.03e8:3.09e8") from None
    if not (np.isfinite(lo) and np.isfinite(hi) and lo < hi):
        raise InputError(f"{name} needs LOW < HIGH, got {text!r}")
    return lo, hi
