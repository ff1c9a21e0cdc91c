"""A study's configuration: factors, their product (or explicit rows), and one run per cell
and seed, each named by a hash of its full configuration and the code version.

The file (TOML)::

    name = "paper-terms"
    seeds = 2                          # or a list: [0, 1, 7]

    [factors]                          # each a list; the study is their product
    law = ["2.06e8*z + 1.28e7*zd"]     # any law the grammar takes (unloading branch, set)
    scenario = ["paper"]               # a name or file, a table {base = "paper", A = 3.5e5},
                                       # or a list of them: several records in one fit
    force_noise = [0.005, 0.01, 0.02, 0.05]   # of the force's peak
    motion_noise = [0.001]             # of each position's / velocity's range
    periods = [4, 12, 40]              # recorded drive periods (after the transient)
    fs = [10000.0]                     # sample rate [Hz]
    library = ["z, zd, z^2, z*zd, zd^2, z^1.5"]
    selection = ["best-subset", "l1-path", "stlsq", "sr3", "constrained-sr3"]
    refine = [true]

    [fit]                              # fixed options of every fit (discovery.discover)
    max_terms = 4

    [record]                           # fixed options of every record
    transient = "auto"                 # periods from rest, or "auto" (decay to 1e-4)
    velocities = true

Instead of the product, ``[[rows]]`` tables list the cells one by one (a factor a row leaves
out takes its default).  Defaults: the scenario's own law, ``paper``, 1 % force and 0.1 %
motion noise, 12 periods at 10 kHz, ``poly:2``, ``best-subset``, refinement on.

Scenarios and laws are resolved here, in the driver, so that a run is a self-contained
description (machine parameters, law text, every setting): workers on another machine need
no files, and the run's key changes when anything that could change its result does.
"""

from __future__ import annotations

import hashlib
import itertools
import json
import math
import os
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

from ..._api._validate import Text, params
from ..._files._io import short
from ...errors import InputError, VidiError
from ..data.measurement import MAX_SAMPLES
from ..fit.certified_fit import SELECTIONS
from ..model.contact_models import is_model_text, parse_law
from ..model.library import Library
from ..model.scenario import load_scenario

__all__ = ["StudyConfig", "load_study", "FACTORS"]

FACTORS = {
    "law": None,  # None: the (first) scenario's own law
    "scenario": "paper",
    "force_noise": 0.01,
    "motion_noise": 0.001,
    "periods": 12,
    "fs": 10000.0,
    "library": "poly:2",
    "selection": "best-subset",
    "refine": True,
    "sheet_error": 0.0,
    "machine": "sheet",
}
"""Every factor a study may vary, with its default.  ``sheet_error`` makes the fit's
machine a designer's sheet off the one that made the records: each of ``m1, m2, k1, A``
off by a uniform draw within +- that share and ``c1`` within +- three times it (seeded by
the run).  ``machine`` is what the fit takes: ``"sheet"`` (the scenario, or the sheet) or
``"record"`` (calibrated from the records, :func:`~discovery.calibrate`)."""

_FIT_KEYS = (
    "max_terms",
    "criterion",
    "shortlist",
    "stepwise",
    "n_boot",
    "n_boot_intervals",
    "max_simulations",
    "scoring",
    "require",
    "physics",
)
_RECORD_KEYS = ("transient", "velocities")

# bounds on a study's size, checked before any work (each message gives the number)
MAX_CELLS = 10_000
MAX_RUNS = 100_000
MAX_FILE_BYTES = 1 << 20  # a study file larger than this is not read
_FIT_BOUNDS = {
    "shortlist": 200,
    "max_simulations": 100_000,
    "n_boot": 10_000,
    "n_boot_intervals": 10_000,
    "stepwise": 64,
}
_TOP = ("name", "seeds", "factors", "rows", "fit", "record")


