"""The catalogue of named physical effects: each a candidate "omitted variable".

An effect extends a :class:`Model` through one general mechanism: it adds terms to the
force law (``terms``), or an observation model applied to the simulated force before it
is compared with the record (``observation``).  Nothing effect-specific enters the
simulator's hot loop.

Effects that need a law with a separate unloading branch, a hysteresis state, a
drifting mass or a support term (unloading damping, permanent set, mass loss, support
nonlinearity) need those extensions of the simulator first; they are not in the
catalogue yet, so no claim is ever made about them.
"""

from dataclasses import dataclass, field

import numpy as np

from ..impulse import Impulse
from ..law import ForceLaw, Term

__all__ = ["Parameter", "Effect", "Model", "EFFECTS", "effect", "first_order_lag"]


@dataclass(frozen=True)
class Parameter:
    """A parameter of an effect, with physical bounds."""

    name: str
    unit: str
    bounds: tuple


@dataclass(frozen=True)
class Effect:
    """A named physical effect (see the module docstring).

    Attributes
    ----------
    id : str
        Stable identifier.
    title, explanation, enters, signature : str
        What it is, the physics, how it enters the model, how it shows in a record.
    parameters : tuple of Parameter
    phases : tuple of str
        The impact phases where its signature concentrates (checked against the
        localisation, :func:`discovery.explain.localise`).
    terms : tuple of str
        Force-law terms it adds (law effects).
    observation : str or None
        Name of the observation model it adds (observation effects).
    """

    id: str
    title: str
    explanation: str
    enters: str
    signature: str
    parameters: tuple
    phases: tuple
    terms: tuple = ()
    observation: str | None = None

    def applicable(self, model):
        """Whether the effect can still be added to ``model``."""
        if self.terms:
            return not set(self.terms) & set(model.law.names)
        return self.observation not in model.observation

    def as_dict(self):
        return {"id": self.id, "title": self.title, "explanation": self.explanation,
                "enters": self.enters, "signature": self.signature,
                "parameters": [{"name": p.name, "unit": p.unit, "bounds": list(p.bounds)}
                               for p in self.parameters],
                "phases": list(self.phases)}


def first_order_lag(impulse, tau):
    """The periodic force history seen through a first-order sensor ``tau F' + F = F_true``.

    Exact for the periodic signal: the history is sampled on a fine uniform grid (64
    points per ``tau``, at least 8192 per cycle) and filtered in the frequency domain by
    ``1 / (1 + i omega tau)``.
    """
    if tau <= 0:
        return impulse
    W = impulse.duration
    n = int(min(2**18, max(8192, 2 ** np.ceil(np.log2(64 * W / tau)))))
    t = np.arange(n) * (W / n)
    F = impulse.evaluate(t, "right")
    w = 2 * np.pi * np.fft.rfftfreq(n, W / n)
    G = np.fft.irfft(np.fft.rfft(F) / (1 + 1j * w * tau), n)
    G = np.maximum(G, 0.0)
    on = G > 1e-9 * max(float(np.max(G)), 1e-300)
    starts = np.flatnonzero(np.diff(np.concatenate([[False], on]).astype(np.int8)) == 1)
    ends = np.flatnonzero(np.diff(np.concatenate([on, [False]]).astype(np.int8)) == -1)
    support = np.column_stack([t[starts], np.minimum(t[ends] + W / n, W)]) if starts.size \
        else np.zeros((0, 2))
    tt = np.concatenate([t, [W]])
    GG = np.concatenate([G, G[:1]])
    return Impulse(t=tt, F=GG, duration=W, support=support, n_periods=impulse.n_periods,
                   onset=impulse.onset, onsets=impulse.onsets)


_OBSERVATIONS = {"sensor_lag": first_order_lag}


@dataclass(frozen=True)
class Model:
    """A force law with the observation models added to it.

    Attributes
    ----------
    law : ForceLaw
    observation : dict
        ``{name: parameter}``, e.g. ``{"sensor_lag": 2e-5}`` (a time constant [s]).
    effects : tuple of str
        Ids of the effects added so far.
    """

    law: ForceLaw
    observation: dict = field(default_factory=dict)
    effects: tuple = ()

    def observe(self):
        """The observation model ``Impulse -> Impulse`` (None when there is none)."""
        if not self.observation:
            return None
        items = sorted(self.observation.items())

        def apply(impulse):
            for name, value in items:
                impulse = _OBSERVATIONS[name](impulse, value)
            return impulse

        return apply

    def with_term(self, term, coefficient, effect_id):
        law = ForceLaw(self.law.terms + (Term.parse(term),),
                       self.law.coefficients + (float(coefficient),))
        return Model(law, dict(self.observation), self.effects + (effect_id,))

    def with_observation(self, name, value, effect_id):
        return Model(self.law, {**self.observation, name: float(value)},
                     self.effects + (effect_id,))

    def as_dict(self):
        return {"terms": list(self.law.names), "coefficients": self.law.as_dict(),
                "observation": dict(self.observation), "effects": list(self.effects),
                "latex": self.law.latex(), "text": self.law.to_text()}


EFFECTS = (
    Effect(
        id="penetration_velocity_coupling",
        title="Penetration-velocity coupling (Hunt-Crossley type damping)",
        explanation="The contact's damping grows with the penetration: a damping term "
                    "z*zd. The force then starts near zero instead of jumping at the onset, "
                    "its maximum moves from the onset toward the middle of the impact (the "
                    "paper's Fig. 8), and the restitution falls as the impact velocity rises.",
        enters="a force-law term c*z*zd, c >= 0",
        signature="onset jump and early loading smaller than a linear damper's; the peak "
                  "later in the impact",
        parameters=(Parameter("c_z_zd", "N s/m^2", (0.0, np.inf)),),
        phases=("onset", "loading", "peak"),
        terms=("z*zd",)),
    Effect(
        id="hertzian_stiffening",
        title="Hertzian stiffening",
        explanation="Contact stiffness that rises with the penetration, as for curved "
                    "elastic bodies (Hertz: F ~ z^1.5). The contact time then shortens as the "
                    "impact velocity rises.",
        enters="a force-law term k*z^1.5, k >= 0",
        signature="the force grows faster than linearly late in loading; a shorter contact",
        parameters=(Parameter("k_z1.5", "N/m^1.5", (0.0, np.inf)),),
        phases=("loading", "peak", "unloading"),
        terms=("z^1.5",)),
    Effect(
        id="sensor_lag",
        title="Force-sensor lag",
        explanation="The force sensor (or its amplifier and filter) has its own dynamics: a "
                    "first-order low-pass tau F' + F = F_true. The recorded onset is smeared "
                    "and the whole impulse lags.",
        enters="an observation model on the simulated force (the simulation is unchanged)",
        signature="a smeared onset, a phase lag, force after the separation",
        parameters=(Parameter("tau", "s", (0.0, 5e-3)),),
        phases=("onset", "separation"),
        observation="sensor_lag"),
)


def effect(effect_id):
    """The catalogue entry ``effect_id``."""
    for e in EFFECTS:
        if e.id == effect_id:
            return e
    from ..errors import InputError

    raise InputError(f"unknown effect {effect_id!r}; the catalogue has "
                     f"{', '.join(e.id for e in EFFECTS)}")
