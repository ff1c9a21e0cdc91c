"""``calibrate``: the machine as the record shows it (see :mod:`.equations`)."""

import math
import time
from dataclasses import dataclass

import numpy as np

from ..._api._validate import Real, params
from ...errors import InputError
from ..data.measurement import Measurement
from ..data.periods import check_drive_period
from ..model.scenario import Scenario
from .equations import machine_rows
from .estimate import (
    cycle_draws,
    drive_phase,
    estimate,
    frame_residual,
    moulding_residual,
    parameter_names,
)
from .result import UNITS, Calibration
from .sensor import sensor_lag, with_lag
from .shedding import MATERIAL, shedding
from .units import check_units

__all__ = ["calibrate", "supports_reading", "CALIBRATED", "LOOSE", "MATERIAL"]

#: the parameters a calibration may estimate
CALIBRATED = ("m1", "c1", "k1", "k3", "A", "m2")
#: a parameter whose 95 % interval reaches further than this share of its value is loose
LOOSE = 0.25
#: a drive phase beyond this many degrees (and its interval) is noted
PHASE_NOTE = 3.0


def _machine_key(sc):
    return (sc.m1, sc.m2, sc.k1, sc.c1, sc.k3, sc.g, sc.mass_loss)


def _listed(x):
    return list(x) if isinstance(x, list | tuple) else [x]


@params(
    scenario=(Scenario, list, tuple),
    measurement=(Measurement, list, tuple),
    n_boot=Real(0, 10_000, integer=True),
    seed=Real(0, integer=True),
    keep=(tuple, list),
)
def calibrate(scenario, measurement, *, time_offset=0.0, n_boot=200, seed=0, keep=()):
    """The machine as the record shows it: ``m1, c1, k1, A, m2`` (and ``k3`` when the
    sheet's supports stiffen) estimated from the record's own motions and force.

    Parameters
    ----------
    scenario : Scenario or sequence of Scenario
        The designer's sheet: one for all records or one per record.  Records whose
        sheets give the same machine (masses, supports) are calibrated jointly, each with
        its own drive amplitude.
    measurement : Measurement or sequence of Measurement
        Records with ``t``, ``F``, ``w1``, ``w2`` (``v1``, ``v2`` used where present).  A
        record without positions is not calibrated: its sheet is used, and a note says so.
    time_offset : float or sequence of float
        Drive-clock time [s] of each record's ``t = 0``.
    n_boot : int
        Bootstrap replicates over the records' cycles, for the intervals.
    seed : int
        Seed of the bootstrap.
    keep : sequence of str
        Parameters held at the sheet's values (of ``m1, c1, k1, k3, A, m2``).

    Returns
    -------
    Calibration
        ``.scenario`` (``.scenarios``) is the machine to verify, fit and explain with.

    Raises
    ------
    InputError
        When a record's units or signs contradict any machine (positions in mm, a force
        in kN, motions measured downwards), or its sampling or drive frequency the sheet's
        (:func:`~discovery.vibroimpact.data.periods.check_drive_period`): one line naming
        the likely cause.
    """
    t_start = time.perf_counter()
    meas, sheets, offsets, keep = _inputs(scenario, measurement, time_offset, keep)
    for m, s in zip(meas, sheets, strict=True):  # a time column in ms is said as such first
        check_drive_period(m.t, m.F, s.period, m.source, motion=m.channels.get("w1"))
    rows = [machine_rows(m, s, float(o)) for m, s, o in zip(meas, sheets, offsets, strict=True)]
    for r, m, s in zip(rows, meas, sheets, strict=True):
        if r is not None:
            check_units(r, s, m.source)
    notes, parameters, residual, series = [], {}, {}, None
    phases = [(0.0, math.nan, math.nan)] * len(meas)
    used = list(sheets)
    groups = {}
    for k, s in enumerate(sheets):
        groups.setdefault(_machine_key(s), []).append(k)
    for members in groups.values():
        notes += [_uncalibrated_note(meas[k], sheets[k]) for k in members if rows[k] is None]
        members = [k for k in members if rows[k] is not None]
        if not members:
            continue
        lag = _sensor(members, rows, keep, sheets[members[0]], (n_boot, seed))
        shed = _shedding(members, rows, meas, sheets, offsets)
        if shed is not None and lag is not None:  # its rows made again: the lag again too
            for k in members:
                rows[k] = with_lag([rows[k]], lag.tau)[0]
        group_sheets = [
            sheets[k] if shed is None else sheets[k].replace(mass_loss=shed.loss) for k in members
        ]
        group = _calibrate_group(
            [rows[k] for k in members], group_sheets, keep, n_boot, seed, found=shed is not None
        )
        if group is None:
            notes.append(
                "the record pins none of the machine's parameters (its force does not "
                "follow its motions: no contact, or a force channel that is not the "
                "contact's); the scenario's machine is used"
            )
            continue
        series = series or group.series
        for k, sc, ph in zip(members, group.scenarios, group.phases, strict=True):
            used[k] = sc
            phases[k] = ph
        prefix = "" if len(groups) == 1 else f"records {', '.join(str(k + 1) for k in members)}: "
        if shed is not None:
            group.parameters["mass_loss"] = _found_row("mass_loss", shed.loss, shed.low, shed.high)
            group.notes.insert(0, _shedding_note(shed))
        if lag is not None:
            group.parameters["force_lag"] = _found_row("force_lag", lag.tau, lag.low, lag.high)
            group.notes.insert(0, _lag_note(lag))
        parameters.update({prefix + n: v for n, v in group.parameters.items()})
        residual = group.residual if len(groups) == 1 else {**residual, prefix: group.residual}
        notes += group.notes
    return Calibration(
        sheet=tuple(sheets),
        scenarios=tuple(used),
        parameters=parameters,
        phase=tuple(phases),
        residual=residual,
        calibrated=bool(parameters),
        notes=tuple(notes + _phase_notes(phases, sheets)),
        settings={
            "time_offset": offsets,
            "n_boot": n_boot,
            "seed": seed,
            "keep": list(keep),
            "loose": LOOSE,
        },
        seconds=time.perf_counter() - t_start,
        series=series,
    )


