"""Settings objects: a long public function's options as one checked object or as keywords."""

import importlib
import json
import pkgutil

import pytest

import discovery
from discovery._api._settings import Settings, options_of
from discovery.errors import InputError, VidiTypeError


def _all_settings():
    """Every settings class of the package (its modules imported)."""
    for info in pkgutil.walk_packages(discovery.__path__, "discovery."):
        if ".cli" not in info.name:
            importlib.import_module(info.name)
    seen, todo = [], list(Settings.__subclasses__())
    while todo:
        cls = todo.pop()
        seen.append(cls)
        todo += cls.__subclasses__()
    return sorted(seen, key=lambda c: c.__name__)


SETTINGS = _all_settings()


def test_a_functions_settings_class_is_public_where_the_function_is():
    """Wherever a package exports a function that takes settings, it exports their class
    too (``discovery.DiscoverSettings`` beside ``discovery.discover``)."""
    missing, found = [], set()
    packages = [discovery] + [
        importlib.import_module(info.name)
        for info in pkgutil.walk_packages(discovery.__path__, "discovery.")
        if info.ispkg
    ]
    for owner in packages:
        for name in getattr(owner, "__all__", ()):
            cls = getattr(getattr(owner, name), "__vidi_settings__", None)
            if cls is not None:
                found.add(cls)
                if getattr(owner, cls.__name__, None) is not cls:
                    missing.append(f"{owner.__name__}.{cls.__name__} (beside {name})")
    assert not missing, missing
    assert {"DiscoverSettings", "UedaChartSettings"} <= {c.__name__ for c in found}


@pytest.mark.parametrize("cls", SETTINGS, ids=lambda c: c.__name__)
def test_settings_round_trip_through_json(cls):
    d = cls()
    assert cls.from_dict(json.loads(json.dumps(d.to_dict(), allow_nan=False))) == d
    assert d.changed() == {}


def test_a_changed_field_round_trips_with_its_object():
    s = discovery.DiscoverSettings(
        tolerances=discovery.Tolerances(rtol=1e-8), require=("z",), seed=7
    )
    back = discovery.DiscoverSettings.from_dict(json.loads(json.dumps(s.to_dict())))
    assert back == s and back.tolerances.rtol == 1e-8
    assert set(s.changed()) == {"tolerances", "require", "seed"}


def test_keywords_override_the_object():
    base = discovery.DiscoverSettings(library="poly:3", seed=4)
    s = discovery.DiscoverSettings.of("discover", base, {"seed": 5})
    assert (s.library, s.seed) == ("poly:3", 5)
    assert base.seed == 4  # the object given is not changed


def test_an_unknown_keyword_is_one_line_with_the_closest_name():
    with pytest.raises(
        VidiTypeError,
        match=r"discover: unexpected keyword 'shortlst' \(did you mean 'shortlist'\?\)",
    ):
        discovery.DiscoverSettings.of("discover", None, {"shortlst": 3})


def test_a_wrong_value_names_the_function_or_the_class():
    with pytest.raises(InputError, match="^discover: max_terms must be"):
        discovery.DiscoverSettings.of("discover", None, {"max_terms": 0})
    with pytest.raises(InputError, match="^DiscoverSettings: max_terms must be"):
        discovery.DiscoverSettings(max_terms=0)
    with pytest.raises(VidiTypeError, match="settings must be a DiscoverSettings"):
        discovery.DiscoverSettings.of("discover", {"seed": 1}, {})


def test_a_function_takes_its_settings_object(paper):
    """The object and the keywords give the same record."""
    law = paper.law
    a = discovery.field_record(paper, law, periods=2, transient=3, seed=2)
    s = discovery.FieldRecordSettings(periods=2, transient=3, seed=2)
    b = discovery.field_record(paper, law, settings=s)
    assert (a.F == b.F).all() and a.source == b.source


def test_options_of_lists_the_signature_and_the_settings():
    opts = options_of(discovery.discover)
    assert opts["library"] == "poly:2" and opts["progress"] is None
    assert "settings" not in opts and "options" not in opts


def _taking():
    """Every public function that takes a settings class (``@takes``)."""
    names = sorted(n for n in discovery.__all__ if not n[0].isupper())
    funcs = [getattr(discovery, n) for n in names]
    return [f for f in funcs if getattr(f, "__vidi_settings__", None) is not None]


@pytest.mark.parametrize("func", _taking(), ids=lambda f: f.__name__)
def test_the_signature_lists_every_option_as_a_keyword(func):
    """``help(discover)`` showed ``**options``: the signature now writes out each field of
    the function's settings class as a keyword at its default, as an editor and the API
    pages read it."""
    import inspect

    params = inspect.signature(func).parameters
    assert not any(p.kind is p.VAR_KEYWORD for p in params.values())
    defaults = func.__vidi_settings__.defaults()
    for name in func.__vidi_settings__.names():
        assert name in params, name
        if params[name].kind is params[name].KEYWORD_ONLY:
            assert params[name].default == getattr(defaults, name), name
    assert "library='poly:2'" in str(inspect.signature(discovery.discover))


@pytest.mark.parametrize("cls", SETTINGS, ids=lambda c: c.__name__)
def test_repr_is_what_one_would_type_and_print_lists_every_option(cls):
    assert cls.__repr__ is Settings.__repr__, "declare it @dataclass(frozen=True, repr=False)"
    assert repr(cls()) == f"{cls.__name__}()"
    text = str(cls())
    assert text.startswith(f"{cls.__name__}: 0 of {len(cls.names())} options changed")
    assert len(text.splitlines()) == len(cls.names()) + 1


def test_a_changed_settings_object_reads_back_from_its_repr():
    s = discovery.DiscoverSettings(library="poly:3", seed=7)
    assert repr(s) == "DiscoverSettings(library='poly:3', seed=7)"
    assert eval(repr(s), {"DiscoverSettings": discovery.DiscoverSettings}) == s
    assert "seed" in str(s) and "(changed)" in str(s)


@pytest.mark.parametrize(
    "make",
    [
        lambda: __import__("discovery").DiscoverSettings(n_boot=0),
        lambda: __import__("discovery").DiscoverSettings(max_simulations=1),
        lambda: __import__("discovery").DiscoverSettings(criterion="I9"),
        lambda: __import__("discovery").DiscoverSettings(selection="bogus"),
        lambda: __import__("discovery").DiscoverSettings(scoring="bogus"),
        lambda: __import__("discovery").ExplainSettings(alpha=1.0),
        lambda: __import__("discovery").IdentifySettings(method="bogus"),
        lambda: __import__("discovery").IdentifySettings(criterion="I9"),
    ],
)
def test_settings_refused_when_used_are_refused_when_made(make):
    """Issue 53: each of these was accepted by the settings object and refused only by the
    function it was given to."""
    from discovery.errors import InputError

    with pytest.raises(InputError):
        make()


def test_explain_takes_no_added_effect_as_its_cli_does():
    from discovery import ExplainSettings

    assert ExplainSettings(max_iterations=0).max_iterations == 0