@dataclass(frozen=True)
class StudyConfig:
    """A parsed study: ``cells`` (one dict of factor values each), ``seeds``, the fixed
    ``fit`` and ``record`` options, and ``varied`` (the factors with several values)."""

    name: str
    cells: tuple
    seeds: tuple
    fit: dict = field(default_factory=dict)
    record: dict = field(default_factory=dict)
    varied: tuple = ()
    source: str = ""

    @property
    def n_runs(self):
        return len(self.cells) * len(self.seeds)

    def runs(self, code_version=""):
        """Every run: a JSON-ready description with its ``key`` (hash of the description
        and ``code_version``), in a fixed order (cells, then seeds)."""
        out, cache = [], {}
        for ci, cell in enumerate(self.cells):
            base = _resolve(cell, self.fit, self.record, 0, cache)  # runs differ by seed
            for seed in self.seeds:
                spec = {**base, "seed": int(seed)}
                spec["cell"] = ci
                spec["key"] = run_key(spec, code_version)
                out.append(spec)
        return out


def run_key(spec, code_version=""):
    """Hash (24 hex digits) of a run's description (without ``key``/``cell``) and the code
    version: the name of its result file."""
    body = {k: v for k, v in spec.items() if k not in ("key", "cell")}
    text = json.dumps({"run": body, "code": code_version}, sort_keys=True, allow_nan=True)
    return hashlib.sha256(text.encode()).hexdigest()[:24]


def _fail(source, what):
    raise InputError(f"study {short(source)!r}: {what}")


def _scenario_value(value, source):
    """A scenario factor value -> a list of Scenario (several records in one fit)."""
    items = value if isinstance(value, list) else [value]
    if not items:
        _fail(source, "a scenario value is an empty list; give a name, a file or a table")
    out = []
    for it in items:
        if isinstance(it, str):
            out.append(load_scenario(it))
        elif isinstance(it, dict):
            base = it.get("base", "paper")
            if not isinstance(base, str):
                _fail(source, 'a scenario table needs base = "paper" (a name or file)')
            sc = load_scenario(base)
            changes = {k: v for k, v in it.items() if k != "base"}
            bad = sorted(
                set(changes) - {"m1", "m2", "k1", "c1", "A", "frequency", "g", "k3", "name"}
            )
            if bad:
                _fail(
                    source,
                    f"unknown scenario key(s) {', '.join(bad)} in a scenario "
                    "table; valid: base, m1, m2, k1, c1, A, frequency, g, k3, name",
                )
            odd = sorted(
                k
                for k, v in changes.items()
                if k != "name" and not (isinstance(v, int | float) and not isinstance(v, bool))
            )
            if odd or not isinstance(changes.get("name", ""), str):
                what = ", ".join(f"{k} = {changes[k]!r}" for k in odd) or "name"
                _fail(
                    source,
                    f"scenario table {short(it, 80)}: {what} is not a number (name is text); "
                    "give e.g. A = 3.5e5",
                )
            if "name" not in changes:
                changes["name"] = (
                    sc.name + "-" + "-".join(f"{k}{v:g}" for k, v in sorted(changes.items()))
                )
            try:
                out.append(sc.replace(**changes))
            except (TypeError, ValueError) as exc:
                _fail(source, f"scenario table {short(it, 80)}: {exc}")
        else:
            _fail(source, f"a scenario is a name, a file or a table; got {it!r}")
    return out


def _number(v):
    return isinstance(v, int | float) and not isinstance(v, bool)


def _check_noise(name, value, source):
    if not (_number(value) and 0 <= value < 1):
        _fail(source, f"{name} values are fractions in [0, 1); got {value!r}")


def _check_periods(name, value, source):
    if not (isinstance(value, int) and not isinstance(value, bool) and 1 <= value <= 10000):
        _fail(source, f"periods values are whole numbers of drive periods; got {value!r}")


def _check_fs(name, value, source):
    if not (_number(value) and 0 < value <= 1e7 and math.isfinite(value)):
        _fail(source, f"fs values are sample rates in Hz; got {value!r}")


def _check_library(name, value, source):
    if not isinstance(value, str):
        _fail(source, f'library values are texts such as "poly:2"; got {value!r}')
    if value != "contact-models":  # the named contact models (fit.contact_fit)
        Library.parse(value)


def _check_selection(name, value, source):
    if value not in SELECTIONS:
        _fail(source, f"selection {value!r} is unknown; choose from {', '.join(SELECTIONS)}")


def _check_refine(name, value, source):
    if not isinstance(value, bool):
        _fail(source, f"refine values are true or false; got {value!r}")


def _check_law(name, value, source):
    if not isinstance(value, str):
        _fail(source, f'law values are texts such as "2e8*z + 1e7*zd"; got {value!r}')
    parse_law(value)


