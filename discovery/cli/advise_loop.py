"""``vidi advise --until-settled``: the experiment loop, each next record made by a command.

``--acquire CMD`` is run (without a shell) once per record the loop asks for, with its
placeholders filled in: ``{amplitude}`` [N], ``{frequency}`` [Hz], ``{m2}`` [kg], ``{step}``
(the record's number), ``{scenario}`` (a TOML file: the sheet at that drive setting) and
``{out}`` (the CSV file the command must write).  A rig's script, or ``vidi simulate`` as a
stand-in for one.
"""

import shlex
import shutil
import subprocess
import tempfile
from pathlib import Path

from .._io import OutputDir
from ..errors import InputError
from ._common import integer, outputs_line, provenance_of, read_record, reporter

#: the placeholders ``--acquire`` may use
PLACEHOLDERS = ("amplitude", "frequency", "m2", "step", "scenario", "out")
#: a record's command may run this long [s] before the loop stops with it
ACQUIRE_TIMEOUT = 3600.0


def acquire_command(template):
    """The words of ``--acquire``, checked: every ``{name}`` is a placeholder and ``{out}``
    is there (the command must write the record somewhere the loop reads it)."""
    try:
        words = shlex.split(template)
    except ValueError as exc:
        raise InputError(
            f"--acquire cannot be split into words ({exc}); check its quotes"
        ) from None
    if not words:
        raise InputError("--acquire is empty; give the command that writes a record to {out}")
    probe = {n: "x" for n in PLACEHOLDERS}
    for w in words:
        try:
            w.format(**probe)
        except KeyError as exc:
            raise InputError(
                f"--acquire names the placeholder {{{exc.args[0]}}}; the placeholders are "
                f"{', '.join('{' + n + '}' for n in PLACEHOLDERS)}"
            ) from None
        except (ValueError, IndexError) as exc:
            raise InputError(
                f"--acquire has a brace that is no placeholder ({exc}) in {w!r}; write a "
                "literal brace as {{ or }}"
            ) from None
    if not any("{out}" in w for w in words):
        raise InputError(
            "--acquire must write the record to {out}: put {out} where the command takes its "
            "output file, e.g. --acquire 'python rig.py --A {amplitude} --f {frequency} "
            "--out {out}'"
        )
    return words


class _Acquirer:
    """Runs ``--acquire`` for each record the loop asks for, in a work directory."""

    def __init__(self, words, args, workdir):
        self.words, self.args, self.workdir = words, args, Path(workdir)
        self.files = []

    def __call__(self, request):
        k = request.step
        scenario = self.workdir / f"scenario_{k}.toml"
        scenario.write_text(request.scenario.to_toml(), encoding="utf-8")
        out = self.workdir / f"record_{k}.csv"
        values = {
            "amplitude": f"{request.amplitude:.8g}",
            "frequency": f"{request.frequency:.8g}",
            "m2": f"{request.scenario.m2:.8g}",
            "step": str(k),
            "scenario": str(scenario),
            "out": str(out),
        }
        argv = [w.format(**values) for w in self.words]
        where = f"record {k} (A = {request.amplitude:.4g} N, f = {request.frequency:.4g} Hz)"
        print(f"{where}: {shlex.join(argv)}", flush=True)
        try:
            proc = subprocess.run(
                argv, capture_output=True, text=True, timeout=ACQUIRE_TIMEOUT, check=False
            )
        except FileNotFoundError:
            raise InputError(f"--acquire: no program {argv[0]!r}; give its full path") from None
        except subprocess.TimeoutExpired:
            raise InputError(
                f"--acquire ran over {ACQUIRE_TIMEOUT:.0f} s for {where}; the loop stopped"
            ) from None
        if proc.returncode != 0:
            tail = (proc.stderr or proc.stdout or "").strip().splitlines()
            raise InputError(
                f"--acquire exited with {proc.returncode} for {where}"
                + (f": {tail[-1]}" if tail else "")
                + "; the loop stopped, nothing was written to --out"
            )
        if not out.is_file():
            raise InputError(
                f"--acquire wrote no record for {where}: the command must write its CSV to "
                "the file {out} names"
            )
        self.files += [scenario, out]
        meas = read_record(self.args, request.scenario, path=str(out))
        for note in meas.notes:
            print(f"note: {note}")
        return meas


def run_loop(args, sc, knobs, safe):
    """Run the loop from ``args.data`` on the sheet ``sc`` and write its directory."""
    from ..vibroimpact.advise import NoiseModel, campaign
    from ..vibroimpact.fit.discovery import DiscoverSettings

    words = acquire_command(args.acquire)
    first = read_record(args, sc)
    for note in first.notes:
        print(f"note: {note}")
    noise = NoiseModel.from_measurement(first, sc, n_boot=args.n_boot, seed=args.seed or 0)
    fit = DiscoverSettings(library=args.library, seed=args.seed or 0, workers=args.workers or 1)
    with tempfile.TemporaryDirectory(prefix="vidi-loop-") as work:
        acquirer = _Acquirer(words, args, work)
        with reporter(args) as rep:
            res = campaign(
                sc,
                first,
                acquirer,
                knobs,
                max_records=args.max_records,
                machine=args.machine,
                fit=fit,
                safe=safe,
                noise=noise,
                refit_simulations=args.refit_simulations,
                workers=args.workers,
                seed=args.seed or 0,
                progress=rep,
            )
        res.record_run({"command": "advise", "mode": "until-settled"}, provenance_of(args))
        files = ["summary.json"]
        with OutputDir(args.out) as out:
            res.write_into(out)
            for f in acquirer.files:
                shutil.copyfile(f, out.path(f.name))
                files.append(f.name)
    print(res)
    print(outputs_line(args, files))
    return 0


def add_loop_options(parser):
    """The options of ``--until-settled`` (each refused without it)."""
    loop = parser.add_argument_group(
        "the experiment loop",
        "fit -> advise -> a record at the advised point -> the joint fit, until one law "
        "remains or no point in the bounds separates the rest",
    )
    loop.add_argument(
        "--until-settled",
        action="store_true",
        help="run the loop from the record --data, taking each next record with --acquire",
    )
    acquire = loop.add_argument(
        "--acquire",
        metavar="CMD",
        help="the command that makes a record at a drive setting, run once per record with "
        "{amplitude} [N], {frequency} [Hz], {m2} [kg], {step}, {scenario} (the sheet at the "
        'setting, a TOML file) and {out} (the CSV it must write) filled in, e.g. "vidi '
        "simulate --scenario {scenario} --law '2e8*z + 1e7*zd' --noise 0.01 --seed {step} "
        '--out {out}"',
    )
    most = loop.add_argument(
        "--max-records",
        type=integer(2, 20),
        default=4,
        help="records in all, the first included (default: %(default)s)",
    )
    library = loop.add_argument(
        "--library",
        default="poly:2",
        help="the loop's fits' candidate terms, as vidi fit's --library (default: %(default)s)",
    )
    for action in (acquire, most, library):
        action.needs = "--until-settled"