def _inputs(scenario, measurement, time_offset, keep):
    """The records, one sheet and one time offset for each, and the held parameters,
    checked: ``(measurements, sheets, offsets, keep)``."""
    meas = _listed(measurement)
    sheets = _listed(scenario)
    if len(sheets) == 1:
        sheets = sheets * len(meas)
    if len(sheets) != len(meas) or not meas:
        raise InputError(
            f"calibrate: {len(meas)} record(s) and {len(sheets)} scenario(s); give one "
            "scenario for all records or one per record"
        )
    offsets = _listed(time_offset)
    offsets = offsets * len(meas) if len(offsets) == 1 else offsets
    if len(offsets) != len(meas):
        raise InputError("calibrate: give one time_offset for all records or one per record")
    keep = tuple(keep)
    bad = [k for k in keep if k not in CALIBRATED]
    if bad:
        raise InputError(
            f"calibrate: keep names {bad[0]!r}; the parameters are {', '.join(CALIBRATED)}"
        )
    return meas, sheets, offsets, keep


def _sensor(members, rows, keep, sheet, boot):
    """The force sensor's lag the records ``members`` of one machine show
    (:mod:`.sensor`), or ``None``; when found, their rows are those of the force the sensor
    saw (``rows`` updated in place).  ``boot``: the bootstrap's ``(n_boot, seed)``."""
    group = [rows[k] for k in members]
    fixed = {n: getattr(sheet, n) for n in keep if n in ("m1", "c1", "k1", "k3", "m2")}
    lag = sensor_lag(group, fixed, cycle_draws(group, *boot), loose=LOOSE, material=MATERIAL)
    if not lag.found:
        return None
    for k, row in zip(members, with_lag(group, lag.tau), strict=True):
        rows[k] = row
    return lag


