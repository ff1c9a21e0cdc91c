"""The catalogue of named physical effects: each a candidate "omitted variable".

An effect extends a :class:`Model` through one general mechanism, :meth:`Model.with_effect`:
its ``target`` says where its one parameter enters,

``term``         a loading term of the force law (the paper's polynomial);
``unloading``    a term of the law's own unloading branch
(:class:`~discovery.vibroimpact.model.law.ForceLaw`);
``set``          the law's permanent-set fraction;
``scenario``     a machine parameter (``k3``, ``mass_loss``:
:class:`~discovery.vibroimpact.model.scenario.Scenario`);
``observation``  an observation model applied to the simulated force before it is compared
                 with the record (a sensor's dynamics).

The simulator reads all of them from its parameter vector and law arrays; nothing
effect-specific enters its hot loop.
"""

from dataclasses import dataclass, field, replace

import numpy as np

from ...catalogue import TARGETS, Effect, Parameter, lookup
from ..model.law import ForceLaw, Term
from ..verify.sensors import first_order_lag, first_order_lag_at, observation

__all__ = [
    "Parameter",
    "Effect",
    "Model",
    "EFFECTS",
    "TARGETS",
    "effect",
    "KnownEffects",
    "first_order_lag",
    "first_order_lag_at",
    "small_step",
    "drift_fitted",
]


def _term(name):
    return Term.parse(name)


def _set_term(terms, coefs, name, value):
    t = _term(name)
    if t in terms:
        i = terms.index(t)
        coefs = coefs[:i] + (float(value),) + coefs[i + 1 :]
        return terms, coefs
    return terms + (t,), coefs + (float(value),)


