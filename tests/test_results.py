"""Results as a data model: every result round-trips through its JSON document, every
command's ``summary.json`` is its result's ``to_dict()``, ``discovery.load`` gives the
right type back, and a summary from before the schema version is one clear error."""

import json
import os

import numpy as np
import pytest

import discovery
from discovery._api._result import KINDS, SCHEMA_VERSION, Result, part, result_class
from discovery.cli import main
from discovery.errors import InputError

LAW = "2.06e8*z + 1.28e7*zd"

# every command's run, small (its --out is the key)
COMMANDS = {
    "verify": ["verify", "--data", "D.csv", "--law", LAW],
    "fit": ["fit", "--data", "D.csv", "--no-refine", "--intervals", "0"],
    "fit-refined": ["fit", "--data", "D.csv", "--intervals", "5", "--workers", "1"],
    "identify": ["identify", "--data", "D.csv", "--start", "1.8e8*z + 1.1e7*zd"]
    + ["--max-simulations", "20"],
    "landscape": ["landscape", "--grid", "3x3", "--workers", "1"],
    "steady": ["steady", "--law", LAW, "--sensitivities"],
    "explain": ["explain", "--data", "D.csv", "--start", "linear", "--max-iterations", "1"],
    "ueda-discover": ["ueda", "discover", "--data", "U.csv", "--model", "negres"]
    + ["--model-periods", "400", "--resamples", "40"],
    "ueda-explain": ["ueda", "explain", "--data", "U.csv", "--model", "negres"]
    + ["--model-periods", "400", "--resamples", "40"],
    "ueda-attractor": ["ueda", "attractor", "--model", "negres", "--periods", "200"],
    "ueda-chart": ["ueda", "chart", "--nu", "0.9:1.1:3", "--B", "0.2:0.4:2"]
    + ["--transient", "50", "--periods", "40", "--max-period", "4", "--workers", "1"],
    "contact-models": ["fit", "--data", "D.csv", "--library", "contact-models"]
    + ["--intervals", "0", "--max-simulations", "10"],
    "advise": ["advise", "--law", LAW, "--law", "2.06e8*z + 1.6e7*zd", "--noise", "0.01"]
    + ["--amplitude", "4e5:6e5", "--frequency", "22:28", "--grid", "2x2", "--refine", "0"]
    + ["--workers", "1"],
}
KIND_OF = {
    "simulate": "simulate",
    "ueda-simulate": "ueda-simulate",
    "verify": "verify",
    "fit": "fit",
    "fit-refined": "fit",
    "identify": "identify",
    "landscape": "landscape",
    "steady": "steady",
    "explain": "explain",
    "ueda-discover": "ueda-discover",
    "ueda-explain": "ueda-explain",
    "ueda-attractor": "ueda-attractor",
    "ueda-chart": "ueda-chart",
    "contact-models": "contact-models",
    "advise": "advise",
}


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """``(directory, {out: the result object the command saved})`` of one small run of
    every command (the objects caught where the command records its run)."""
    d = tmp_path_factory.mktemp("results")
    caught = {}
    original = Result.record_run

    def catch(self, head=None, tail=None, **options):
        caught[(head or {}).get("command") or self.KIND] = self
        return original(self, head, tail, **options)

    cwd = os.getcwd()
    os.chdir(d)
    mp = pytest.MonkeyPatch()
    mp.setattr(Result, "record_run", catch)
    try:
        sim = ["simulate", "--periods", "12", "--noise", "0.01", "--seed", "1", "--out", "D.csv"]
        assert main(sim) == 0
        assert main(["ueda", "simulate", "--periods", "120", "--out", "U.csv"]) == 0
        objects = {"simulate": caught["simulate"], "ueda-simulate": caught["ueda simulate"]}
        for out, argv in COMMANDS.items():
            assert main([*argv, "--out", out]) == 0, out
            objects[out] = caught[" ".join(argv[:2]) if argv[0] == "ueda" else argv[0]]
    finally:
        mp.undo()
        os.chdir(cwd)
    return d, objects


# where each run's summary is (simulate writes D.summary.json beside D.csv)
SUMMARY = {
    "simulate": "D.summary.json",
    "ueda-simulate": "U.summary.json",
    **{k: f"{k}/summary.json" for k in COMMANDS},
}


