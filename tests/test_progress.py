"""Progress on long commands: a bar with an ETA on a terminal, one line per stage
otherwise, nothing with --quiet; the API's callback sees every stage."""

import io
import sys
import threading
import types

import pytest

from discovery import ForceLaw, landscape, load_scenario
from discovery._api._progress import Reporter, interactive, reports_progress, resolve
from discovery.cli import main
from discovery.errors import VidiTypeError
from discovery.ueda import UedaSystem
from discovery.ueda.regime_chart import chart


def test_reporter_modes():
    plain = io.StringIO()
    r = Reporter(stream=plain, bar=False)
    for stage in ("a", "a", "b"):
        r(stage, 1, 3)
    r.close()
    assert plain.getvalue() == "a ...\nb ...\n"  # one line per stage
    # a stage that goes on prints its count every `every` seconds (issue 50: a pipe stayed
    # silent for the 160 s of the named models' fit)
    slow = io.StringIO()
    r = Reporter(stream=slow, bar=False)
    r.every = 0.0
    for k in range(3):
        r("fit", k, 3)
    assert slow.getvalue() == "fit ...\nfit: 1/3 ...\nfit: 2/3 ...\n"
    bar = io.StringIO()
    with Reporter(stream=bar, bar=True) as r:
        for k in range(4):
            r("rows", k, 3)
    assert "rows:" in bar.getvalue() and "3/3" in bar.getvalue()  # capped at the total
    quiet = io.StringIO()
    with Reporter(quiet=True, stream=quiet, bar=True) as r:
        r("rows", 1, 2)
    assert quiet.getvalue() == ""


def test_the_api_reports_every_row():
    calls = []
    sc = load_scenario("paper")
    landscape(
        sc,
        ForceLaw.parse("2.06e8*z + 1.28e7*zd"),
        [1.5e8, 2.06e8, 2.5e8],
        [1e7, 1.28e7],
        workers=1,
        progress=lambda *a: calls.append(a),
    )
    assert calls == [("landscape: rows of the grid", k, 3) for k in (1, 2, 3)]


def test_cli_progress_lines_and_quiet(tmp_path, capsys):
    args = ["landscape", "--grid", "3x3", "--workers", "1"]
    assert main([*args, "--out", str(tmp_path / "a")]) == 0
    err = capsys.readouterr().err
    assert err == "landscape: rows of the grid ...\n"  # stderr is not a terminal here
    assert main([*args, "--quiet", "--out", str(tmp_path / "b")]) == 0
    assert capsys.readouterr().err == ""


# ---------------------------------------------------------------- progress by default
# The API's progress=None is automatic: a bar when a person watches (stderr a terminal, or a
# Jupyter kernel), nothing otherwise; False is off, True on, a callable used as is. The
# tests give stderr a stream of their own, so the runner's terminal does not matter.


class _Terminal(io.StringIO):
    def isatty(self):
        return True


def _small_landscape(**kw):
    sc = load_scenario("paper")
    law = ForceLaw.parse("2.06e8*z + 1.28e7*zd")
    return landscape(sc, law, [1.5e8, 2.06e8, 2.5e8], [1e7, 1.28e7], workers=1, **kw)


@pytest.fixture
def no_kernel(monkeypatch):
    monkeypatch.delitem(sys.modules, "IPython", raising=False)


def test_a_terminal_gets_a_bar_by_default(monkeypatch, no_kernel):
    tty = _Terminal()
    monkeypatch.setattr(sys, "stderr", tty)
    _small_landscape()
    assert "landscape: rows of the grid" in tty.getvalue() and "3/3" in tty.getvalue()


def test_not_interactive_or_false_stays_silent(monkeypatch, no_kernel):
    log = io.StringIO()  # a pipe or a log file: not a terminal
    monkeypatch.setattr(sys, "stderr", log)
    _small_landscape()
    assert log.getvalue() == ""
    tty = _Terminal()
    monkeypatch.setattr(sys, "stderr", tty)
    _small_landscape(progress=False)
    assert tty.getvalue() == ""


def test_true_reports_even_off_a_terminal(monkeypatch, no_kernel):
    log = io.StringIO()
    monkeypatch.setattr(sys, "stderr", log)
    _small_landscape(progress=True)
    assert log.getvalue() == "landscape: rows of the grid ...\n"  # a line per stage


def test_a_notebook_kernel_is_interactive(monkeypatch):
    """A Jupyter kernel's stderr is no terminal; IPython's shell there has a kernel."""
    shell = types.SimpleNamespace(kernel=None)
    monkeypatch.setitem(sys.modules, "IPython", types.SimpleNamespace(get_ipython=lambda: shell))
    assert not interactive(io.StringIO())  # IPython in a terminal without a kernel
    shell.kernel = object()
    assert interactive(io.StringIO())
    out = io.StringIO()
    monkeypatch.setattr(sys, "stderr", out)
    for progress in (None, True):
        rep, owned = resolve(progress)
        assert owned and rep.bar  # a bar in the notebook's output
        rep.close()


def test_ipython_absent_is_not_imported(monkeypatch, no_kernel):
    assert not interactive(io.StringIO())
    assert "IPython" not in sys.modules


def test_worker_threads_and_nested_calls_stay_silent(monkeypatch, no_kernel):
    monkeypatch.setattr(sys, "stderr", _Terminal())
    seen = {}

    @reports_progress
    def inner(progress=None):
        return progress

    @reports_progress
    def outer(progress=None):
        seen["outer"], seen["inner"] = progress, inner()
        seen["inner given"] = inner(progress=progress)

    outer()
    assert isinstance(seen["outer"], Reporter)
    assert seen["inner"] is None  # the caller's stages are the ones reported
    assert seen["inner given"] is seen["outer"]
    thread = threading.Thread(target=lambda: seen.update(thread=interactive()))
    thread.start()
    thread.join()
    assert seen["thread"] is False


def test_a_wrong_progress_is_refused_before_any_work():
    with pytest.raises(VidiTypeError, match=r"landscape: progress must be None \(automatic\)"):
        _small_landscape(progress=5)


def test_the_ueda_chart_reports_with_the_one_protocol():
    calls = []
    chart(
        UedaSystem.from_model("duffing"),
        [1.0, 1.1],
        [0.1, 0.15],
        transient=20,
        periods=40,
        max_period=8,
        workers=1,
        progress=lambda *a: calls.append(a),
    )
    assert calls == [("chart: rows", 1, 2), ("chart: rows", 2, 2)]


def test_every_public_function_with_progress_resolves_it_one_way():
    """Every public function that takes ``progress`` goes through the one resolver."""
    import inspect

    import discovery
    import discovery.ueda
    import discovery.ueda.regime_chart

    found = []
    for module in (discovery, discovery.ueda, discovery.ueda.regime_chart):
        for name in getattr(module, "__all__", dir(module)):
            obj = getattr(module, name)
            if inspect.isfunction(obj) and "progress" in inspect.signature(obj).parameters:
                found.append(name)
                chain, wrapped = obj, False
                while chain is not None and not wrapped:
                    wrapped = getattr(chain, "__vidi_progress__", False)
                    chain = getattr(chain, "__wrapped__", None)
                assert wrapped, f"{module.__name__}.{name} does not resolve progress"
    assert {"study", "discover", "explain", "identify", "landscape", "advise", "chart"} <= set(
        found
    )