@dataclass(frozen=True)
class Model:
    """A force law with the machine changes and observation models added to it.

    Attributes
    ----------
    law : ForceLaw
        With its unloading branch, if an effect gave it one.
    observation : dict
        ``{name: parameter}``, e.g. ``{"sensor_lag": 2e-5}`` (a time constant [s]).
    scenario : dict
        Machine parameters changed from the record's scenario, e.g. ``{"k3": 3e12}``.
    effects : tuple of str
        Ids of the effects added so far.
    held : tuple of str
        Ids of added effects whose parameter another channel of the record reads, held
        where it reads it and not refitted with the law (stiffening supports the machine's
        own equations read before the loop:
        :func:`~discovery.vibroimpact.explain.starts.supports_read`).
    fit_drift : bool
        Whether :func:`discovery.identify` fits a drift effect's parameter too (records
        compared over their span, where each block starts with the mass left); by default
        the drift channel fits it.  The machine parameters such an effect is refitted with
        (:attr:`~discovery.catalogue.Effect.machine`) are fitted too where ``scenario``
        holds them (:func:`drift_fitted` puts them there).
    """

    law: ForceLaw
    observation: dict = field(default_factory=dict)
    effects: tuple = ()
    scenario: dict = field(default_factory=dict)
    held: tuple = ()
    fit_drift: bool = field(default=False, compare=False)

    # ------------------------------------------------------------- one mechanism
    def value(self, eff):
        """The current value of an effect's parameter (0 when it is absent)."""
        law, key = self.law, eff.key
        if eff.target == "term":
            return law.as_dict().get(_term(key).name, 0.0)
        if eff.target == "unloading":
            d = dict(zip([t.name for t in law.unloading], law.unloading_coefficients, strict=True))
            return d.get(_term(key).name, 0.0)
        if eff.target == "set":
            return law.permanent_set
        if eff.target == "scenario":
            return float(self.scenario.get(key, 0.0))
        return float(self.observation.get(key, 0.0))

    def with_effect(self, eff, value, add=True):
        """The model with the effect's parameter set to ``value`` (and, with ``add``, the
        effect's id recorded)."""
        law, obs, scen = self.law, dict(self.observation), dict(self.scenario)
        if eff.target == "term":
            law = ForceLaw(
                *_set_term(law.terms, law.coefficients, eff.key, value),
                law.unloading,
                law.unloading_coefficients,
                law.permanent_set,
            )
        elif eff.target == "unloading":
            terms, coefs = _set_term(law.unloading, law.unloading_coefficients, eff.key, value)
            law = law.with_unloading(terms, coefs)
        elif eff.target == "set":
            law = law.with_unloading(permanent_set=float(value))
        elif eff.target == "scenario":
            scen[eff.key] = float(value)
        else:
            obs[eff.key] = float(value)
        ids = self.effects + ((eff.id,) if add and eff.id not in self.effects else ())
        return replace(self, law=law, observation=obs, effects=ids, scenario=scen)

    def without_effect(self, eff):
        """The model with the effect taken out (its term, unloading term, set, machine
        change or observation model removed, and its id)."""
        law, obs, scen = self.law, dict(self.observation), dict(self.scenario)
        if eff.target == "term":
            keep = [i for i, t in enumerate(law.terms) if t != _term(eff.key)]
            law = replace(
                law,
                terms=tuple(law.terms[i] for i in keep),
                coefficients=tuple(law.coefficients[i] for i in keep),
            )
        elif eff.target == "unloading":
            keep = [i for i, t in enumerate(law.unloading) if t != _term(eff.key)]
            law = law.with_unloading(
                tuple(law.unloading[i] for i in keep),
                tuple(law.unloading_coefficients[i] for i in keep),
            )
        elif eff.target == "set":
            law = law.with_unloading(permanent_set=0.0)
        elif eff.target == "scenario":
            scen.pop(eff.key, None)
        else:
            obs.pop(eff.key, None)
        ids = tuple(i for i in self.effects if i != eff.id)
        held = tuple(i for i in self.held if i != eff.id)
        return replace(self, law=law, observation=obs, effects=ids, scenario=scen, held=held)

    def with_law(self, law):
        return replace(self, law=law)

    # ------------------------------------------- the parameters identify() fits
    def free_effects(self):
        """Added effects whose parameter is not a coefficient of the loading law, nor held
        where another channel reads it (:attr:`held`)."""
        return [
            e
            for e in (effect(i) for i in self.effects)
            if e.target != "term"
            and e.id not in self.held
            and (self.fit_drift or "drift" not in e.phases)
        ]

    def free_machine(self):
        """The machine parameters fitted with a drift's (:attr:`fit_drift`): those its
        effects are refitted with that :attr:`scenario` holds."""
        keys = [k for e in self.free_effects() for k in e.machine if k in self.scenario]
        return tuple(dict.fromkeys(keys))

    @property
    def coefficients(self):
        """The law's coefficients, then the added effects' other parameters, then the
        machine parameters fitted with them (:meth:`free_machine`)."""
        own = tuple(self.value(e) for e in self.free_effects())
        return self.law.coefficients + own + tuple(self.scenario[k] for k in self.free_machine())

    @property
    def names(self):
        own = [e.parameters[0].name for e in self.free_effects()]
        return list(self.law.names) + own + list(self.free_machine())

    def with_coefficients(self, values):
        """The model with new :attr:`coefficients` (each effect parameter clipped to its
        physical bounds, a machine parameter kept positive), so :func:`discovery.identify`
        fits them jointly."""
        values = [float(v) for v in values]
        n, effects, machine = len(self.law.coefficients), self.free_effects(), self.free_machine()
        m = self.with_law(self.law.with_coefficients(values[:n]))
        for e, v in zip(effects, values[n : n + len(effects)], strict=True):
            lo, hi = e.parameters[0].bounds
            m = m.with_effect(e, min(max(v, lo), hi), add=False)
        scen = dict(m.scenario)
        for k, v in zip(machine, values[n + len(effects) :], strict=True):
            scen[k] = max(v, 1e-12 * abs(self.scenario[k]))
        return replace(m, scenario=scen)

    def apply(self, scenario, record=None):
        """The scenario ``record`` (a :class:`~discovery.vibroimpact.verify.Reference`) is
        compared with: the record's, with this model's machine changes.  A mass loss applies
        to a record compared over its span (each block starts with the mass left after the
        record's impacts before it); a drifting record has no steady state, so its averaged
        cycle (a record without positions, or ``record`` None) stays compared with the
        scenario's mass, and its drift is checked orbit by orbit
        (:mod:`discovery.vibroimpact.explain.drift`)."""
        spans = getattr(record, "span", None) is not None
        changes = {k: v for k, v in self.scenario.items() if spans or k != "mass_loss"}
        return scenario.replace(**changes) if changes else scenario

    def observe(self):
        """The observation model ``Impulse -> Impulse`` (None when there is none;
        :func:`~discovery.vibroimpact.verify.sensors.observation`)."""
        return observation(self.observation)

    def as_dict(self):
        law = self.law
        return {
            "terms": list(law.names),
            "coefficients": law.as_dict(),
            "unloading": dict(
                zip([t.name for t in law.unloading], law.unloading_coefficients, strict=True)
            ),
            "permanent_set": law.permanent_set,
            "scenario": dict(self.scenario),
            "observation": dict(self.observation),
            "effects": list(self.effects),
            "held": list(self.held),
            "latex": law.latex(),
            "text": law.to_text(),
        }

    def changes(self):
        """What the model adds beside its law, as text: its machine changes and observation
        models (``"m2 = 6767; mass_loss = 0.0056"``; "" for none)."""
        extra = [f"{k} = {v:.4g}" for k, v in sorted(self.scenario.items())]
        extra += [f"observed through {k} = {v:.4g}" for k, v in sorted(self.observation.items())]
        return "; ".join(extra)

    def __str__(self):
        extra = self.changes()
        return str(self.law) + (f"  ({extra})" if extra else "")