@pytest.mark.parametrize("out", list(KIND_OF))
def test_every_result_round_trips_and_is_json(runs, out):
    d, objects = runs
    r = objects[out]
    doc = r.to_dict()
    text = json.dumps(doc, allow_nan=False)  # no ndarrays, no NaN
    assert doc["schema_version"] == SCHEMA_VERSION and doc["result"] == KIND_OF[out]
    back = type(r).from_dict(json.loads(text))
    assert back == r and back.loaded and not r.loaded
    assert isinstance(back, result_class(KIND_OF[out]))


@pytest.mark.parametrize("out", list(KIND_OF))
def test_each_command_summary_is_its_result_to_dict(runs, out):
    d, objects = runs
    saved = json.loads((d / SUMMARY[out]).read_text())
    assert saved == objects[out].to_dict()
    loaded = discovery.load(d / SUMMARY[out])
    assert type(loaded) is type(objects[out]) and loaded == objects[out]


@pytest.mark.parametrize(
    "out", ["verify", "fit", "fit-refined", "identify", "landscape", "explain", "steady"]
)
def test_a_loaded_result_prints_as_the_original(runs, out):
    """The typed fields come back: the printed report of a loaded result is the
    original's (the vibro-impact results, whose printing reads their fields)."""
    d, objects = runs
    loaded, original = str(discovery.load(d / out)).splitlines(), str(objects[out]).splitlines()
    if out == "explain":  # the command records its own wall time as "seconds" (as before)
        loaded, original = loaded[:-1], original[:-1]
    assert loaded == original


def test_typed_fields_come_back(runs):
    d, objects = runs
    v = discovery.load(d / "verify")
    assert v.law == discovery.ForceLaw.parse(LAW)
    assert v.evaluation.criteria == objects["verify"].evaluation.criteria
    assert v.evaluation.limits.keys() == objects["verify"].evaluation.limits.keys()
    land, orig = discovery.load(d / "landscape"), objects["landscape"]
    for a, b in zip(land.axes, orig.axes, strict=True):
        np.testing.assert_array_equal(a, b)
    for k, v in orig.values.items():
        np.testing.assert_array_equal(land.values[k], v)
    assert (land.regime == orig.regime).all() and land.argmin("I2") == orig.argmin("I2")
    fit = discovery.load(d / "fit")
    assert fit.selected.law == objects["fit"].selected.law
    assert [m.law for m in fit.ranking] == [m.law for m in objects["fit"].ranking]
    ex = discovery.load(d / "explain")
    assert ex.final_model.law == objects["explain"].final_model.law
    np.testing.assert_array_equal(discovery.load(d / "ueda-chart").nu, objects["ueda-chart"].nu)
    rec = discovery.load(d / "D.summary.json")
    assert rec.law == discovery.ForceLaw.parse("2.06e8*z + 1.28e7*zd") and rec.samples == 9600
    uex = discovery.load(d / "ueda-explain")
    assert uex.final_model == objects["ueda-explain"].final_model
    assert [it.model_after for it in uex.iterations] == [
        it.model_after for it in objects["ueda-explain"].iterations
    ]
    att = discovery.load(d / "ueda-attractor")
    assert att.system == objects["ueda-attractor"].system
    assert att.lyapunov.value == objects["ueda-attractor"].lyapunov.value


def test_a_loaded_fit_holds_what_its_report_reads(runs):
    """The standard errors, intervals, each candidate's BIC, the certificate (the selected
    model's too), the records and each record's check come back typed, equal to the fresh
    result's."""
    d, objects = runs
    fresh, loaded = objects["fit-refined"], discovery.load(d / "fit-refined")
    sel, orig = loaded.selected, fresh.selected
    assert sel.refinement is None and orig.refinement is not None
    assert sel.standard_errors and sel.standard_errors == orig.standard_errors
    assert all(type(v) is float for v in sel.standard_errors.values())
    assert sel.intervals.bounds == {k: tuple(v) for k, v in orig.intervals.bounds.items()}
    assert sel.intervals.method == orig.intervals.method
    assert [m.bic for m in loaded.ranking] == [m.bic for m in fresh.ranking]
    assert [type(m.bic) for m in loaded.ranking] == [float] * len(fresh.ranking)
    assert [m.candidate.rss for m in loaded.ranking] == [m.candidate.rss for m in fresh.ranking]
    kept = ("method", "holds", "worst_violation", "domain", "conditions")
    as_kept = {k: v for k, v in fresh.certificate.as_dict().items() if k in kept}
    assert {k: v for k, v in loaded.certificate.as_dict().items() if k in kept} == as_kept
    assert sel.certificate == loaded.certificate and loaded.ranking[1].certificate is None
    assert loaded.records == fresh.records and [r.data for r in loaded.records] == ["D.csv"]
    assert [ev.criteria for ev in sel.evaluations] == [ev.criteria for ev in orig.evaluations]
    assert (sel.criteria, sel.noise_floor, sel.limits) == (
        orig.criteria,
        orig.noise_floor,
        orig.limits,
    )
    assert (loaded.equivalent, loaded.warnings) == (fresh.equivalent, fresh.warnings)
    assert loaded.settings == fresh.settings and sel.defects == orig.defects


