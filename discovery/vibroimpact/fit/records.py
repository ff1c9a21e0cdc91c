"""The records a fit compares with: pairing scenarios and records, a record's contact scales
and start coefficients, what a model fits (:func:`model_parts`), the measured cycles with
their residual weights, and the verdict of a law against several records.
"""

import numpy as np

from ...errors import InputError
from ..data.impulse import Impulse
from ..model.law import ForceLaw
from ..verify import Reference

__all__ = [
    "pair_records",
    "as_records",
    "contact_scales",
    "record_start",
    "model_parts",
    "cycle_pairs",
]


def pair_records(scenario, records):
    """``[(scenario, record), ...]``: one scenario per record, or one for all; a single
    scenario or record may be given bare."""
    scs = list(scenario) if isinstance(scenario, list | tuple) else [scenario]
    recs = list(records) if isinstance(records, list | tuple) else [records]
    if len(scs) == 1 and len(recs) > 1:
        scs = scs * len(recs)
    if not recs or len(scs) != len(recs):
        raise InputError(
            f"{len(recs)} record(s) but {len(scs)} scenario(s): give one scenario "
            "per record (or one for all)"
        )
    return list(zip(scs, recs, strict=True))


def as_records(scenario, reference):
    """``[(scenario, Reference), ...]`` from one pair or from two equal-length sequences.

    ``reference`` may be a :class:`~discovery.vibroimpact.verify.Reference`, a
    :class:`~discovery.vibroimpact.data.measurement.Measurement` (prepared with
    :meth:`Reference.from_measurement`) or an exact
    :class:`~discovery.vibroimpact.data.impulse.Impulse`.
    """
    out = []
    for sc, ref in pair_records(scenario, reference):
        if isinstance(ref, Impulse):
            ref = Reference.exact(ref, source="impulse")
        elif not isinstance(ref, Reference):
            ref = Reference.from_measurement(ref, sc)
        out.append((sc, ref))
    return out


def contact_scales(scenario, reference):
    """Typical contact time [s], impact velocity [m/s] and penetration ``v tau / pi`` [m] of
    a record (the scenario's period and motion scale when the record lacks them)."""
    E = reference.impulse
    tau = float(np.median(E.support[:, 1] - E.support[:, 0])) if len(E.support) else scenario.period
    v = reference.noise.get("impact_velocity") if reference.noise else None
    if not (v is not None and v > 0):
        # no onset slope, or one that noise (or a contact shorter than the slope's window)
        # turned negative: the drive's velocity scale
        v = scenario.scales()[1]
    return tau, v, v * tau / np.pi


def record_start(scenario, reference, terms):
    """Start coefficients for ``terms`` from the record alone (a spring-dashpot estimate, to
    be refined by simulation): stiffness ``k = mu (pi / tau)^2`` from the contact time and
    the reduced mass, damping ``c = F(0+) / v`` from the force jump at onset (5 % of
    critical without a jump), each term scaled to give that force at the typical
    penetration ``z0``: elastic terms (``b = 0``) ``k z0 / z0^a``, the others ``c / z0^a``.

    Returns
    -------
    ndarray
        One coefficient per term.
    """
    E = reference.impulse
    tau, v, z0 = contact_scales(scenario, reference)
    mu = scenario.m1 * scenario.m2 / (scenario.m1 + scenario.m2)
    k = mu * (np.pi / tau) ** 2
    jump = float(E.evaluate(0.0, "right"))
    c = jump / v if jump > 0.05 * E.peak else 0.1 * np.sqrt(k * mu)
    return np.array([(k * z0 if t.b == 0 else c) / z0**t.a for t in terms])


def _named(model):
    return dict(zip(model.names, model.coefficients, strict=True))


def model_parts(model, observe=None):
    """``(law, (scenario, record) -> scenario, observation)`` of what :func:`identify` fits:
    a :class:`ForceLaw`, or a model with more parameters than a law's coefficients (the
    missing-effect workflow's :class:`~discovery.vibroimpact.explain.Model`: ``coefficients``,
    ``names``, ``with_coefficients``, ``law``, ``apply(scenario, record)``, ``observe()``).
    The machine a record is simulated with may depend on how the record is compared (a
    mass loss per impact applies to a record compared over its span only).  ``observe``:
    the observation model of a known sensor, used where the model has none of its own (a
    named contact model; an explained model that fits a lag reads the force through its
    own)."""
    if isinstance(model, ForceLaw):
        return model, (lambda sc, ref=None: sc), observe
    own = model.observe()
    return model.law, model.apply, observe if own is None else own


def _measured_cycles(ref):
    """The measured cycles a record is compared on: every block of a record span, else
    the one aligned cycle."""
    return list(ref.blocks) if getattr(ref, "blocks", ()) else [ref.impulse]


def cycle_pairs(ev, ref):
    """``[(measured, simulated), ...]`` of an evaluation, one per compared cycle."""
    return ev.blocks or [(ref.impulse, ev.simulated)]


def _residual_weights(ref):
    """Per measured cycle: trapezoid-like sample spacing, normalised so that the sum of
    squared residuals of a cycle is its I3^2, times the square root of its share of the
    record's cycles."""
    cycles = _measured_cycles(ref)
    n = np.array([max(E.n_cycles, 1) for E in cycles], dtype=float)
    share = np.sqrt(n / n.sum())
    return [
        s * np.sqrt(np.gradient(E.t) / max(np.trapezoid(E.F**2, E.t), 1e-300))
        for E, s in zip(cycles, share, strict=True)
    ]


def records_verdict(evaluations, text):
    """One sentence on a law against several records (each an Evaluation, ``text(ev)`` its
    verdict): consistent with all, or the records it is inconsistent with, every one's
    verdict in full (none is cut to "(and 1 more)")."""
    bad = [(i, ev) for i, ev in enumerate(evaluations) if not ev.consistent]
    if not bad:
        return f"consistent with all {len(evaluations)} records"
    if len(bad) == 1:
        i, ev = bad[0]
        return f"inconsistent with record {i + 1}: {text(ev)}"
    return f"inconsistent with {len(bad)} of {len(evaluations)} records: " + "; ".join(
        f"record {i + 1}: {text(ev)}" for i, ev in bad
    )
