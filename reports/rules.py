"""The consistency rule as the reports state it, rendered from its constants
(:mod:`discovery.vibroimpact.verify.evaluation`), so a report can never state another rule
than the verdict applied."""

__all__ = ["rule_text", "rule_tex"]


def _constants():
    """``(factors, spread, slack)`` of the rule, read when a report states it (importing the
    verdict's module loads the simulators: `vidi --help` must not)."""
    from discovery.vibroimpact.verify import (
        CONSISTENCY_FACTORS,
        CONSISTENCY_SLACK,
        CONSISTENCY_SPREAD,
    )

    return CONSISTENCY_FACTORS, CONSISTENCY_SPREAD, CONSISTENCY_SLACK


def _by_factor(factors):
    """``[(factor, [criteria])]`` in the order the criteria are held."""
    groups = {}
    for name, f in factors.items():
        groups.setdefault(f, []).append(name)
    return list(groups.items())


def _and(items):
    return items[0] if len(items) == 1 else ", ".join(items[:-1]) + " and " + items[-1]


def rule_text():
    """The rule in words: ``f times the noise floor, f = 2 for I2 and I4 and 1.25 for I5,
    or the floor plus 3 of its standard deviations, plus 0.005``."""
    factors, spread, slack = _constants()
    each = _and([f"{f:g} for {_and(names)}" for f, names in _by_factor(factors)])
    return (
        f"f times the noise floor, f = {each}, or the floor plus {spread:g} of its standard "
        f"deviations, plus {slack:g}"
    )


def rule_tex():
    """The rule as LaTeX source (the templates mark it as such): ``$\\max(f\\,floor,
    floor + 3\\,sd) + 0.005$, with $f = 2$ for $I_2$ and $I_4$ and $f = 1.25$ for
    $I_5$``."""
    factors, spread, slack = _constants()
    each = _and(
        [
            f"$f = {f:g}$ for {_and([f'$I_{n[1:]}$' for n in names])}"
            for f, names in _by_factor(factors)
        ]
    )
    return (
        rf"$\max(f\,\text{{floor}}, \text{{floor}} + {spread:g}\,\text{{sd}}) + "
        rf"{slack:g}$, with {each}"
    )
