"""``vidi advise --until-settled``: the experiment loop, each next record made by a command.

``--acquire CMD`` is run (without a shell) once per record the loop asks for, with its
placeholders filled in: ``{amplitude}`` [N], ``{frequency}`` [Hz], ``{m2}`` [kg], ``{step}``
(the record's number), ``{scenario}`` (a TOML file: the sheet at that drive setting) and
``{out}`` (the CSV file the command must write).  A rig's script, or ``vidi simulate`` as a
stand-in for one.
"""

import os
import shlex
import shutil
import subprocess
from pathlib import Path

from .._files._io import OutputDir
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


def _program(words):
    """The ``--acquire`` program must exist before any work (it runs without a shell)."""
    prog = words[0]
    if "{" in prog:
        return
    found = (
        shutil.which(prog) if os.sep not in prog else (prog if os.access(prog, os.X_OK) else None)
    )
    if found is None:
        raise InputError(
            f"--acquire: no program {prog!r} on the PATH (the command runs without a shell); "
            "give its full path, e.g. --acquire '/usr/bin/python3 rig.py ... --out {out}'"
        )


def _step(path):
    return int(path.stem.rsplit("_", 1)[1])


def records_dir(args):
    """``(directory, [(sheet path, record path), ...])``: where the loop keeps each record as
    it arrives (``--records``, default ``OUT.records`` beside ``--out``) and the records an
    earlier loop left there, which only ``--resume`` takes."""
    d = Path(args.records) if args.records else Path(f"{Path(args.out)}.records")
    taken = sorted(d.glob("record_*.csv"), key=_step) if d.is_dir() else []
    if taken and not args.resume:
        raise InputError(
            f"{str(d)!r} holds {len(taken)} record(s) of an earlier loop: give --resume to go on "
            "from them, or --records with another directory"
        )
    if args.resume and not taken:
        raise InputError(f"--resume: {str(d)!r} holds no record_K.csv of an earlier loop")
    pairs = []
    for rec in taken:
        sheet = rec.with_name(f"scenario_{_step(rec)}.toml")
        if not sheet.is_file():
            raise InputError(f"--resume: {str(rec)!r} has no {sheet.name} beside it (its sheet)")
        pairs.append((sheet, rec))
    return d, pairs


class _Acquirer:
    """Runs ``--acquire`` for each record the loop asks for, keeping each in ``directory``."""

    def __init__(self, words, args, directory):
        self.words, self.args, self.directory = words, args, Path(directory)

    def __call__(self, request):
        k = request.step
        self.directory.mkdir(parents=True, exist_ok=True)  # made when the first record comes
        scenario = self.directory / f"scenario_{k}.toml"
        scenario.write_text(request.scenario.to_toml(), encoding="utf-8")
        out = self.directory / f"record_{k}.csv"
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
        kept = f"the records so far are in {str(self.directory)!r} (--resume goes on from them)"
        print(f"{where}: {shlex.join(argv)}", flush=True)
        try:  # the rig's own output goes to the terminal as it comes
            code = subprocess.run(argv, timeout=ACQUIRE_TIMEOUT, check=False).returncode
        except FileNotFoundError:
            raise InputError(f"--acquire: no program {argv[0]!r}; give its full path") from None
        except subprocess.TimeoutExpired:
            raise InputError(
                f"--acquire ran over {ACQUIRE_TIMEOUT:.0f} s for {where}; the loop stopped: {kept}"
            ) from None
        if code != 0:
            raise InputError(
                f"--acquire exited with {code} for {where} (its output is above); the loop "
                f"stopped: {kept}"
            )
        if not out.is_file():
            raise InputError(
                f"--acquire wrote no record for {where}: the command must write its CSV to "
                f"the file {{out}} names ({str(out)!r}); the loop stopped: {kept}"
            )
        try:
            meas = read_record(self.args, request.scenario, path=str(out))
        except InputError as exc:
            raise InputError(
                f"{where}, as --acquire wrote it: {exc} (the rig must drive at {{amplitude}} "
                f"and {{frequency}}); the loop stopped: {kept}"
            ) from None
        for note in meas.notes:
            print(f"note: {note}")
        return meas


def run_loop(args, sc, knobs, safe):
    """Run the loop from ``args.data`` on the sheet ``sc`` and write its directory."""
    from ..vibroimpact.advise import NoiseModel, campaign
    from ..vibroimpact.fit.discovery import DiscoverSettings
    from ..vibroimpact.model.scenario import load_scenario

    words = acquire_command(args.acquire)
    _program(words)
    directory, earlier = records_dir(args)
    first = read_record(args, sc)
    for note in first.notes:
        print(f"note: {note}")
    sheets, records = [sc], [first]
    for sheet, rec in earlier:
        sheets.append(load_scenario(str(sheet)))
        records.append(read_record(args, sheets[-1], path=str(rec)))
    if earlier:
        print(f"going on from {len(records)} records ({str(directory)!r})")
    noise = NoiseModel.from_measurement(first, sc, n_boot=args.n_boot, seed=args.seed or 0)
    fit = DiscoverSettings(library=args.library, seed=args.seed or 0, workers=args.workers)
    with reporter(args) as rep:
        res = campaign(
            sheets,
            records,
            _Acquirer(words, args, directory),
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
        for k in range(2, len(res.records) + 1):
            for name in (f"record_{k}.csv", f"scenario_{k}.toml"):
                shutil.copyfile(directory / name, out.path(name))
                files.append(name)
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
        help="the command that makes a record at a drive setting, run once per record "
        "(without a shell: its program on the PATH or given by its full path; its output "
        "shown as it comes) with {amplitude} [N], {frequency} [Hz], {m2} [kg], {step}, "
        "{scenario} (the sheet at the setting, a TOML file) and {out} (the CSV it must write: "
        't, F, w1, w2 and v1, v2 as for --data) filled in, e.g. "vidi simulate --scenario '
        "{scenario} --law '2e8*z + 1e7*zd' --noise 0.01 --seed {step} --out {out}\"",
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
    records = loop.add_argument(
        "--records",
        metavar="DIR",
        help="where the loop keeps each record as it arrives, with its sheet (default: "
        "OUT.records beside --out); they stay there whatever happens",
    )
    resume = loop.add_argument(
        "--resume",
        action="store_true",
        help="go on from the records an earlier loop left in --records (after a rig failed "
        "or the budget was reached)",
    )
    for action in (acquire, most, library, records, resume):
        action.needs = "--until-settled"