def _lag_note(lag):
    return (
        f"the force lags the motions: a sensor of time constant {_fmt(lag.tau)} "
        f"[{_fmt(lag.low)}, {_fmt(lag.high)}] s (seen in the machine's equations, "
        f"{lag.share:.1%} of the force's); the machine is read from the force it saw, "
        "vidi fit, verify, identify and landscape compare a law's force as this sensor "
        "sees it, and vidi explain starts from it (sensor_lag)"
    )


def _shedding(members, rows, meas, sheets, offsets):
    """The mass loss the records ``members`` of one machine show where their sheets have
    none (:mod:`.shedding`), or ``None``; when found, their rows are made again with it
    (``rows`` updated in place), so that ``m2`` is the mass at each record's start."""
    if any(sheets[k].mass_loss > 0 for k in members):
        return None
    found = shedding(
        [rows[k] for k in members], [meas[k] for k in members], [sheets[k] for k in members]
    )
    if found is None or not found.found:
        return None
    for k in members:
        rows[k] = machine_rows(meas[k], sheets[k].replace(mass_loss=found.loss), float(offsets[k]))
    return found


def _found_row(name, value, low, high):
    """The parameter table's row of an effect the record shows where the sheet has none (a
    mass loss, a force sensor's lag): its value, used."""
    return {
        "unit": UNITS[name],
        "sheet": 0.0,
        "record": value,
        "low": low,
        "high": high,
        "determined": True,
        "held": False,
        "used": value,
    }


def _shedding_note(shed):
    return (
        f"the moulding sheds mass: {_fmt(shed.loss)} [{_fmt(shed.low)}, {_fmt(shed.high)}] "
        f"of it at every contact (from its mass at each of {shed.contacts} contacts) where "
        "the sheet has none; m2 is its mass at the record's start, and the machine used "
        "sheds it"
    )


def _phase_notes(phases, sheets):
    """A note for each record whose drive phase at ``t = 0`` is clearly not 0."""
    notes = []
    for k, (p, lo, hi) in enumerate(phases):
        if math.isfinite(lo) and abs(p) > PHASE_NOTE and not lo <= 0.0 <= hi:
            notes.append(
                f"{'record ' + str(k + 1) + ': ' if len(phases) > 1 else ''}the drive's phase "
                f"at the record's t = 0 is {p:.1f} deg [{lo:.1f}, {hi:.1f}], not 0: is t on "
                f"the drive's clock? (a time offset of {-p / 360 * sheets[k].period:.4g} s "
                "would put it there)"
            )
    return notes


@dataclass(frozen=True)
class _Group:
    """The calibration of records of one machine: the parameter table, the machine of each
    record, the equations' residuals, notes, each record's drive phase and the figure's
    series (see :class:`~.result.Calibration`)."""

    parameters: dict
    scenarios: list
    residual: dict
    notes: list
    phases: list
    series: dict


def _uncalibrated_note(meas, sheet):
    src = f"{meas.source}: " if meas.source else ""
    return (
        f"{src}the record has no positions w1, w2 (or is too short for the equations' "
        f"windows): its machine is taken as the scenario gives it ({sheet.name})"
    )


