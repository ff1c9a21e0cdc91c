"""Results as a data model: a versioned JSON document per result, and one loader.

Every result the API returns (:class:`~discovery.VerifyResult`, :class:`~discovery.Landscape`,
:class:`~discovery.DiscoveryResult`, ...) derives from :class:`Result`:

* ``r.to_dict()`` is a JSON-safe ``dict`` (``json.dumps(r.to_dict())`` works): its
  ``schema_version`` (:data:`SCHEMA_VERSION`), its kind (``"result"``: ``"verify"``,
  ``"fit"``, ...), then the result's own keys (the keys ``summary.json`` has always had).
  Conventions: arrays and tuples are lists, dictionary keys are text, and a number that is
  not finite (NaN, +-inf) is ``null``.
* ``type(r).from_dict(d)`` rebuilds the result: every field the document holds comes back
  typed (a law as a :class:`~discovery.ForceLaw`, iterations as their class, arrays as
  arrays); what the document does not hold (the simulated force histories, the contact
  samples, a fitted estimator, the record itself) is ``None`` on a loaded result.  A loaded
  result keeps its document, so ``to_dict()`` gives it back unchanged.
* Two results are equal when their documents are: ``from_dict(r.to_dict()) == r``.
* ``r.save(dir)`` writes ``dir/summary.json`` through :class:`~discovery._files._io.OutputDir`
  (staged, put in place whole or not at all); :func:`load` reads any saved result back as
  its own type.

A command line run records its provenance (versions, settings, input checksums) on the
result before saving (:meth:`Result.record_run`): a command's ``summary.json`` is its
result's ``to_dict()``.
"""

import copy
import dataclasses
import json
from importlib import import_module
from pathlib import Path

from .._files._io import OutputDir, short, to_jsonable
from .._files._jsonable import load_json
from ..errors import InputError

__all__ = ["SCHEMA_VERSION", "Result", "load", "load_summary", "part", "KINDS"]

SCHEMA_VERSION = 1
"""The version of every result document; a document of another version is refused."""

#: kind -> "module:Class" of every result type (the loader imports the class on use)
KINDS = {
    "evaluation": "discovery.vibroimpact.verify.evaluation:Evaluation",
    "verify": "discovery.vibroimpact.verify.verdict:VerifyResult",
    "calibrate": "discovery.vibroimpact.calibration.result:Calibration",
    "landscape": "discovery.vibroimpact.verify.criteria_landscape:Landscape",
    "ranked-model": "discovery.vibroimpact.fit.discovery_result:RankedModel",
    "fit": "discovery.vibroimpact.fit.discovery_result:DiscoveryResult",
    "identify": "discovery.vibroimpact.fit.identification:IdentificationResult",
    "intervals": "discovery.vibroimpact.fit.intervals:Intervals",
    "explain-iteration": "discovery.vibroimpact.explain.result:Iteration",
    "explain": "discovery.vibroimpact.explain.result:ExplainResult",
    "study": "discovery.vibroimpact.studies.result:StudyResult",
    "advise": "discovery.vibroimpact.advise.result:AdviseResult",
    "campaign": "discovery.vibroimpact.advise.campaign_loop:CampaignResult",
    "contact-models": "discovery.vibroimpact.fit.contact_fit:ContactModelsResult",
    "steady": "discovery.vibroimpact.dynamics.steady_states:SteadyState",
    "simulate": "discovery.vibroimpact.dynamics.synthetic:SimulatedRecord",
    "ueda-simulate": "discovery.ueda.simulated_record:SimulatedUedaRecord",
    "ueda-lyapunov": "discovery.ueda.exponents:Lyapunov",
    "ueda-attractor": "discovery.ueda.attractor_analysis:Attractor",
    "ueda-chart": "discovery.ueda.regime_chart:Chart",
    "ueda-discover": "discovery.ueda.equation_discovery:Discovery",
    "ueda-explain-iteration": "discovery.ueda.explanation:Iteration",
    "ueda-explain": "discovery.ueda.explanation:Explanation",
}


def _document(data):
    """``data`` as pure JSON values (non-finite numbers ``null``); raises ``TypeError``
    naming the value that is not data."""
    return json.loads(json.dumps(to_jsonable(data), allow_nan=False))