def _check_machine(name, value, source):
    if value not in ("record", "sheet"):
        _fail(source, f'machine values are "record" or "sheet"; got {value!r}')


_FACTOR_CHECKS = {
    "sheet_error": _check_noise,
    "machine": _check_machine,
    "force_noise": _check_noise,
    "motion_noise": _check_noise,
    "periods": _check_periods,
    "fs": _check_fs,
    "library": _check_library,
    "selection": _check_selection,
    "refine": _check_refine,
    "law": _check_law,
    "scenario": lambda name, value, source: _scenario_value(value, source),
}


def _check_factor(name, value, source):
    """One factor value, checked (the scenario and law are resolved later)."""
    _FACTOR_CHECKS[name](name, value, source)
    return value


def _resolve(cell, fit, record, seed, cache=None):
    """The self-contained description of one run (``cache``: the scenarios and laws already
    resolved, by their text)."""
    cache = {} if cache is None else cache
    sk = ("scenario", json.dumps(cell["scenario"], sort_keys=True, default=str))
    if sk not in cache:
        scenarios = _scenario_value(cell["scenario"], "")
        cache[sk] = (
            scenarios[0].law,
            [
                {k: v for k, v in sc.as_dict().items() if k not in ("law", "source")}
                for sc in scenarios
            ],
            scenarios[0].name,
        )
    own_law, scenario_dicts, first = cache[sk]
    law = cell["law"]
    if law is None:
        if own_law is None:
            raise InputError(f"scenario {first!r} has no law; give [factors] law")
        law = own_law.to_text()
    else:
        lk = ("law", law)
        if lk not in cache:
            # a named model keeps its name (the truth a contact-models fit is scored by)
            cache[lk] = parse_law(law).to_text() if not is_model_text(law) else law
        law = cache[lk]
    # the machine's factors are in a run's description only when set: the runs of a study
    # that does not vary them keep their keys
    machine = {
        k: cell[k] for k in ("sheet_error", "machine") if cell.get(k, FACTORS[k]) != FACTORS[k]
    }
    return {
        **machine,
        "law": law,
        "scenarios": [dict(d) for d in scenario_dicts],
        "force_noise": float(cell["force_noise"]),
        "motion_noise": float(cell["motion_noise"]),
        "periods": int(cell["periods"]),
        "fs": float(cell["fs"]),
        "library": str(cell["library"]),
        "selection": cell["selection"],
        "refine": bool(cell["refine"]),
        "fit": dict(sorted(fit.items())),
        "record": dict(sorted(record.items())),
        "seed": int(seed),
    }


def _as_list(name, value, source):
    if not isinstance(value, list) or not value:
        _fail(
            source,
            f"[factors] {name} must be a non-empty list, e.g. {name} = "
            f"[{json.dumps(FACTORS[name] if FACTORS[name] is not None else '2e8*z')}]",
        )
    return value


def _seeds(data, source):
    """The study's seeds: a count or a list of distinct whole numbers."""
    seeds = data.get("seeds", 1)
    if isinstance(seeds, int) and not isinstance(seeds, bool):
        if not 1 <= seeds <= 100000:
            _fail(source, f"seeds = {seeds}: give a count of at least 1 or a list of seeds")
        seeds = list(range(seeds))
    if not (
        isinstance(seeds, list)
        and seeds
        and all(isinstance(s, int) and not isinstance(s, bool) and s >= 0 for s in seeds)
    ):
        _fail(source, "seeds is a count (seeds = 3) or a list of whole numbers >= 0")
    if len(set(seeds)) != len(seeds):
        _fail(source, "seeds repeats a seed; each seed is one run per cell")
    return seeds


def _settings(data, source):
    """The ``[fit]`` and ``[record]`` tables, checked, and the record's transient."""
    fit = data.get("fit", {})
    record = data.get("record", {})
    for tname, table, keys in (("fit", fit, _FIT_KEYS), ("record", record, _RECORD_KEYS)):
        if not isinstance(table, dict):
            _fail(source, f"[{tname}] must be a table")
        extra = sorted(set(table) - set(keys))
        if extra:
            _fail(source, f"unknown [{tname}] key(s) {', '.join(extra)}; valid: {', '.join(keys)}")
    tr = record.get("transient", "auto")
    if not (tr == "auto" or (isinstance(tr, int) and not isinstance(tr, bool) and 0 <= tr <= 5000)):
        _fail(source, f'[record] transient is "auto" or a number of periods; got {tr!r}')
    vel = record.get("velocities", True)
    if not isinstance(vel, bool):
        _fail(source, f"[record] velocities is true or false; got {vel!r}")
    _check_fit(fit, source)
    return fit, record, tr