def drift_fitted(model, scenarios):
    """``model`` with its drift effects' parameters fitted (:attr:`Model.fit_drift`), each
    with the machine parameters it is refitted with (:attr:`~discovery.catalogue.Effect.machine`)
    starting from the records' machine (``scenarios``) where the model has not changed them
    and the records' machines agree on them."""
    m = replace(model, fit_drift=True)
    scen = dict(m.scenario)
    for e in m.free_effects():
        for k in e.machine:
            values = {float(getattr(sc, k)) for sc in scenarios}
            if k not in scen and len(values) == 1:
                scen[k] = values.pop()
    return replace(m, scenario=scen)


def small_step(eff, scenario, peak, *, tau, v, z0):
    """A small value of an effect's parameter: one that changes the force by about 1 % of
    its peak (``peak`` [N], at the typical penetration ``z0`` and impact velocity ``v``),
    1 % of the contact time ``tau`` for a time constant, a 2 % set, supports 1 % stiffer at
    the grid's excursion, or 0.2 % of the mass shed per impact (any other machine
    parameter)."""
    if eff.target in ("term", "unloading"):
        return 0.01 * peak / max(float(_term(eff.key)(z0, v)), 1e-300)
    if eff.target == "set":
        return 0.02
    if eff.target == "observation":
        return 0.01 * tau
    if eff.key == "offset":
        return 0.01 * z0
    if eff.key == "k3":
        x = abs(float(scenario.initial_state()[0])) + scenario.scales()[0]
        return 0.01 * max(scenario.k1, 1e-300) / x**2
    return 0.002


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
        target="term",
        key="z*zd",
    ),
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
        target="term",
        key="z^1.5",
    ),
    Effect(
        id="unloading_damping",
        title="Damping while unloading",
        explanation="The contact dissipates energy in restitution too (wet sand, a rubber "
        "pad): a damper that keeps acting while the bodies separate, so the "
        "force falls below the elastic branch and reaches zero before the "
        "penetration does; the bodies then part with the surface still "
        "indented.",
        enters="a term d*zd of the law's unloading branch (acting at the signed velocity, "
        "lowering the force while the bodies separate), d >= 0",
        signature="the force reaches zero before zeta does; a weaker unloading and an "
        "earlier end of the force",
        parameters=(Parameter("d_zd", "N s/m", (0.0, np.inf)),),
        phases=("unloading", "separation"),
        target="unloading",
        key="zd",
        departs="the paper's condition (5) (a negative penetration velocity has no effect "
        "on the force): a real contact can dissipate energy while unloading, and "
        "its restitution is then lower than any law obeying (5) with the same "
        "loading can give",
    ),
    Effect(
        id="permanent_set",
        title="Permanent set (plastic indentation, Walton-Braun)",
        explanation="The moulding's sand (or the grid's pad) yields under load: unloading "
        "is stiffer than loading and ends at a residual penetration, a share s "
        "of the impact's largest one (linear law: loading k*z, unloading "
        "k/(1-s)*(z - s*z_max)). The set is recovered between impacts.",
        enters="the law's permanent-set fraction s in [0, 0.95]",
        signature="unloading ends at a residual penetration: the force drops to zero "
        "before the bodies separate, faster than the loading rose",
        parameters=(Parameter("set", "1", (0.0, 0.95)),),
        phases=("unloading", "separation"),
        target="set",
        key="permanent_set",
        departs="the paper's elastic unloading P(zeta, 0): a plastic contact does not give "
        "back its loading energy, whatever the velocity",
    ),
    Effect(
        id="support_nonlinearity",
        title="Stiffening grid supports",
        explanation="The grid's springs stiffen with the deflection (rubber buffers, coil "
        "springs closing up): their force is k1*w1 + k3*w1^3. The grid's free "
        "motion, and with it the impact velocity, depart from a linear "
        "suspension's.",
        enters="the supports' cubic stiffness k3 >= 0 (a machine parameter)",
        signature="the disagreement lies in the grid's free motion; the impacts shift with it",
        parameters=(Parameter("k3", "N/m^3", (0.0, np.inf)),),
        phases=("grid", "free", "onset"),
        target="scenario",
        key="k3",
    ),
    Effect(
        id="mass_loss",
        title="Mass shed at every impact",
        explanation="The moulding loses sand at each impact, so its mass falls through the "
        "record: the impacts drift (the peak force and the contact change "
        "impact by impact) and the record has no steady state. It shows only "
        "across the impacts of a record, not in its averaged cycle.",
        enters="the share of the moulding's mass shed per impact, in [0, 0.5] (a machine "
        "parameter); fitted on the one-period-ahead predictions of every period",
        signature="a trend of the peak force across the impacts that the model's "
        "predictions from the record's own states do not follow",
        parameters=(Parameter("loss", "1/impact", (0.0, 0.5)),),
        phases=("drift",),
        target="scenario",
        key="mass_loss",
        machine=("m2",),
    ),
    Effect(
        id="contact_offset",
        title="Contact offset (a clearance, or the position sensors' zero offset)",
        explanation="The contact does not start where the recorded penetration w1 - w2 "
        "crosses zero but at a recorded penetration delta0: a clearance between the "
        "bodies, or position sensors whose zeros differ by delta0. The force then "
        "acts only beyond delta0, and a law fitted from zero penetration trades its "
        "spring for damping.",
        enters="the machine's contact offset delta0 [m] (the recorded penetration at which "
        "contact starts; a record with positions)",
        signature="the force starts and ends at a recorded penetration that is not zero",
        parameters=(Parameter("delta0", "m", (-1.0, 1.0)),),
        phases=("onset", "separation"),
        target="scenario",
        key="offset",
    ),
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
        target="observation",
        key="sensor_lag",
    ),
)


def effect(effect_id):
    """The catalogue entry ``effect_id`` (:func:`discovery.catalogue.lookup`)."""
    return lookup(EFFECTS, effect_id)


class KnownEffects:
    """The spec of effects found before the loop (:func:`~discovery.explain`'s ``known``):
    ``{effect id: value}``, each a catalogue effect with its value within its parameter's
    bounds."""

    def describe(self):
        return "a dict {effect id: value}"

    def __call__(self, where, value):
        from ...errors import InputError, VidiTypeError

        if not isinstance(value, dict):
            raise VidiTypeError(f"{where} must be {self.describe()}; got {type(value).__name__}")
        ids = [e.id for e in EFFECTS]
        for eid, v in value.items():
            if eid not in ids:
                raise InputError(
                    f"{where}: unknown effect {eid!r}; the catalogue has {', '.join(ids)}"
                )
            eff = lookup(EFFECTS, eid)
            lo, hi = eff.parameters[0].bounds
            if not (isinstance(v, int | float) and lo <= v <= hi):
                raise InputError(
                    f"{where}: {eid}'s {eff.parameters[0].name} must be a number in "
                    f"[{lo:g}, {hi:g}]; got {v!r}"
                )