class Result:
    """The data-model side of a result (see the module docstring).

    A subclass sets ``KIND`` (a key of :data:`KINDS`), implements ``as_dict()`` (its own
    keys) and may set ``_LOAD``: ``{field: function of the document}`` for the fields that
    are not plain values of the same name.  Subclasses are dataclasses with ``eq=False``
    (equality is :meth:`__eq__`'s).
    """

    KIND = None
    _LOAD = {}

    # ---------------------------------------------------------------- the document
    def to_dict(self):
        """The result as a JSON-safe document (see the module docstring)."""
        doc = self.__dict__.get("_document")
        if doc is not None:
            return copy.deepcopy(doc)
        run = self.__dict__.get("_run") or {}
        out = {"schema_version": SCHEMA_VERSION, "result": self.KIND}
        out.update(run.get("head", {}))
        out.update(self.as_dict(**run.get("options", {})))
        out.update(run.get("tail", {}))
        return _document(out)

    def record_run(self, head=None, tail=None, **options):
        """Record what a run adds to the document: ``head`` (the command and its inputs)
        before the result's keys, ``tail`` (provenance, which wins a clash of keys) after,
        ``options`` for ``as_dict``; returns the result itself."""
        run = {"head": dict(head or {}), "tail": dict(tail or {}), "options": options}
        object.__setattr__(self, "_run", run)
        return self

    @property
    def run_record(self):
        """What :meth:`record_run` recorded: ``{"head", "tail", "options"}``."""
        return self.__dict__.get("_run") or {"head": {}, "tail": {}, "options": {}}

    @classmethod
    def from_dict(cls, d):
        """The result a document describes (the inverse of :meth:`to_dict`)."""
        check_document(d, "from_dict", expect=cls.KIND)
        obj = cls.__new__(cls)
        for f in dataclasses.fields(cls):
            if f.name in cls._LOAD:
                try:
                    value = cls._LOAD[f.name](d)
                except _Unreadable as exc:
                    # a nested result's field: the message names the whole path to it
                    raise _Unreadable(cls.KIND, (f.name, *exc.path), exc.cause) from None
                except (
                    KeyError,
                    TypeError,
                    ValueError,
                    ArithmeticError,
                    AttributeError,
                    InputError,
                ) as exc:
                    raise _Unreadable(cls.KIND, (f.name,), exc) from None
            elif f.name in d:
                value = _typed(cls.KIND, f, d[f.name])
            elif f.default is not dataclasses.MISSING:
                value = f.default
            elif f.default_factory is not dataclasses.MISSING:
                value = f.default_factory()
            else:
                value = None
            object.__setattr__(obj, f.name, value)
        object.__setattr__(obj, "_document", copy.deepcopy(d))
        return obj

    @staticmethod
    def from_summary(doc):
        """The result a run's ``summary.json`` describes, as its own type: the kind is the
        document's ``result``, or for a summary written before the schema version its
        command's (read with the keys it has); ``None`` for a command with no result kind."""
        kind = kind_of(doc)
        if kind is None:
            return None
        if "schema_version" not in doc:
            doc = {**doc, "schema_version": SCHEMA_VERSION, "result": kind}
        return result_class(kind).from_dict(doc)

    @property
    def loaded(self):
        """True for a result read back from a document (its simulations are not here)."""
        return self.__dict__.get("_document") is not None

    def __eq__(self, other):
        if type(other) is not type(self):
            return NotImplemented
        return self.to_dict() == other.to_dict()

    __hash__ = None

    # ---------------------------------------------------------------- files
    def save(self, directory):
        """Write ``directory/summary.json`` (the document), staged and put in place as a
        whole (:class:`~discovery._files._io.OutputDir`); returns the directory's path."""
        with OutputDir(directory) as out:
            self.write_into(out)
        return Path(directory)

    def write_into(self, out):
        """Write the document as ``summary.json`` into an open :class:`OutputDir`."""
        out.write_json("summary.json", self.to_dict())


#: the JSON types a plain field's annotation asks for (a tuple is a list in JSON; a float
#: may be an integer, or null for a number that is not finite)
_JSON_TYPES = {
    "dict": (dict,),
    "list": (list,),
    "tuple": (list,),
    "str": (str,),
    "bool": (bool,),
    "int": (int,),
    "float": (int, float, type(None)),
    "None": (type(None),),
}


def _json_types(f):
    """The JSON types the field's annotation allows, or None when it names no plain JSON
    type (an object the document holds in its own form)."""
    names = [
        n.strip()
        for n in (f.type if isinstance(f.type, str) else getattr(f.type, "__name__", str(f.type)))
        .replace("NoneType", "None")
        .split("|")
    ]
    if not all(n in _JSON_TYPES for n in names):
        return None
    allowed = tuple(t for n in names for t in _JSON_TYPES[n])
    if f.default is None:  # an optional field the document may leave null
        allowed += (type(None),)
    return allowed


def _typed(kind, f, value):
    """``value`` when it is of the field's JSON type (a bool is no number), else the
    document's field is unreadable."""
    allowed = _json_types(f)
    if allowed is None:
        return value
    if isinstance(value, bool) and bool not in allowed:
        ok = False
    else:
        ok = isinstance(value, allowed)
    if not ok:
        want = " or ".join(sorted({t.__name__.replace("NoneType", "null") for t in allowed}))
        raise _Unreadable(kind, (f.name,), TypeError(f"{type(value).__name__}, not {want}"))
    return value


