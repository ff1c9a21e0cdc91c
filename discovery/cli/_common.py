"""Shared pieces of the command modules: option types that check values at parse time
(before any work), and the record/output helpers every command calls (the options
several commands share are in :mod:`._options`).

For the command modules:

* ``add_record_options(parser)`` adds ``--columns t=NAME,F=NAME,...`` (the file's
  header names for our columns); ``read_record(args, scenario)`` then loads
  ``args.data`` with that mapping (:meth:`discovery.Measurement.from_csv`).
* ``check_out(args, kind="dir")`` refuses a bad ``--out`` before any work
  (:func:`discovery._files._io.check_output` with the command's input files);
  ``check_record_out(args)`` and ``write_record(...)`` do it for a command that writes a
  record (``D.csv`` and ``D.summary.json``).
* ``provenance_of(args)`` is the provenance of ``summary.json`` (the options and the
  input files of ``inputs_of(args)``).
* ``number(...)`` and ``integer(...)`` are argparse ``type=`` functions with ranges.
"""

import argparse
import math
import os

import numpy as np

from .._api._printing import interval_text
from .._files._io import check_output
from ..errors import InputError
from ..vibroimpact.model.scenario import builtin_scenarios

COLUMNS_HELP = (
    "the file's header names for our columns when they differ, e.g. "
    "t=time_s,F=force_N (names: t, F, w1, v1, w2, v2, a2; default: the headers are "
    "these names)"
)


def _fmt(x):
    return f"{x:g}" if isinstance(x, float) else str(x)


def number(lo=None, hi=None, *, lo_open=False, unit=""):
    """argparse ``type=``: a finite float in ``[lo, hi]`` (``(lo, hi]`` with ``lo_open``)."""
    lo_txt = "" if lo is None else (f"> {_fmt(lo)}" if lo_open else f">= {_fmt(lo)}")
    hi_txt = "" if hi is None else f"<= {_fmt(hi)}"
    rng = " and ".join(x for x in (lo_txt, hi_txt) if x)
    need = f"a finite number{' ' + rng if rng else ''}{' ' + unit if unit else ''}"

    def parse(text):
        try:
            if not text.isascii():  # float() would take full-width and other digits
                raise ValueError(text)
            v = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r} is not a number; give {need}") from None
        if (
            not math.isfinite(v)
            or (lo is not None and (v <= lo if lo_open else v < lo))
            or (hi is not None and v > hi)
        ):
            raise argparse.ArgumentTypeError(f"{text!r} is out of range; give {need}")
        return v

    parse.__name__ = "number"
    return parse


def integer(lo=None, hi=None):
    """argparse ``type=``: an integer in ``[lo, hi]``."""
    rng = " and ".join(
        x
        for x in ((f">= {lo}" if lo is not None else ""), (f"<= {hi}" if hi is not None else ""))
        if x
    )
    need = f"an integer{' ' + rng if rng else ''}"

    def parse(text):
        try:
            if not text.isascii():
                raise ValueError(text)
            v = int(text, 10)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r} is not an integer; give {need}") from None
        if (lo is not None and v < lo) or (hi is not None and v > hi):
            raise argparse.ArgumentTypeError(f"{text!r} is out of range; give {need}")
        return v

    parse.__name__ = "integer"
    return parse


def interval_count(text):
    """0 or an integer >= 5: bootstrap replicates of coefficient intervals (argparse type)."""
    n = integer(0, 10_000)(text)
    if 0 < n < 5:
        raise argparse.ArgumentTypeError(
            f"{n} replicates cannot give an interval; give 0 "
            "(none) or at least 5, e.g. --intervals 30"
        )
    return n


