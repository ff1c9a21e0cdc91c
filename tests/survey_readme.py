"""The README's numbers, measured as a user meets them: a fresh clone's set-up, the demo's
results and each command's time (one run file, ``docs/_measured/readme.jsonl``).

Not a test module.  From a clone of this checkout's HEAD in a temporary folder:

1. ``--install``: ``make install`` as on a fresh machine (a new venv, pip without its
   download cache, the simulators compiled once); else the clone borrows this checkout's
   venv and the compile is timed alone, with an empty numba cache;
2. ``make demo``, every ``vidi`` command it runs timed on its own (a ``vidi`` on ``BIN``
   that times the real one), then the numbers its outputs hold (each verdict, the named
   effect, the final law and its intervals against the demo's truth);
3. the README's quickstart blocks, each command timed, in an empty folder, and the Ueda
   chart of the README's sentence;
4. ``--test``: ``make test`` in the clone (less the two test modules that read this run).

The README's set-up line, its demo paragraph and its expected times are rendered from this
file (``tests/tables.py``: ``setup``, ``demo``, ``times``), so they say what this code did,
and the demo's figures are copied into ``reports/assets`` from the same run (their hashes in
the run file).

    python -m tests.survey_readme --install --test     # about 20 min on two cores
"""

import argparse
import hashlib
import json
import os
import re
import resource
import shlex
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from . import measured

ROOT = measured.ROOT
OUT = measured.MEASURED / "readme.jsonl"
#: the regime chart the README times (its sentence is rendered with this command)
CHART = "vidi ueda chart --nu 0.8:1.2:200 --B 0:0.6:200 --out out/chart"
#: the demo's figures the README and the gallery show: ``{output: reports/assets name}``
DEMO_FIGURES = {
    "explain/explain_1.png": "demo_explain.png",
    "verify/verify.png": "demo_verify.png",
    "fit/fit_impulse.png": "demo_fit_impulse.png",
    "fit/fit_surface.png": "demo_fit_surface.png",
}
ASSETS = ROOT / "reports" / "assets"
#: the README's bash blocks, in the order a user runs them
BLOCKS = ("quickstart", "quickstart-explain", "quickstart-ueda")

#: the machine's load (1-minute average) after each timed command of this run
_LOADS = []

_SHIM = """#!{python}
import json, os, resource, subprocess, sys, time
t0 = time.perf_counter()
rc = subprocess.call([{vidi!r}, *sys.argv[1:]])
cpu = resource.getrusage(resource.RUSAGE_CHILDREN)
with open({log!r}, "a") as fh:
    fh.write(json.dumps({{"argv": sys.argv[1:], "seconds": time.perf_counter() - t0,
                         "cpu": cpu.ru_utime + cpu.ru_stime, "rc": rc}}) + "\\n")
sys.exit(rc)
"""


def block(name, text=None):
    """The command lines of the README's bash block ``<!-- NAME -->``."""
    text = text if text is not None else (ROOT / "README.md").read_text()
    found = re.search(rf"<!-- {name} -->\s*```bash\n(.*?)```\s*<!-- /{name} -->", text, re.S)
    if found is None:
        raise SystemExit(f"README.md has no <!-- {name} --> bash block")
    return [ln.strip() for ln in found.group(1).splitlines() if ln.strip()]


