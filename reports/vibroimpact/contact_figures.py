"""The figure of a fit of the named contact models (``vidi fit --library contact-models``):
each model's criterion I2, marked consistent, inconsistent or failed. The command draws no
figure; its report draws this one from the run's document (matplotlib is imported only
then: the report of a run reads this module's parsing of a failed fit without it).

A failed fit's parameters are read here too (:func:`failure_reasons`): a parameter the fit
drove to its floor (``1e-300``) or to the end of its range is a reason the fit failed, never
a value to print.
"""

import re

import numpy as np

__all__ = ["contact_models_figure", "failure_reasons", "failed", "at_floor"]

#: a parameter this small sits at its fit's floor (``1e-300``): it has no value to print
_FLOOR = 1e-200

_CLAUSES = (
    (re.compile(r"(?P<p>\w+) = \S+ sits at its floor"), "at its floor (driven to zero)"),
    (
        re.compile(r"(?P<p>\w+) = \S+ sits at the end of its range (?P<r>\[[^\]]*\])"),
        "at the end of its range {r}",
    ),
    (
        re.compile(r"(?P<p>\w+)'s interval spans its whole range"),
        "its interval spans its whole range",
    ),
)


def at_floor(value):
    """Whether a fitted parameter sits at the fit's floor (a number it cannot be printed as)."""
    try:
        return abs(float(value)) < _FLOOR
    except (TypeError, ValueError):
        return False


def failed(fit):
    """Whether a named model's fit failed (its consistency unknown)."""
    return fit.consistent is None


def failure_reasons(fit):
    """``({parameter: why}, [other reasons])`` of a failed fit, from its message (``fit
    degenerate: k = 1e-300 sits at its floor; n = 0.5 sits at the end of its range [0.5,
    3]``) and its parameters (one at the floor is named even where the message is not);
    empty for a fit that did not fail."""
    if not failed(fit):
        return {}, []
    params, other = {}, []
    message = str(fit.message or "")
    body = message.split(":", 1)[1] if message.startswith("fit degenerate:") else message
    for clause in (c.strip() for c in body.split(";") if c.strip()):
        for pattern, why in _CLAUSES:
            m = pattern.fullmatch(clause)
            if m is not None and m["p"] in fit.parameters:
                params[m["p"]] = why.format(r=m.groupdict().get("r"))
                break
        else:
            other.append(clause)
    for k, v in fit.parameters.items():
        if at_floor(v):
            params.setdefault(k, "at its floor (driven to zero)")
    return params, other


def _status(fit):
    if failed(fit):
        params, _ = failure_reasons(fit)
        return "failed (degenerate fit)" if params else "failed"
    return "consistent" if fit.consistent else "inconsistent"


_STYLE = {
    "consistent": dict(color="C2"),
    "inconsistent": dict(color="C3"),
    "failed": dict(color="0.85", hatch="//", edgecolor="0.4"),
}


def contact_models_figure(result, stem):
    """Each named model's I2 as a bar (log axis): consistent with every record (green),
    inconsistent (red), or failed (hatched grey: the I2 of the law the failed fit ended
    at, when it has one, and why it failed), the model the record supports starred.

    Parameters
    ----------
    result : ContactModelsResult
    stem : str
        Output path without extension.
    """
    from .._mpl import PRINT_WIDTH, print_sizes, save, subplots  # matplotlib: on first use

    fits = list(result.fits or ())
    n = max(len(fits), 1)
    with print_sizes():  # drawn at the width it is printed: its text 7 to 8 pt
        fig, ax = subplots(figsize=(PRINT_WIDTH, 1.4 + 0.38 * n), layout="constrained")
        y = np.arange(len(fits))[::-1]
        values = [fit.criteria.get("I2", fit.value) for fit in fits]
        shown = [float(v) for v in values if v is not None and np.isfinite(v) and v > 0]
        lo = min(shown, default=0.01) / 3
        hi = max(shown, default=1.0) * 60
        for yk, fit, v in zip(y, fits, values, strict=True):
            status = _status(fit)
            has = v is not None and np.isfinite(v) and v > 0
            if has:
                ax.barh(yk, v - lo, left=lo, height=0.6, **_STYLE[status.split(" ")[0]])
            ax.text(
                v * 1.15 if has else lo * 1.15,
                yk,
                f"{v:.3g}, {status}" if has else status,
                va="center",
            )
        star = {result.selected}
        ax.set_yticks(y, [f.model + (" (selected)" if f.model in star else "") for f in fits])
        ax.set_xscale("log")
        ax.set_xlim(lo, hi)
        ax.set_ylim(-0.6, len(fits) - 0.4)
        ax.set_xlabel("$I_2$: relative L1 distance of the force histories (dimensionless)")
        ax.set_title(
            "The named contact models: I2 of each fit (consistent: every criterion within\n"
            "its noise limit; failed: the fit degenerated, I2 of the law it ended at)"
        )
        return save(fig, stem)
