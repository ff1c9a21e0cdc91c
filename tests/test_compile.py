"""Whether the compiled kernels are cached, wherever numba keeps its cache, and the one line a
run that must compile prints (:mod:`discovery._startup._compile`)."""

import io
import os
import subprocess
import sys
import textwrap

import discovery._startup._compile as C


def test_the_installed_kernels_are_cached(monkeypatch):
    # `make install` compiled them (python -m discovery.warm) before the suite runs
    monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)
    assert C.cached("vibro-impact") and C.cached("oscillator")


def test_the_cache_folder_is_numbas_own_with_numba_cache_dir(tmp_path, monkeypatch):
    """A module compiled with NUMBA_CACHE_DIR set leaves its index where
    ``_cache_folder`` looks."""
    src = tmp_path / "mod"
    src.mkdir()
    (src / "m.py").write_text(
        textwrap.dedent("""
            from numba import njit

            @njit(cache=True)
            def f(x):
                return x + 1

            f(1)
        """)
    )
    cache = tmp_path / "cache"
    env = {**os.environ, "NUMBA_CACHE_DIR": str(cache)}
    subprocess.run([sys.executable, "-c", "import m"], cwd=src, env=env, check=True)
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(cache))
    assert any(p.suffix == ".nbi" for p in C._cache_folder(src).iterdir())
    monkeypatch.delenv("NUMBA_CACHE_DIR")
    assert C._cache_folder(src) == src / "__pycache__"


def test_a_changed_source_of_the_kernel_drops_its_whole_cache(tmp_path, monkeypatch):
    """Numba stamps a cached function with its own file only, and the function holds what it
    calls from the kernel's other modules: the cache is kept while the digest of all the
    kernel's sources is the one it was made with, and dropped when it is not."""
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path))
    folder, prefix = C.KERNELS["vibro-impact"]
    cache = C._cache_folder(folder)
    C.refresh()
    entry = cache / f"{prefix}1.py311.nbi"
    entry.write_bytes(b"")
    assert C.cached() and entry.exists()  # the same sources: kept
    (cache / C._STAMP).write_text("the digest of an older kernel")
    assert not C.cached() and not entry.exists()
    assert (cache / C._STAMP).read_text() != "the digest of an older kernel"


def test_an_empty_cache_is_announced_once(tmp_path, monkeypatch):
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path))
    monkeypatch.setattr(C, "_ANNOUNCED", set())
    assert not C.cached("vibro-impact")
    out = io.StringIO()
    C.announce_compile("vibro-impact", stream=out)
    C.announce_compile("vibro-impact", stream=out)
    lines = out.getvalue().splitlines()
    assert len(lines) == 1 and lines[0].startswith("vidi: compiling the vibro-impact simulator")


def test_a_steady_state_announces_the_compile_before_its_first_period(
    tmp_path, monkeypatch, capsys
):
    """The stroboscopic map is the first to call the kernel in `vidi steady` (its contact
    modes' set-up, when it is built): it says so first."""
    from discovery import load_scenario
    from discovery.vibroimpact.dynamics.steady_states import StroboscopicMap

    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path))
    monkeypatch.setattr(C, "_ANNOUNCED", set())
    sc = load_scenario("paper")
    StroboscopicMap(sc, sc.law)
    err = capsys.readouterr().err
    assert (
        err.startswith("vidi: compiling the vibro-impact simulator once") and err.count("\n") == 1
    )


def test_warm_announces_the_compile_once(tmp_path, monkeypatch, capsys):
    """`make install`'s compile says so in one line, not once more per kernel call."""
    import discovery.warm as W

    monkeypatch.setattr(C, "_ANNOUNCED", set())
    monkeypatch.setattr(W, "_ANNOUNCED", C._ANNOUNCED)
    monkeypatch.setattr(W, "cached", lambda kernel: False)  # as with an empty cache
    monkeypatch.setattr(W, "warm", lambda: {k: 0.0 for k in C.KERNELS})
    assert W.main() == 0
    C.announce_compile("vibro-impact")  # what the first run would print
    out, err = capsys.readouterr()
    assert out.count("compiling the simulators once") == 1 and "vidi: compiling" not in err


def test_warm_says_it_is_still_compiling_while_it_compiles(monkeypatch, capsys):
    """A long compile is never silent: a line every heartbeat until it ends, none after."""
    import time

    import discovery.warm as W

    monkeypatch.setattr(C, "_ANNOUNCED", set())
    monkeypatch.setattr(W, "_ANNOUNCED", C._ANNOUNCED)
    monkeypatch.setattr(W, "cached", lambda kernel: False)

    def slow():
        time.sleep(0.35)
        return {k: 0.35 for k in C.KERNELS}

    monkeypatch.setattr(W, "warm", slow)
    assert W.main(every=0.1) == 0
    time.sleep(0.3)  # a beat after the end would show here
    lines = capsys.readouterr().out.splitlines()
    beats = [ln for ln in lines if "still compiling" in ln]
    assert 2 <= len(beats) <= 4 and lines[-1].startswith("simulators ready")


def test_the_install_compiles_every_entry_of_the_oscillators_kernel(monkeypatch):
    """`make install` (discovery.warm) leaves each compiled entry point of Ueda's kernel in
    the cache, the chart's scan and Floquet check too: a first chart after the install
    compiled those in its workers (4-8 s of each worker's time)."""
    import re
    from pathlib import Path

    monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)
    folder, _ = C.KERNELS["oscillator"]
    src = (Path(folder) / "_kernel.py").read_text()
    entries = re.findall(r"@njit\(cache=True\)\ndef (\w+)\(", src)
    assert {"scan_run", "monodromy_run", "strobe_run"} <= set(entries)
    cached = {p.name for p in C._cache_folder(folder).iterdir() if p.suffix == ".nbi"}
    missing = [e for e in entries if not any(n.startswith(f"_kernel.{e}-") for n in cached)]
    assert not missing, f"not compiled by discovery.warm: {missing}"


def test_the_kernel_borrows_its_arrays_where_numba_can(monkeypatch):
    """The kernel's non-allocating functions are compiled without reference counts
    (``_nrt=False``) with this numba; a numba without that private option gets no option,
    so the kernel still compiles (with the counts)."""
    import types

    from discovery._startup._compile import borrowing_options
    from discovery.vibroimpact.dynamics.kernel.contact import _contact_search
    from discovery.vibroimpact.dynamics.kernel.entries import work_arrays

    assert borrowing_options() == {"_nrt": False}
    assert _contact_search.targetoptions.get("_nrt") is False
    assert "_nrt" not in work_arrays.targetoptions  # it allocates: the counts stay
    without = types.SimpleNamespace(CPUTargetOptions=type("CPUTargetOptions", (), {}))
    monkeypatch.setitem(sys.modules, "numba.core.cpu", without)
    assert borrowing_options() == {}