def _calibrate_group(rows, sheets, keep, n_boot, seed, *, found=False):
    """Calibrate records of one machine: a :class:`_Group`, or ``None`` when the record
    pins none of its parameters (``found``: the sheets' mass loss is the records', noted by
    the caller)."""
    sheet = sheets[0]
    R = len(rows)
    draws = cycle_draws(rows, n_boot, seed)
    amps = parameter_names(R)[4:-1]  # each record's drive amplitude
    sheet_values = {
        "m1": sheet.m1,
        "c1": sheet.c1,
        "k1": sheet.k1,
        "k3": sheet.k3,
        "m2": sheet.m2,
        **{a: s.A for a, s in zip(amps, sheets, strict=True)},
    }
    held = {n: sheet_values[n] for n in keep if n != "A"}
    if "A" in keep:
        held.update({a: sheet_values[a] for a in amps})
    try:
        first, held = _first_estimate(rows, held, draws, sheet.k3 == 0 and "k3" not in held)
    except np.linalg.LinAlgError:
        return None
    if first is None:
        return None
    loose = {
        name: sheet_values[name]
        for k, name in enumerate(first.names)
        if not first.fixed[k] and not _determined(first, k)
    }
    if len(loose) == int((~first.fixed).sum()):
        return None  # the record pins nothing: its force does not follow its motions
    final = estimate(rows, {**held, **loose}, draws) if loose else first
    parameters, notes = _table(first, final, held, loose, sheet_values)
    if sheet.k3 == 0 and "k3" in parameters:
        k3 = parameters["k3"]
        notes.insert(
            0,
            f"the supports stiffen: k3 = {_fmt(k3['record'])} [{_fmt(k3['low'])}, "
            f"{_fmt(k3['high'])}] N/m^3 where the sheet's are linear (the support "
            "nonlinearity, seen in the frame's own equation; the machine used has it)",
        )
    if sheet.mass_loss > 0 and not found:  # a loss the record showed has its own note
        notes.append(
            f"the moulding sheds {sheet.mass_loss:.3g} of its mass at every contact: "
            "m2 is its mass at the record's start (each window's equations hold the mass "
            "left after the record's contacts before it)"
        )
    common = {n: final.get(n) for n in ("m1", "c1", "k1", "k3", "m2")}
    scenarios = [s.replace(**common, A=final.get(a)) for s, a in zip(sheets, amps, strict=True)]
    sheet_frame = [sheet.m1, sheet.c1, sheet.k1, sheet.k3, *[s.A for s in sheets]]
    residual = {
        "frame": {"sheet": frame_residual(rows, sheet_frame), "record": final.residual["frame"]},
        "moulding": {
            "sheet": moulding_residual(rows, sheet.m2),
            "record": final.residual["moulding"],
        },
    }
    theta = [final.get(n) for n in final.names]
    series = _series(rows[0], [*sheet_frame[:5], sheet.m2], [*theta[:5], theta[-1]])
    return _Group(parameters, scenarios, residual, notes, drive_phase(rows, draws), series)


def _determined(est, k):
    """Whether parameter ``k`` of ``est`` is pinned: positive, its 95 % interval above 0 and
    its half width at most :data:`LOOSE` of its value."""
    v, lo, hi = est.value[k], est.low[k], est.high[k]
    return bool(v > 0 and np.isfinite(lo) and lo > 0 and (hi - lo) / 2 <= LOOSE * v)


def stiffening_share(rows, k1, k3):
    """The stiffening's share of the supports' force as the records' equations hold it:
    ``k3 ||int phi w1^3|| / (k1 ||int phi w1||)`` over every window of ``rows``."""
    frame = np.concatenate([r.frame for r in rows])
    linear = abs(k1) * np.linalg.norm(frame[:, 2])
    return float(abs(k3) * np.linalg.norm(frame[:, 3]) / linear) if linear > 0 else math.inf


