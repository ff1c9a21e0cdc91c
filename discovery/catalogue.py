"""The missing-effect mechanism, shared by both systems: an :class:`Effect` is a named
physical effect with one bounded :class:`Parameter` and the place it enters a model; each
system keeps its own catalogue (:data:`discovery.vibroimpact.explain.EFFECTS`,
:data:`discovery.ueda.effects.EFFECTS`) and looks entries up here, with one message for
an unknown name.
"""

from dataclasses import dataclass

from .errors import InputError

__all__ = ["TARGETS", "Parameter", "Effect", "lookup", "select"]


#: where an effect's parameter can enter a model
TARGETS = ("term", "unloading", "set", "scenario", "observation")


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
        Its one parameter, with physical bounds.
    phases : tuple of str
        The impact phases where its signature concentrates (checked against the
        localisation, :func:`discovery.vibroimpact.explain.localise`); ``"grid"`` for the grid's
        free motion, ``"drift"`` for a trend across the impacts of a record.
    target : str
        Where the parameter enters (:data:`TARGETS`).
    key : str
        The term, scenario field or observation model it sets.
    departs : str
        The paper's condition it departs from, and why a user may still need it.
    terms : tuple of str
        For a system whose effects are terms of its own model (the Ueda oscillator's
        catalogue): the terms it adds; ``target`` is then ``"term"`` and ``key`` the first.
    machine : tuple of str
        Machine parameters a record fixes only together with this effect's, refitted with
        it where its parameter is fitted on the records' spans (a mass shed per impact and
        the moulding's mass at the record's start: a calibration that read one a little
        high reads the other high too, and the loss alone cannot undo it).
    """

    id: str
    title: str
    explanation: str
    enters: str
    signature: str
    parameters: tuple
    phases: tuple
    target: str = ""
    key: str = ""
    departs: str = ""
    terms: tuple = ()
    machine: tuple = ()

    def __post_init__(self):
        if not self.target and self.terms:
            object.__setattr__(self, "target", "term")
            object.__setattr__(self, "key", self.terms[0])
        if self.target not in TARGETS or not self.key:
            raise InputError(f"effect {self.id}: target must be one of {TARGETS}, with a key")

    def applicable(self, model):
        """Whether the effect can still be added to ``model`` (its parameter is zero)."""
        return model.value(self) == 0.0

    def as_dict(self):
        return {
            "id": self.id,
            "title": self.title,
            "explanation": self.explanation,
            "enters": self.enters,
            "signature": self.signature,
            "parameters": [
                {"name": p.name, "unit": p.unit, "bounds": list(p.bounds)} for p in self.parameters
            ],
            "phases": list(self.phases),
            "target": self.target,
            "key": self.key,
            "departs_from_paper": self.departs,
            "refitted_with": list(self.machine),
        }


def lookup(catalogue, effect_id):
    """The entry ``effect_id`` of ``catalogue`` (a sequence of :class:`Effect`)."""
    for e in catalogue:
        if e.id == effect_id:
            return e
    raise InputError(
        f"unknown effect {effect_id!r}; the catalogue has {', '.join(e.id for e in catalogue)}"
    )


def select(catalogue, ids, where="effects"):
    """The entries of ``catalogue`` named in ``ids`` (catalogue order; ``None``: all);
    an unknown or empty selection is refused in one line naming ``where``."""
    if ids is None:
        return list(catalogue)
    ids = [ids] if isinstance(ids, str) else list(ids)
    known = [e.id for e in catalogue]
    unknown = sorted(set(ids) - set(known))
    if unknown or not ids:
        raise InputError(
            f"{where}: unknown effect(s) {', '.join(unknown) or '(none given)'}; "
            f"the catalogue has {', '.join(known)}"
        )
    return [e for e in catalogue if e.id in ids]
