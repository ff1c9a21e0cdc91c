"""The sentences a verdict adds about the law's trajectory: a trajectory that has not
settled over the record's span, a steady orbit that is unknown, and contact counts that
differ between the folded cycles yet agree within the record's noise."""

import numpy as np

__all__ = ["JUDGED_OVER_SPAN", "transient_notes", "contacts_note"]


JUDGED_OVER_SPAN = "the law is judged against the record's own span"
"""How every note on an unsettled trajectory ends (the reports look for it)."""


def _gap_text(transient, orbit):
    """Where the law's trajectory is, over the record's last cycles, from ``orbit``."""
    if np.isinf(transient):
        return f"over its last cycles it has contact force where {orbit} has none"
    return f"over its last cycles it is I2 = {transient:.3g} from {orbit}"


def transient_notes(transient_mismatch, settled, transient, reg, ss, *, why=""):
    """What the verdict says when the law's trajectory from the measured state has not
    settled over the record's span (the law's trajectory, not the record), or when the law's
    steady orbit is unknown (``why``)."""
    notes = []
    if why:
        notes.append(
            f"the law's regime is unknown: {why}; {JUDGED_OVER_SPAN}"
            if transient_mismatch
            else f"the law's steady orbit is unknown: {why}"
        )
    elif transient_mismatch:
        if ss is not None and ss.periodic:
            what = f"has not settled by the record's end: it tends to {reg['simulated']}" + (
                "" if transient is None else f" ({_gap_text(transient, 'that orbit')})"
            )
        else:
            what = f"reaches no stable periodic orbit ({reg['simulated']})"
        notes.append(
            f"the record reads {reg['measured']}, but this law's trajectory from the "
            f"measured state {what}; {JUDGED_OVER_SPAN}"
        )
    elif not settled and transient is not None:
        gap = _gap_text(transient, "the law's steady orbit")
        notes.append(
            "the law's trajectory from the measured state has not settled by the record's "
            f"end: {gap}; {JUDGED_OVER_SPAN}"
        )
    return notes


def _contacts(n):
    return f"{n} contact" if n == 1 else f"{n} contacts"


def contacts_note(simulated, measured, folded, own=None):
    """Why the contacts per cycle are taken to agree though the law's folded cycle shows
    ``simulated`` and the record ``measured`` (its folded cycle ``folded``; ``own``: the
    onsets per cycle of the law's own periodic motion, None when unknown)."""
    if own == measured:
        why = (
            f"the law's own motion has {_contacts(own)} (onsets of its steady orbit from "
            "the record's state)"
        )
    elif simulated == folded:
        why = (
            f"the record's folded cycle shows {_contacts(folded)} too (its cycles taken one "
            f"by one show {measured})"
        )
    else:
        why = f"the law's own records with the record's noise show the record's {_contacts(folded)}"
    return (
        f"the law's folded cycle shows {_contacts(simulated)} and the record "
        f"{_contacts(measured)}; {why}, so within the record's noise and sampling the "
        "contact counts agree (a contact split or hidden near the threshold)"
    )