def supports_reading(scenarios, measurements):
    """The supports' cubic stiffness ``k3`` [N/m^3] the frame's own equation reads from
    records of one machine, the rest of it (``m1, c1, k1, m2`` and each record's ``A``)
    held as ``scenarios`` give it: a start for a refit that adds stiffening supports to a
    machine given without them (the force's regression cannot see the supports).  None
    where a record has no positions, the records are of different machines, or the reading
    is not a positive number that moves the supports' force by :data:`MATERIAL` (as the
    calibration keeps a stiffening: on records of linear supports the equations read a
    ``k3`` whose share is 1e-6 to 1e-4, on stiffening ones 0.03 to 1.3)."""
    if len({_machine_key(s) for s in scenarios}) != 1:
        return None
    rows = [machine_rows(m, s) for s, m in zip(scenarios, measurements, strict=True)]
    if any(r is None for r in rows):
        return None
    sheet = scenarios[0]
    held = {n: getattr(sheet, n) for n in ("m1", "c1", "k1", "m2")}
    amps = parameter_names(len(rows))[4:-1]  # each record's drive amplitude
    held.update({a: s.A for a, s in zip(amps, scenarios, strict=True)})
    k3 = estimate(rows, held, []).get("k3")
    if not (np.isfinite(k3) and k3 > 0 and stiffening_share(rows, sheet.k1, k3) >= MATERIAL):
        return None
    return k3


def _first_estimate(rows, held, draws, probe_k3):
    """The estimate with only ``held`` fixed, and the parameters it held: ``(Estimate or
    None, held)``.  With ``probe_k3`` (a sheet with linear supports) the supports are
    estimated linear, and with ``k3`` free too: the record's stiffening is kept where it
    pins ``k3`` (:func:`_determined`), else the supports stay linear, as the sheet has
    them, and every other parameter is judged as with them."""
    linear = {**held, "k3": 0.0} if probe_k3 else held
    first = estimate(rows, linear, draws)
    if not np.all(np.isfinite(first.value)):
        return None, linear
    if probe_k3:
        free = estimate(rows, held, draws)
        k = free.names.index("k3")
        v = free.value
        if (
            np.all(np.isfinite(v))
            and _determined(free, k)
            and stiffening_share(rows, v[free.names.index("k1")], v[k]) >= MATERIAL
        ):
            return free, held
    return first, linear


def _table(first, final, held, loose, sheet_values):
    """The parameter table of :class:`~.result.Calibration` and a note for each loose
    parameter: ``first`` the estimate with only the held parameters fixed, ``final`` with the
    loose ones kept at the sheet's values too."""
    parameters, notes = {}, []
    for k, name in enumerate(final.names):
        if name == "k3" and sheet_values["k3"] == 0 and (name in held or name in loose):
            continue  # linear supports, as the sheet has them
        src = first if name in loose else final
        rec = float(src.value[k])
        determined = not final.fixed[k]
        parameters[name] = {
            "unit": UNITS[name.split("[")[0]],
            "sheet": float(sheet_values[name]),
            "record": rec,
            "low": float(src.low[k]) if name not in held else None,
            "high": float(src.high[k]) if name not in held else None,
            "determined": bool(determined),
            "held": name in held,
            "used": float(final.value[k]),
        }
    for name in loose:
        p = parameters.get(name)
        if p is not None:
            notes.append(
                f"the record leaves {name} loose ({_fmt(p['record'])} "
                f"[{_fmt(p['low'])}, {_fmt(p['high'])}] {p['unit']}): the sheet's "
                f"{_fmt(p['sheet'])} is kept"
            )
    return parameters, notes


def _series(row, sheet, record):
    """The figure's series of one record: the force its motions imply over each window,
    with the ``sheet``'s and the ``record``'s parameters (each ``m1, c1, k1, k3, A, m2``)."""

    even = ~row.anchored  # the evenly spread windows, in time order
    fr, ones = row.frame[even], row.ones[even]
    mould = row.moulding[even] / ones

    def frame(p):
        return -(fr @ np.asarray(p[:5], dtype=float)) / ones

    return {
        "t": row.centre[even],
        "measured": row.force[even] / ones,  # the force the sensor saw, where it lags
        "lag_removed": bool(row.lagged),
        "frame": {"sheet": frame(sheet), "record": frame(record)},
        "moulding": {"sheet": mould * sheet[5], "record": mould * record[5]},
    }


def _fmt(x):
    return "--" if x is None else f"{x:.4g}"