def _check_fit(fit, source):
    """Every ``[fit]`` option by the checks :func:`~discovery.vibroimpact.fit.discovery.discover`
    makes of its arguments (their types, ranges and names), so that a bad option stops the
    study up front instead of failing every run."""
    from ..fit.certified_fit import SCORES
    from ..fit.discovery import DiscoverSettings
    from ..verify.criteria import criterion as _criterion

    def bad(exc):
        text = str(exc).removeprefix("discover: ")
        _fail(source, f"[fit] {text}")

    try:
        known = {k: v for k, v in fit.items() if k in DiscoverSettings.names()}
        DiscoverSettings.of("discover", None, known)
        if "criterion" in fit:
            _criterion(fit["criterion"])
        if "scoring" in fit and fit["scoring"] not in SCORES:
            raise InputError(f"scoring must be one of {', '.join(SCORES)}; got {fit['scoring']!r}")
        req = fit.get("require", [])
        if not (isinstance(req, list) and all(isinstance(r, str) and r for r in req)):
            raise InputError(f'require must be a list of term names such as ["z"]; got {req!r}')
        for k, hi in _FIT_BOUNDS.items():  # the command line's bounds (`vidi fit`)
            if k in fit and fit[k] > hi:
                raise InputError(f"{k} must be at most {hi}; got {fit[k]}")
    except VidiError as exc:
        bad(exc)


def _cells(data, factors, levels, source):
    """The study's cells (explicit ``[[rows]]`` or the product of the factors' levels) and
    the factors that vary between them."""
    if "rows" in data:
        rows = data["rows"]
        if factors:
            _fail(source, "give either [factors] (their product) or [[rows]], not both")
        if not (isinstance(rows, list) and rows and all(isinstance(r, dict) for r in rows)):
            _fail(source, "[[rows]] are tables of factor values, one per cell")
        if len(rows) > MAX_CELLS:
            _fail(source, f"{len(rows)} [[rows]]; the limit is {MAX_CELLS} cells")
        cells = []
        for r in rows:
            extra = sorted(set(r) - set(FACTORS))
            if extra:
                _fail(
                    source,
                    f"unknown factor(s) {', '.join(extra)} in a row; valid: {', '.join(FACTORS)}",
                )
            cells.append(
                {k: _check_factor(k, r[k], source) if k in r else FACTORS[k] for k in FACTORS}
            )
        varied = tuple(k for k in FACTORS if len({json.dumps(c[k]) for c in cells}) > 1)
    else:
        n = math.prod(len(v) for v in levels.values())
        if n > MAX_CELLS:
            _fail(
                source,
                f"the factors' levels make {n} cells (the product of "
                f"{' x '.join(str(len(v)) for v in levels.values() if len(v) > 1)}); the "
                f"limit is {MAX_CELLS}: vary fewer factors or give fewer levels",
            )
        cells = [
            dict(zip(FACTORS, combo, strict=True)) for combo in itertools.product(*levels.values())
        ]
        varied = tuple(k for k in FACTORS if len(levels[k]) > 1)
    return cells, varied