def law_or_default(text, scenario, what="--law"):
    """The law given as text, or the scenario's law when the option was left out; an
    empty text is an error (not silently the scenario's law)."""
    if text is not None:
        if not text.strip():
            raise InputError(
                f"{what} is empty; give a law such as '2.06e8*z + 1.28e7*zd' or "
                "leave the option out to use the scenario's law"
            )
        from ..vibroimpact.model.contact_models import parse_law

        law = parse_law(text)  # law text, or a named contact model's ("flores: k=..., ...")
        law.check_physical(scenario, what)
        return law
    if scenario.law is None:
        raise InputError(f"scenario {scenario.name!r} has no reference law; pass {what}")
    scenario.law.check_physical(scenario, f"the scenario's law ({scenario.name})")
    return scenario.law


def parse_range(text, default, name):
    if text is None:
        return default
    try:
        lo, hi = (float(v) for v in text.split(":"))
    except ValueError:
        raise InputError(f"{name} {text!r} must look like LOW:HIGH, e.g. 1.03e8:3.09e8") from None
    bad = [v for v in (lo, hi) if not np.isfinite(v)]
    if bad:
        raise InputError(f"{name} {text!r}: {bad[0]!r} is not a finite number; e.g. 1.03e8:3.09e8")
    if not lo < hi:
        raise InputError(f"{name} needs LOW < HIGH, got {text!r}")
    return lo, hi


# ------------------------------------------------------------------ records and outputs
def parse_columns(text, option="--columns"):
    """``"t=time_s,F=force_N"`` -> ``{"t": "time_s", "F": "force_N"}`` (None for None)."""
    from ..vibroimpact.data.measurement import COLUMNS

    if text is None:
        return None
    mapping = {}
    for part in text.split(","):
        key, sep, col = part.partition("=")
        key, col = key.strip(), col.strip()
        if not sep or not key or not col:
            raise InputError(
                f"{option} {text!r}: write OURS=THEIRS pairs separated by commas, "
                "e.g. t=time_s,F=force_N"
            )
        if key not in COLUMNS:
            raise InputError(
                f"{option}: unknown name {key!r}; map the names "
                f"{', '.join(COLUMNS)} to the file's headers, e.g. t=time_s"
            )
        if key in mapping:
            raise InputError(f"{option}: {key} is mapped twice; map each name once")
        mapping[key] = col
    return mapping


def reporter(args):
    """The progress reporter of a long command (``--quiet`` silences it; ``--progress``, where
    a command has it, draws the bar even when stderr is not a terminal)."""
    from .._api._progress import Reporter

    return Reporter(
        quiet=getattr(args, "quiet", False), bar=True if getattr(args, "progress", False) else None
    )


def executor_of(args):
    """The executor of ``--scheduler`` (a context manager that closes it), or a null
    context giving ``None`` (the API's default: ``--workers`` local processes)."""
    import contextlib

    if not getattr(args, "scheduler", None):
        return contextlib.nullcontext(None)
    from ..parallel import make_executor

    return make_executor(getattr(args, "workers", None), args.scheduler)


MACHINE_HELP = (
    "the machine the record is judged with: 'record' calibrates the scenario's masses, "
    "supports and drive from the record's own motions and force (vidi calibrate; a record "
    "without positions keeps the scenario), 'sheet' takes the scenario as given "
    "(default: %(default)s)"
)


def add_record_options(parser):
    """Add the options of reading a record (``--columns``, ``--machine``); returns the
    ``--columns`` action."""
    columns = parser.add_argument("--columns", metavar="MAP", help=COLUMNS_HELP)
    parser.add_argument(
        "--machine", choices=("record", "sheet"), default="record", help=MACHINE_HELP
    )
    return columns


def machine_scale(machine):
    """The machine scale's uncertainty ``(low, high)`` of a :func:`machine_for` summary
    when the run uses the calibrated machine, else ``None``."""
    if machine and machine.get("used") == "record" and machine.get("scale_range"):
        return tuple(machine["scale_range"])
    return None


