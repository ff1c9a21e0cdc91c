"""What a discovery fits and checks against: every record's contact samples and
reference, the certified sparse regression on the samples, the required terms, stability
selection."""

from dataclasses import dataclass

import numpy as np

from ...errors import InputError, VidiError
from ..data.samples import ContactSamples, contact_samples, join_samples
from ..model.law import Term
from ..model.library import Library
from .certified_fit import CertifiedSparseFit, RegressionSettings


def _sign_vector(signs, library):
    """``{term: +1 | -1 | 0}`` as the estimator's per-term sign vector."""
    lib = library if isinstance(library, Library) else Library.parse(library)
    names = [t.name for t in lib.terms]
    out = np.zeros(len(names))
    for key, sign in signs.items():
        try:
            name = Term.parse(str(key).strip()).name
        except VidiError:
            name = None
        if name not in names:
            raise InputError(f"signs: term {key!r} is not in the library ({', '.join(names)})")
        if sign not in (-1, 0, 1):
            raise InputError(f"signs: the sign of {key} must be +1, -1 or 0; got {sign!r}")
        out[names.index(name)] = sign
    return out


def _required_terms(require, library):
    """The set of required term names, each checked against the library."""
    if isinstance(require, str):
        require = [r for r in require.split(",") if r.strip()]
    names = [t.name for t in library.terms]
    out = set()
    for r in require:
        try:
            name = Term.parse(str(r).strip()).name
        except VidiError:
            name = None
        if name not in names:
            raise InputError(
                f"required term {r!r} is not in the library ({', '.join(names)})"
                "; give library terms to --require, e.g. --require z"
            )
        out.add(name)
    return frozenset(out)


@dataclass(frozen=True, eq=False)
class _Evidence:
    """The records of one discovery as it fits and checks them.

    Attributes
    ----------
    pairs : list of (Scenario, Measurement)
        Every record with its scenario.
    parts : list of ContactSamples
        Every record's contact samples.
    samples : ContactSamples
        Their join (what the regression is fitted to).
    est : CertifiedSparseFit
        The certified sparse regression fitted to ``samples``.
    refs : list of (Scenario, Reference)
        Every record's reference (what each law is simulated against).
    """

    pairs: list
    parts: list
    samples: ContactSamples
    est: CertifiedSparseFit
    refs: list


def _contact_samples(pairs, derivative, average_cycles):
    """Contact samples of every record and their join: ``(parts, samples)``."""
    parts = [
        contact_samples(m, derivative=derivative, average_cycles=average_cycles, period=sc.period)
        for sc, m in pairs
    ]
    return parts, join_samples(parts)


def _regression(samples, settings):
    """The certified sparse regression ``CertifiedSparseFit`` with ``settings`` fitted to
    ``samples`` (``settings["signs"]`` may be ``{term: sign}``)."""
    if isinstance(settings.get("signs"), dict):
        settings = {**settings, "signs": _sign_vector(settings["signs"], settings["library"])}
    est = CertifiedSparseFit(RegressionSettings(**settings))
    est.fit(samples.X, samples.F, groups=samples.impact, sample_weight=samples.weight)
    return est


def _stability(est, samples, resamples, seed):
    """Stability selection's term frequencies over ``resamples`` bootstrap resamples of
    impacts (``{}`` for none)."""
    if not resamples:
        return {}
    s = samples
    return est.stability(
        s.X, s.F, s.impact, n_resamples=resamples, random_state=seed, sample_weight=s.weight
    )