def _check_cells(cells, source):
    """What only a cell shows: each record's size (periods at the sample rate, at the
    scenario's drive frequency) within :data:`MAX_SAMPLES`, and each true law one a machine
    could have (:meth:`ForceLaw.check_physical` on its scenario)."""
    seen, loaded = set(), {}
    for cell in cells:
        sk = json.dumps(cell["scenario"], sort_keys=True, default=str)
        if sk not in loaded:
            loaded[sk] = _scenario_value(cell["scenario"], source)
        scenarios = loaded[sk]
        for sc in scenarios:
            n = cell["periods"] * cell["fs"] / sc.frequency
            if not n <= MAX_SAMPLES:
                _fail(
                    source,
                    f"periods = {cell['periods']} at fs = {cell['fs']:g} Hz is {n:.3g} samples "
                    f"a record (scenario {sc.name!r} at {sc.frequency:g} Hz); the limit is "
                    f"{MAX_SAMPLES:.0e}: lower fs or periods",
                )
        law = cell["law"]
        key = (law, sk)
        if key in seen:
            continue
        seen.add(key)
        if law is None:
            if scenarios[0].law is None:
                _fail(source, f"scenario {scenarios[0].name!r} has no law; give [factors] law")
            truth, what = scenarios[0].law, f"the scenario's law ({scenarios[0].name})"
        else:
            truth, what = parse_law(law), "[factors] law"
        for sc in scenarios:
            try:
                truth.check_physical(sc, what)
            except InputError as exc:
                _fail(source, str(exc))


def study_from_mapping(data, source="<dict>"):
    """Validate a parsed study file (see the module docstring)."""
    if not isinstance(data, dict):
        _fail(source, "must be a table of settings")
    bad = sorted(set(data) - set(_TOP))
    if bad:
        _fail(source, f"unknown key(s) or table(s) {', '.join(bad)}; valid: {', '.join(_TOP)}")
    name = data.get("name", Path(source).stem if source else "study")
    if not isinstance(name, str) or not name.strip():
        _fail(source, "name must be non-empty text")
    seeds = _seeds(data, source)
    fit, record, tr = _settings(data, source)
    factors = data.get("factors", {})
    if not isinstance(factors, dict):
        _fail(source, "[factors] must be a table")
    extra = sorted(set(factors) - set(FACTORS))
    if extra:
        _fail(source, f"unknown factor(s) {', '.join(extra)}; valid: {', '.join(FACTORS)}")
    levels = {
        k: [_check_factor(k, v, source) for v in _as_list(k, factors[k], source)]
        if k in factors
        else [FACTORS[k]]
        for k in FACTORS
    }
    cells, varied = _cells(data, factors, levels, source)
    if len(cells) * len(seeds) > MAX_RUNS:
        _fail(
            source,
            f"{len(cells)} cells x {len(seeds)} seeds = {len(cells) * len(seeds)} runs; the "
            f"limit is {MAX_RUNS}: give fewer seeds or cells",
        )
    _check_cells(cells, source)
    return StudyConfig(
        name=name,
        cells=tuple(cells),
        seeds=tuple(seeds),
        fit=dict(fit),
        record={"transient": tr, "velocities": record.get("velocities", True)},
        varied=varied,
        source=source,
    )


@params(path_or_mapping=(Text(), os.PathLike, dict, StudyConfig))
def load_study(path_or_mapping):
    """A :class:`StudyConfig` from a TOML file (or an already parsed mapping)."""
    if isinstance(path_or_mapping, StudyConfig):
        return path_or_mapping
    if isinstance(path_or_mapping, dict):
        return study_from_mapping(path_or_mapping)
    path = Path(path_or_mapping)
    try:
        with open(path, "rb") as fh:
            raw = fh.read(MAX_FILE_BYTES + 1)
        if len(raw) > MAX_FILE_BYTES:
            raise InputError(
                f"study file {short(path)!r} is larger than {MAX_FILE_BYTES} bytes (or not "
                "a file); give a TOML study file"
            )
        text = raw.decode("utf-8-sig")
    except FileNotFoundError:
        raise InputError(
            f"study file {short(path)!r} does not exist; give a TOML file such as {_example()}"
        ) from None
    except IsADirectoryError:
        raise InputError(f"study file {short(path)!r} is a directory; give a TOML file") from None
    except UnicodeDecodeError:
        raise InputError(f"study file {short(path)!r} is not UTF-8 text; re-save it") from None
    except OSError as exc:
        raise InputError(
            f"cannot read study file {short(path)!r} ({exc.strerror or exc})"
        ) from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"study file {short(path)!r} is not valid TOML: {exc}") from None
    return study_from_mapping(data, str(path))


def _example():
    """Where the shipped example study is: the source tree's ``examples/study_paper.toml``
    by its full path when the package runs from one (a run from another folder finds it
    there), else its path in the repository."""
    example = Path(__file__).resolve().parents[3] / "examples" / "study_paper.toml"
    return str(example) if example.is_file() else "examples/study_paper.toml (in the repository)"