def machine_known(machine):
    """The effects a :func:`machine_for` summary found beyond the machine when the run
    uses the calibrated machine (a force sensor's lag): ``{effect id: value}`` for
    :func:`~discovery.explain`'s ``known``, else ``None``."""
    from ..vibroimpact.calibration.result import found_lag

    if not (machine and machine.get("used") == "record"):
        return None
    value = found_lag(machine.get("parameters") or {})
    return {"sensor_lag": value} if value else None


def sensor_lag_of(args, machine):
    """``--sensor-lag`` (:func:`._options.add_sensor_lag_option`), else the force sensor's
    lag the calibration found (0 without)."""
    if getattr(args, "sensor_lag", None) is not None:
        return args.sensor_lag
    return (machine_known(machine) or {}).get("sensor_lag", 0.0)


def machine_for(args, scenarios, measurements, time_offset=0.0):
    """The machine each record is judged with (``--machine``): the scenarios calibrated
    from the records (``record``, the default) or as given (``sheet``).  The records' units
    and signs are checked either way; one line is printed for the machine used and one for
    each sheet value the records contradict.  Returns ``(scenarios, summary entry)``."""
    from ..vibroimpact.calibration import calibrate

    scs = list(scenarios)
    cal = calibrate(
        scs, list(measurements), time_offset=time_offset, seed=getattr(args, "seed", 0) or 0
    )
    use = getattr(args, "machine", "record")
    for note in cal.notes:
        print(f"note: {note}")
    if use == "record" and cal.calibrated:
        used = list(cal.scenarios)
        print(
            f"machine: calibrated from the record ({cal.summary_line()}); "
            "--machine sheet keeps the scenario's"
        )
        for line in cal.disagreements():
            print(f"machine: {line}")
    else:
        used = scs
        if cal.calibrated:
            print("machine: the scenario as given (--machine sheet)")
            for line in cal.disagreements():
                print(f"machine: {line} (not used: --machine sheet)")
    return used, {"used": use if cal.calibrated else "sheet", **cal.as_dict()}


def read_record(args, scenario, path=None):
    """The record ``path`` (default ``args.data``) read with ``args.columns``."""
    from ..vibroimpact.data.measurement import Measurement

    columns = parse_columns(getattr(args, "columns", None))
    return Measurement.from_csv(
        args.data if path is None else path, scenario=scenario, columns=columns
    )


def scenario_file(text):
    """The scenario option as a file path when it names an existing file, else None (a
    built-in name)."""
    if text and text not in builtin_scenarios() and os.path.isfile(text):
        return text
    return None


def _listed(value):
    if value is None:
        return []
    return list(value) if isinstance(value, list | tuple) else [value]


def inputs_of(args):
    """``{"data": ..., "scenario": ...}`` of a command's arguments, for provenance (a
    repeated option gives ``data``, ``data_2``, ...)."""
    out = {}
    for key in ("data", "scenario"):
        for k, v in enumerate(_listed(getattr(args, key, None))):
            if v:
                out[key if k == 0 else f"{key}_{k + 1}"] = v
    return out


def check_out_inputs(args):
    """The input files an output may not replace: the records and scenario files."""
    inputs = [p for p in _listed(getattr(args, "data", None)) if p]
    return inputs + [p for p in map(scenario_file, _listed(getattr(args, "scenario", None))) if p]


def check_out(args, kind="dir", option="--out"):
    """Refuse a bad ``--out`` before any work (see :func:`discovery._files._io.check_output`)."""
    return check_output(
        getattr(args, "out", None), check_out_inputs(args), kind=kind, option=option
    )


def provenance_of(args, counted=True):
    """The ``summary.json`` provenance of a command: its options, its input files
    (:func:`inputs_of`) and, with ``counted``, the work it counted so far
    (:mod:`discovery.numerics.counts`: the vibro-impact system's units; not for the Ueda
    commands, whose work they do not count)."""
    from .._files._io import provenance
    from ..numerics import counts

    prov = provenance(vars(args), inputs=inputs_of(args))
    return {**prov, "counts": counts.snapshot()} if counted else prov