def test_save_and_load_from_the_api(runs, tmp_path):
    d, objects = runs
    r = objects["verify"]
    where = r.save(tmp_path / "v")
    assert (where / "summary.json").is_file() and discovery.load(where) == r


def test_nested_results_round_trip_alone(runs):
    """The parts of a result (an evaluation, a ranked model, an iteration, intervals, the
    exponents) are results of their own."""
    _, objects = runs
    parts = [
        objects["verify"].evaluation,
        objects["fit"].selected,
        objects["ueda-attractor"].lyapunov,
        *objects["explain"].iterations,
        *objects["ueda-explain"].iterations,
    ]
    assert len({type(p) for p in parts}) >= 4
    for p in parts:
        doc = json.loads(json.dumps(p.to_dict(), allow_nan=False))
        assert type(p).from_dict(doc) == p


def test_every_kind_has_a_class():
    for kind in KINDS:
        assert result_class(kind).KIND == kind


def test_an_old_summary_is_one_clear_error(runs, tmp_path, capsys):
    d, _ = runs
    old = tmp_path / "old"
    old.mkdir()
    doc = json.loads((d / "verify" / "summary.json").read_text())
    del doc["schema_version"], doc["result"]
    (old / "summary.json").write_text(json.dumps(doc))
    with pytest.raises(InputError, match="no schema_version.*run `vidi verify` again"):
        discovery.load(old)
    doc["schema_version"] = SCHEMA_VERSION + 1
    with pytest.raises(InputError, match="schema_version 2 is not 1"):
        part.__globals__["check_document"](doc, "x")
    with pytest.raises(InputError, match="holds no summary.json"):
        discovery.load(tmp_path)


@pytest.mark.parametrize("out", ["verify", "fit", "fit-refined", "landscape", "ueda-discover"])
def test_a_report_from_a_result_equals_the_report_from_its_directory(runs, out, tmp_path):
    d, objects = runs
    r = objects[out]
    from_dir = discovery.report(d / out, compile=False).tex.read_text()
    from_object = discovery.report(r, out=d / out, compile=False).tex.read_text()
    assert from_object == from_dir
    # saved from Python into an empty directory: the same report, less the command's
    # own keys (no figures, no provenance)
    plain = type(r).from_dict({k: v for k, v in r.to_dict().items() if k not in ("command",)})
    rep = discovery.report(plain, out=tmp_path / "saved", compile=False)
    assert rep.kind == r.to_dict()["command"]
    assert discovery.report(tmp_path / "saved", compile=False).tex.read_text() == (
        rep.tex.read_text()
    )
    with pytest.raises(InputError, match="holds another result"):
        discovery.report(objects["identify"], out=d / out, compile=False)


@pytest.mark.parametrize("out", ["ueda-attractor", "ueda-chart", "ueda-explain"])
def test_a_ueda_report_from_a_result_equals_the_report_from_its_directory(runs, out, tmp_path):
    test_a_report_from_a_result_equals_the_report_from_its_directory(runs, out, tmp_path)