def _timed(argv, cwd, env, timeout=3600):
    """Run ``argv``: ``(seconds, cpu seconds of its processes, completed process)``."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    run = subprocess.run(argv, cwd=cwd, env=env, capture_output=True, text=True, timeout=timeout)
    seconds = time.perf_counter() - t0
    _LOADS.append(os.getloadavg()[0])
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    if run.returncode:
        tail = (run.stdout + run.stderr)[-3000:]
        raise SystemExit(f"{' '.join(argv)} failed (exit {run.returncode}):\n{tail}")
    return seconds, cpu, run


def _clone(work):
    """A clone of HEAD at ``work/main``, ``work/shared`` the corpus beside it."""
    clone = work / "main"
    subprocess.run(["git", "clone", "-q", str(ROOT), str(clone)], check=True)
    shared = ROOT.parent / "shared"
    if shared.exists():
        (work / "shared").symlink_to(shared)
    return clone


def _install(clone, env, log):
    """``make install`` in the clone (pip's cache off): its row, with the compile's seconds
    as the simulators' warm-up printed them."""
    env = {**env, "PIP_NO_CACHE_DIR": "1"}
    seconds, cpu, run = _timed(["make", "install"], clone, env)
    compiled = _compiled(run)
    log(f"make install {seconds:.0f} s (compile {compiled})")
    return {"kind": "install", "seconds": seconds, "cpu": cpu, "compile": compiled, "fresh": True}


def _compiled(run):
    """``{kernel: seconds}`` from the warm-up's "simulators ready (...)" line in ``run``'s
    output (empty when it did not print one)."""
    for line in (run.stdout + run.stderr).splitlines():
        if line.startswith("simulators ready"):
            return {k: float(v) for k, v in re.findall(r"([\w-]+) ([\d.]+) s", line)}
    return {}


def _borrow_venv(clone, env, log):
    """The clone on this checkout's venv; the compile timed alone with an empty cache."""
    (clone / ".venv").symlink_to(ROOT / ".venv")
    with tempfile.TemporaryDirectory() as cache:
        seconds, cpu, run = _timed(
            [str(ROOT / ".venv/bin/python"), "-m", "discovery.warm"],
            clone,
            {**env, "NUMBA_CACHE_DIR": cache},
        )
    compiled = _compiled(run)
    log(f"compile {seconds:.0f} s {compiled}")
    return {"kind": "install", "seconds": None, "cpu": cpu, "compile": compiled, "fresh": False}


def _shim(work, clone):
    """A folder whose ``vidi`` times the clone's one command by command (its log beside)."""
    folder = work / "timed-bin"
    folder.mkdir()
    log = work / "vidi-times.jsonl"
    shim = folder / "vidi"
    shim.write_text(
        _SHIM.format(python=sys.executable, vidi=str(clone / ".venv/bin/vidi"), log=str(log))
    )
    shim.chmod(0o755)
    return folder, log


def _demo(work, clone, env, fresh, log):
    """``make demo`` in the clone: its total, each command's row, and the demo's numbers."""
    folder, times = _shim(work, clone)
    argv = ["make", "demo", f"BIN={folder}"]
    if not fresh:  # the borrowed venv is not the clone's to reinstall
        argv[1:1] = ["-o", ".venv/.installed"]
    seconds, cpu, _ = _timed(argv, clone, env)
    log(f"make demo {seconds:.0f} s")
    rows = [{"kind": "demo-total", "seconds": seconds, "cpu": cpu}]
    for line in times.read_text().splitlines():
        entry = json.loads(line)
        rows.append(
            {
                "kind": "command",
                "block": "demo",
                "command": shlex.join(["vidi", *entry["argv"]]),
                "seconds": entry["seconds"],
                "cpu": entry["cpu"],
            }
        )
    numbers = demo_numbers(clone / "out" / "demo", _demo_truth(clone))
    rows.append({"kind": "demo", **numbers, "figures": _copy_figures(clone / "out" / "demo")})
    return rows


def _copy_figures(out):
    """The demo's figures copied into reports/assets (the README's figure is the run's):
    ``{asset: sha256}``."""
    digests = {}
    for source, name in DEMO_FIGURES.items():
        shutil.copyfile(out / source, ASSETS / name)
        digests[name] = hashlib.sha256((ASSETS / name).read_bytes()).hexdigest()
    return digests


def _demo_truth(clone):
    """The demo's true law, as its Makefile writes it."""
    text = (clone / "Makefile").read_text()
    law = re.search(r"^DEMO_LAW := (.+)$", text, re.M).group(1).strip()
    true = re.search(r"^DEMO_TRUE := (.+)$", text, re.M).group(1).strip()
    return {"start": law, "true": true.replace("$(DEMO_LAW)", law)}


def demo_numbers(out, truth):
    """What the README says of the demo, read from its outputs in ``out``."""
    from discovery.vibroimpact.model.law import ForceLaw

    verify = json.loads((out / "verify" / "summary.json").read_text())
    fit = json.loads((out / "fit" / "summary.json").read_text())
    explain = json.loads((out / "explain" / "summary.json").read_text())
    first = explain["iterations"][0] if explain["iterations"] else None
    true = ForceLaw.parse(truth["true"])
    truths = {str(t): c for t, c in zip(true.terms, true.coefficients, strict=True)}
    truths.update(
        {f"d_{t}": c for t, c in zip(true.unloading, true.unloading_coefficients, strict=True)}
    )
    best = fit["ranking"][0]
    return {
        "truth": truth,
        "verify": {
            "law": verify["law"],
            "consistent": verify["consistent"],
            "criteria": {k: verify["criteria"][k] for k in ("I2", "I4")},
            "limits": {k: verify["limits"][k] for k in ("I2", "I4")},
        },
        "fit": {
            "library": fit["fit_settings"]["library"],
            "records": len(fit["data"]),
            "terms": best["terms"],
            "consistent": any(r["consistent"] for r in fit["ranking"]),
            "I2": best["criteria"]["I2"],
            "limits_I2": [r["limits"]["I2"] for r in best["records"]],
        },
        "explain": {
            "named": [it["effect"] for it in explain["iterations"]],
            "before": first and first["criteria_before"]["I2"],
            "after": first and first["criteria_after"]["I2"],
            "floor": first and first["noise_floor"]["I2"],
            "others": first
            and min(
                s["criteria_after"]["I2"]
                for s in first["scores"]
                if s["effect"] != first["effect"] and s.get("criteria_after")
            ),
            "final": explain["final_model"]["text"],
            "consistent": explain["consistent"],
            "intervals": explain["final_model"]["intervals"]["bounds"],
            "truths": truths,
            "replicates": explain["final_model"]["intervals"]["n_boot"],
        },
    }


def _blocks(work, clone, env, log):
    """Each quickstart command and the chart, timed in an empty folder."""
    here = work / "user"
    here.mkdir()
    env = {**env, "PATH": f"{clone / '.venv/bin'}{os.pathsep}{env['PATH']}"}
    rows = []
    for name in (*BLOCKS, "chart"):
        for line in [CHART] if name == "chart" else block(name):
            seconds, cpu, _ = _timed(shlex.split(line), here, env)
            log(f"{seconds:6.1f} s  {line}")
            rows.append(
                {"kind": "command", "block": name, "command": line, "seconds": seconds, "cpu": cpu}
            )
    return rows


#: the tests that read this survey's own run file: they cannot pass before it is saved
READS_THE_RUN = ("tests/test_readme_numbers.py", "tests/test_tables.py")


def _make_test(clone, env, log):
    """``make test`` in the clone, less :data:`READS_THE_RUN`."""
    ignore = " ".join(f"--ignore={path}" for path in READS_THE_RUN)
    env = {**env, "PYTEST_ADDOPTS": f"{env.get('PYTEST_ADDOPTS', '')} {ignore}".strip()}
    seconds, cpu, run = _timed(["make", "test"], clone, env, timeout=7200)
    summary = re.findall(r"(\d+) (passed|failed|skipped|xfailed|xpassed)", run.stdout)
    log(f"make test {seconds:.0f} s")
    return {
        "kind": "test",
        "seconds": seconds,
        "cpu": cpu,
        "outcome": dict((b, int(a)) for a, b in summary),
    }


def machine():
    """The machine a run was made on: its cores and its load when the run started."""
    return {"cores": os.cpu_count(), "load": os.getloadavg()[0]}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--install", action="store_true", help="time make install in the clone")
    ap.add_argument("--test", action="store_true", help="time make test in the clone")
    ap.add_argument("--out", type=Path, default=OUT, help="the run file (default: %(default)s)")
    args = ap.parse_args(argv)
    env = {k: v for k, v in os.environ.items() if k not in ("VIRTUAL_ENV", "PYTHONPATH")}
    out = measured.RunFile(args.out, "survey_readme", argv, machine=machine())

    def log(text):
        print(text, flush=True)

    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        clone = _clone(work)
        setup = _install if args.install else _borrow_venv
        out.write(setup(clone, env, log))
        for row in _demo(work, clone, env, args.install, log):
            out.write(row)
        for row in _blocks(work, clone, env, log):
            out.write(row)
        if args.test:
            out.write(_make_test(clone, env, log))
        out.write({"kind": "load", "low": min(_LOADS), "high": max(_LOADS)})
    shutil.rmtree(work, ignore_errors=True)
    print(f"saved {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