def data_entry(data):
    """The ``data`` entry of a summary: the one ``--data`` record, or the list of them."""
    return [str(p) for p in data] if len(data) > 1 else str(data[0])


def check_record_out(args):
    """``--out`` of a command that writes a record: a new ``.csv`` file and the
    ``.summary.json`` beside it, refused before any work; returns ``(csv, summary)``."""
    out = check_out(args, kind="file")
    if out.suffix.lower() != ".csv":
        raise InputError(f"--out {args.out!r} must name a .csv file, e.g. D.csv")
    summary = out.with_suffix(".summary.json")
    check_output(summary, check_out_inputs(args), kind="file", option="--out's summary")
    return out, summary


def write_record(paths, csv_text, summary):
    """The record ``csv_text`` and its ``summary`` result, each written atomically to the
    ``(csv, summary)`` paths of :func:`check_record_out` (the summary holds the CSV's
    sha256, so a pair from two runs is detectable)."""
    import json

    from .._files._io import atomic_write_text

    out, summary_path = paths
    text = json.dumps(summary.to_dict(), indent=2) + "\n"
    atomic_write_text(out, csv_text)
    atomic_write_text(summary_path, text)


def outputs_line(args, files):
    """``outputs in OUT/: a, b, ...``: the last line of a command's printout."""
    return f"outputs in {args.out}/: {', '.join(files)}"


def read_records(args, machine=True):
    """Every ``--data`` record with its scenario (``--scenario`` once per ``--data`` in the
    same order, or once for all), and the machine each is judged with (:func:`machine_for`):
    ``(scenarios, measurements, machine summary)``; notes are printed.  With ``machine``
    false the scenarios are returned as given and the summary is ``None``."""
    from ..vibroimpact.model.scenario import load_scenario

    data = _listed(args.data)
    names = _listed(args.scenario) or ["paper"]
    if len(names) not in (1, len(data)):
        raise InputError(
            f"{len(data)} --data record(s) but {len(names)} --scenario: give one "
            "--scenario per --data, in the same order, or one for all"
        )
    scs = [load_scenario(n) for n in names] * (len(data) if len(names) == 1 else 1)
    meas = []
    for path, sc in zip(data, scs, strict=True):
        m = read_record(args, sc, path)
        for note in m.notes:
            print(f"note: {path}: {note}" if len(data) > 1 else f"note: {note}")
        meas.append(m)
    if not machine:
        return scs, meas, None
    scs, summary = machine_for(args, scs, meas)
    return scs, meas, summary


def criteria_line(criteria, floor):
    """``  criteria (noise floor): I0 x (f), ...`` for the command's printout."""
    return "  criteria (noise floor): " + ", ".join(
        f"{k} {v:.3g} ({floor.get(k, float('nan')):.2g})" for k, v in criteria.items()
    )


def _error_text(error):
    """A standard error as the printout shows it ("--" where the fit gave none)."""
    return f"{error:.2g}" if error is not None and np.isfinite(error) else "--"


def coefficients_line(coefficients, errors, intervals=None):
    """``  coefficients (standard error): z c (se), ...`` for the command's printout, and
    with ``intervals`` (:class:`discovery.vibroimpact.fit.intervals.Intervals`) a second line with
    them and what the standard errors do not cover."""
    line = "  coefficients (standard error): " + ", ".join(
        f"{t} {c:.4g} ({_error_text(errors.get(t))})" for t, c in coefficients.items()
    )
    if intervals is None:
        if errors:
            line += (
                "\n  (Jacobian standard errors: they assume white residuals and miss the "
                "noise of the estimated machine states)"
            )
        return line
    b = intervals.bounds
    return line + (
        f"\n  {intervals.level:.0%} intervals ({intervals.method}, "
        f"{intervals.n_boot} replicates): "
        + ", ".join(f"{t} {interval_text(*b[t])}" for t in coefficients if t in b)
    )