def test_a_loaded_ueda_result_has_what_its_report_reads(runs):
    """The fields of Ueda's results that their reports read come back typed (the regime,
    the final model's coefficients); a loaded chart, whose grids are not in its summary,
    gives its summary's fractions and periods."""
    d, objects = runs
    att, orig = discovery.load(d / "ueda-attractor"), objects["ueda-attractor"]
    assert (att.regime.regime, att.regime.kind, att.regime.period) == (
        orig.regime.regime,
        orig.regime.kind,
        orig.regime.period,
    )
    assert att.regime.evidence["rule"] == orig.regime.evidence["rule"]
    ch, orig = discovery.load(d / "ueda-chart"), objects["ueda-chart"]
    assert ch.fractions() == orig.fractions() and ch.period_counts() == orig.period_counts()
    np.testing.assert_array_equal(ch.B, orig.B)
    dis, orig = discovery.load(d / "ueda-discover"), objects["ueda-discover"]
    assert dis.terms == orig.terms and dis.coefficients == orig.coefficients
    assert dis.standard_errors == orig.standard_errors and dis.n_windows == orig.n_windows
    ex, orig = discovery.load(d / "ueda-explain"), objects["ueda-explain"]
    assert ex.coefficients == orig.coefficients
    assert ex.standard_errors == orig.standard_errors
    assert ex.effects_added == orig.effects_added and ex.gap == orig.gap
    assert ex.consistent == orig.consistent and ex.stopped_because == orig.stopped_because