def _prints(obj):
    """A loaded result prints, or its document was edited where no field's type tells (a
    field deleted, a key the summary reads inside a mapping): one :class:`InputError`, not
    the exception of the line that prints it.  :func:`load` asks it of what it reads; a
    report reads a document's keys as far as they go (a run directory of an older
    vidi)."""
    try:
        str(obj)
    except (
        TypeError,
        ValueError,
        AttributeError,
        KeyError,
        IndexError,
        ArithmeticError,
        RecursionError,
    ) as exc:
        raise InputError(
            f"from_dict: the {obj.KIND!r} document does not read as a result "
            f"({type(exc).__name__}: {short(exc, 80)}); was it edited? run the command again"
        ) from None


def check_document(d, where, expect=None):
    """Refuse what is not a result document of this version (one :class:`InputError`)."""
    if not isinstance(d, dict):
        raise InputError(f"{where}: a result document is a dict; got {type(d).__name__}")
    version = d.get("schema_version")
    if version is None:
        cmd = d.get("command")
        rerun = f"run `vidi {cmd}` again" if isinstance(cmd, str) else "run the command again"
        raise InputError(
            f"{where}: the summary has no schema_version (written by a vidi older than "
            f"results with a data model); {rerun} to get a result that loads"
        )
    if version != SCHEMA_VERSION:
        raise InputError(
            f"{where}: schema_version {version!r} is not {SCHEMA_VERSION}, the version "
            "this vidi reads; load it with the vidi that wrote it, or run the command again"
        )
    kind = d.get("result")
    if not isinstance(kind, str) or kind not in KINDS:
        raise InputError(f"{where}: unknown result kind {kind!r}; known: {', '.join(KINDS)}")
    if expect is not None and kind != expect:
        raise InputError(f"{where}: the document is a {kind!r} result, not {expect!r}")
    return kind


def result_class(kind):
    """The class of a result kind (a key of :data:`KINDS`)."""
    module, name = KINDS[kind].split(":")
    return getattr(import_module(module), name)


def load_summary(path):
    """The document of a saved result: ``path`` is a result directory (its
    ``summary.json``) or a summary file (``D.summary.json`` of ``vidi simulate``)."""
    p = Path(path)
    f = p / "summary.json" if p.is_dir() else p
    data, why = load_json(f)
    if data is None and why is None:
        raise InputError(
            f"{short(str(path))!r} holds no summary.json: give the --out directory of a vidi "
            "command (or a .summary.json file)"
        )
    if why is not None:
        raise InputError(f"{short(str(f))!r} {why}; give a vidi command's summary")
    return data


def load(path):
    """The result saved in ``path`` (a result directory or a ``.summary.json`` file), as
    its own type (:class:`~discovery.VerifyResult`, :class:`~discovery.DiscoveryResult`,
    ...).  A summary written before results had a schema version is one
    :class:`~discovery.errors.InputError` saying so."""
    if not isinstance(path, str) and not hasattr(path, "__fspath__"):
        from ..errors import VidiTypeError

        raise VidiTypeError(
            f"load: path must be a result directory or a summary file; got {type(path).__name__}"
        )
    d = load_summary(path)
    kind = check_document(d, f"load {short(str(path))!r}")
    result = result_class(kind).from_dict(d)
    _prints(result)
    return result


class _Unreadable(InputError):
    """A document's field that cannot be read, named by its path from the outer document
    (``selected.status``), with the reason."""

    def __init__(self, kind, path, cause):
        self.kind, self.path, self.cause = kind, tuple(path), cause
        super().__init__(
            f"from_dict: the {kind!r} document's {'.'.join(self.path)!r} cannot be read "
            f"({type(cause).__name__}: {short(cause, 80)}); was it edited? run the "
            "command again"
        )


def part(cls, d):
    """A result nested in a document (``d`` a dict without the head, or ``None``), as a
    loaded ``cls``."""
    if d is None:
        return None
    return cls.from_dict({**d, "schema_version": SCHEMA_VERSION, "result": cls.KIND})


#: the command whose report a result kind has (a saved result names no command)
_COMMANDS = {
    "calibrate": "calibrate",
    "verify": "verify",
    "landscape": "landscape",
    "fit": "fit",
    "identify": "identify",
    "explain": "explain",
    "study": "study",
    "advise": "advise",
    "campaign": "advise",
    "contact-models": "fit",
    "ueda-attractor": "ueda attractor",
    "ueda-chart": "ueda chart",
    "ueda-discover": "ueda discover",
    "ueda-explain": "ueda explain",
}


def command_of(doc):
    """``doc`` with its ``command`` (a result saved from Python has none: its kind's)."""
    kind = doc.get("result")
    if "command" in doc or not isinstance(kind, str) or kind not in _COMMANDS:
        return doc
    return {**doc, "command": _COMMANDS[kind]}


def kind_of(doc):
    """The result kind of a run's document: its ``result``, or for a summary written before
    the schema version the kind of its command (``None`` when it names none)."""
    kind = doc.get("result")
    if isinstance(kind, str) and kind in KINDS:
        return kind
    cmd = doc.get("command")
    if cmd == "fit" and doc.get("library") == "contact-models":
        return "contact-models"
    return next((k for k, c in _COMMANDS.items() if c == cmd and k != "contact-models"), None)