def test_an_old_or_edited_summary_in_the_cli_is_exit_2_and_one_line(runs, tmp_path, capsys):
    d, _ = runs
    old = tmp_path / "old-landscape"
    old.mkdir()
    doc = json.loads((d / "landscape" / "summary.json").read_text())
    (old / "summary.json").write_text(
        json.dumps({k: v for k, v in doc.items() if k not in ("schema_version", "result")})
    )
    argv = ["identify", "--data", str(d / "D.csv"), "--start", "1.8e8*z + 1.1e7*zd"]
    argv += ["--max-simulations", "4", "--out", str(tmp_path / "i")]
    capsys.readouterr()
    assert main([*argv, "--landscape", str(old)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "no schema_version" in err and "vidi landscape" in err
    edited = tmp_path / "edited"
    edited.mkdir()
    (edited / "summary.json").write_text(json.dumps({**doc, "alpha1": "many"}))
    assert main([*argv, "--landscape", str(edited)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "'axes' cannot be read" in err
    # the report of an old run directory still reads (from its keys, as before)
    assert "Criteria landscape" in discovery.report(old, compile=False).tex.read_text()


def test_a_study_round_trips_and_its_summary_is_its_to_dict(tmp_path):
    cfg = {
        "name": "tiny",
        "seeds": 1,
        "factors": {
            "force_noise": [0.01],
            "periods": [4],
            "library": ["z, zd"],
            "selection": ["best-subset"],
            "refine": [False],
        },
    }
    r = discovery.study(cfg, tmp_path / "s", workers=1)
    doc = json.loads(json.dumps(r.to_dict(), allow_nan=False))
    assert doc == json.loads((tmp_path / "s" / "summary.json").read_text())
    assert doc["result"] == "study" and doc["command"] == "study" and doc["runs"] == 1
    loaded = discovery.load(tmp_path / "s")
    assert loaded == r and type(r).from_dict(doc) == r
    assert loaded.config.name == "tiny" and loaded.config.varied == r.config.varied
    assert len(loaded.cells) == len(r.cells) and loaded.figures == r.figures and loaded.runs == []


def test_a_ranked_model_s_mean_criteria_skip_what_one_record_lacks():
    """Two records, one judged over its span (with I5), one on the steady orbit (without):
    the mean over the records has the criteria both have, no KeyError (the demo's fit)."""
    from discovery.vibroimpact.fit.discovery_result import _mean_over

    assert _mean_over([{"I2": 0.1, "I5": 0.04}, {"I2": 0.3}]) == pytest.approx({"I2": 0.2})
    assert _mean_over([{"I2": 0.1}, {}]) == {}


@pytest.mark.parametrize("out", ["advise", "contact-models"])
def test_advise_and_contact_models_are_results_like_the_others(runs, out, tmp_path):
    """An advise and a contact-models run: the loaded result prints as the original, and
    its report from the object equals the report from its directory (saved from Python
    into an empty directory too)."""
    d, objects = runs
    r = objects[out]
    assert isinstance(r, Result)
    assert str(discovery.load(d / out)) == str(r)
    from_dir = discovery.report(d / out, compile=False).tex.read_text()
    assert discovery.report(r, out=d / out, compile=False).tex.read_text() == from_dir
    saved = r.save(tmp_path / "saved")
    assert (saved / "summary.json").is_file()
    if out == "advise":  # its table of every point goes with its document
        assert (saved / "advise.csv").read_text() == (d / out / "advise.csv").read_text()
    rep = discovery.report(r, out=saved, compile=False)
    assert "\\section" in rep.tex.read_text()


def _paths(doc, depth=2, prefix=()):
    """Every key path of ``doc`` down to ``depth`` levels (dicts, and a list's first item)."""
    if depth == 0:
        return
    items = (
        doc.items()
        if isinstance(doc, dict)
        else ([(0, doc[0])] if isinstance(doc, list) and doc else [])
    )
    for k, v in items:
        if prefix == () and k in ("schema_version", "result"):
            continue
        yield (*prefix, k)
        yield from _paths(v, depth - 1, (*prefix, k))


def _mutated(doc, path, value):
    """A deep copy of ``doc`` with the field at ``path`` replaced (or deleted: ``value`` is
    ``_DELETE``)."""
    d = json.loads(json.dumps(doc))
    node = d
    for k in path[:-1]:
        node = node[k]
    if value is _DELETE:
        del node[path[-1]]
    else:
        node[path[-1]] = value
    return d


_DELETE = object()
# what an edit or a careless tool puts in a field: nothing, text, a list, a number, a
# mapping, deep nesting
_VALUES = (_DELETE, None, "text", [1, "x"], -1.5, {"a": 1}, json.loads("[" * 60 + "]" * 60))


@pytest.mark.parametrize("out", list(KIND_OF))
def test_a_mutated_document_loads_or_is_one_project_error(runs, tmp_path, out):
    """Issue 53: every field of every result kind's saved document, deleted or replaced by
    a value of another type, either loads into a result that prints, or is the project's
    own error naming what to do, never Python's own exception (a seeded sample of the
    fields two levels deep, every top-level one)."""
    from discovery.errors import VidiError

    d, _ = runs
    doc = json.loads((d / SUMMARY[out]).read_text())
    paths = list(_paths(doc))
    rng = np.random.default_rng(53)
    top = [p for p in paths if len(p) == 1]
    deep = [p for p in paths if len(p) > 1]
    chosen = top + [deep[i] for i in rng.permutation(len(deep))[:40]]
    bad = []
    for path in chosen:
        for value in _VALUES:
            f = tmp_path / "m.summary.json"
            f.write_text(json.dumps(_mutated(doc, path, value)))
            try:
                str(discovery.load(f))
            except VidiError as exc:
                assert "\n" not in str(exc).strip(), (path, str(exc))
            except Exception as exc:  # noqa: BLE001 (what the test looks for)
                bad.append(f"{'.'.join(map(str, path))} = {str(value)[:20]}: {exc!r}"[:200])
    assert not bad, f"{len(bad)} mutations raised Python's own errors:\n" + "\n".join(bad[:20])


def _documents():
    """``(class, a document its to_dict wrote)`` of the objects results hold and the
    settings."""
    from discovery.vibroimpact.advise.candidates import Knobs, NoiseModel, SafeRegion
    from discovery.vibroimpact.explain.loop import ExplainSettings
    from discovery.vibroimpact.fit.discovery import DiscoverSettings

    return [
        (discovery.ForceLaw, discovery.ForceLaw.parse(LAW).as_dict()),
        (Knobs, Knobs((3e5, 6e5), (20.0, 30.0)).to_dict()),
        (NoiseModel, NoiseModel(relative=0.01).to_dict()),
        (SafeRegion, SafeRegion(1e7, 1e-3).to_dict()),
        (ExplainSettings, ExplainSettings().to_dict()),
        (DiscoverSettings, DiscoverSettings().to_dict()),
    ]


@pytest.mark.parametrize("cls, doc", _documents(), ids=lambda x: getattr(x, "__name__", ""))
def test_from_dict_of_a_hostile_document_is_one_project_error(cls, doc):
    """Issue 53: the from_dict of Knobs, NoiseModel, SafeRegion, ForceLaw and the settings
    raised KeyError, TypeError, AttributeError, RecursionError on documents that are not
    theirs; a document of the wrong shape or with a field of another type is one
    InputError, and the document to_dict wrote reads back."""
    from discovery.errors import VidiError

    assert cls.from_dict(doc) is not None
    hostile = [v for v in _VALUES if v is not _DELETE]
    cases = [*hostile, {}]
    cases += [{**doc, k: v} for k in doc for v in hostile]
    bad = []
    for case in cases:
        try:
            cls.from_dict(case)
        except VidiError as exc:
            assert "\n" not in str(exc)
        except Exception as exc:  # noqa: BLE001 (what the test looks for)
            bad.append(f"{str(case)[:60]}: {exc!r}"[:160])
    assert not bad, "\n".join(bad[:10])
