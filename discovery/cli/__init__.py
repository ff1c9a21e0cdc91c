"""``vidi``: a thin command line over the :mod:`discovery` API.

One module per command of :data:`COMMANDS` (``ueda`` a package with one module per
subcommand), each with ``register(subparsers)`` and ``run(args)``.  Every command
writes ``summary.json`` (results, versions, settings) beside its other outputs;
outputs are staged and put in place as a whole only when the command succeeds
(:class:`discovery._files._io.OutputDir`).

Exit codes: 0 success; 2 bad input, failed numerics or an OS error such as a full disk
(one line on stderr, ``vidi: error: ...``, naming the problem and the fix; also for
option errors, which argparse would print as a usage block); 130 interrupted by Ctrl-C
(SIGINT), 143 terminated (SIGTERM), one line each, earlier results untouched; 1 an
internal error (one line, the traceback with ``VIDI_TRACEBACK=1``).

A value that starts with ``-`` (``--law -1e8*z``) is taken as the option's value when
it is not itself an option; ``--law=-1e8*z`` always works.
"""

import _thread
import argparse
import atexit
import contextlib
import os
import re
import signal
import sys
import threading
import traceback

from ..errors import VidiError

__all__ = ["main", "UsageError", "VidiArgumentParser"]


class UsageError(VidiError):
    """A command-line option is missing, unknown or has an invalid value."""


class Terminated(BaseException):  # noqa: N818  (like KeyboardInterrupt)
    """SIGTERM received: unwinds like Ctrl-C, so staging directories are removed."""


def _one_line(message, prog, command=None):
    """argparse's message rewritten as one line naming the option, the valid values and
    the fix."""
    command = prog.split()[-1] if prog and prog != "vidi" else command
    see = f"see vidi {command} --help" if command else "see vidi --help"
    m = re.match(
        r"argument (\S+?)(?:/\S+)?: invalid choice: '(.*)' \(choose from (.*)\)$", message, re.S
    )
    if m:
        opt, value, choices = m.groups()
        choices = choices.replace("'", "")
        if opt in ("COMMAND", "command", "SUBCOMMAND"):
            return _unknown_command(value, [c.strip() for c in choices.split(",")], see)
        hint = _did_you_mean(value, [c.strip() for c in choices.split(",")])
        return f"{opt}: invalid choice {value!r}{hint}; choose one of {choices}"
    m = re.match(r"argument (\S+?)(?:/\S+)?: invalid (\w+) value: '(.*)'$", message, re.S)
    if m:
        opt, kind, value = m.groups()
        what = {"int": "an integer", "float": "a number"}.get(kind, f"a valid {kind}")
        return f"{opt}: {value!r} is not {what}; give e.g. {opt} {'20' if kind == 'int' else '0.5'}"
    m = re.match(r"argument (\S+?)(?:/\S+)?: expected one argument$", message)
    if m:
        opt = m.group(1)
        example = "-1e8*z" if opt in ("--law", "--start", "--truth") else "-1e-3"
        return (
            f"{opt} needs a value; write {opt} VALUE, and a value that starts with '-' as "
            f"{opt}=-VALUE (e.g. {opt}={example})"
        )
    m = re.match(r"the following arguments are required: (.*)$", message)
    if m:
        names = m.group(1)
        if names in ("COMMAND", "command"):
            cmds = ", ".join(COMMANDS)
            return f"missing the command; choose one of {cmds} (see vidi --help)"
        return f"missing required option(s) {names}; {see}"
    m = re.match(r"unrecognized arguments: (.*)$", message)
    if m:
        return f"unrecognized option(s) or value(s) {m.group(1)}; {see}"
    m = re.match(r"argument (\S+?)(?:/\S+)?: (.*)$", message, re.S)
    if m:  # an ArgumentTypeError from a type function: its message names the fix
        return f"{m.group(1)}: {m.group(2)}"
    return f"{' '.join(message.split())}; {see}"


class VidiArgumentParser(argparse.ArgumentParser):
    """An ArgumentParser whose errors are one line (raised as :class:`UsageError`)."""

    command_hint = None  # the command named on the line (for the top-level parser)

    def error(self, message):
        raise UsageError(_one_line(message, self.prog, self.command_hint))

    def add_argument(self, *args, needs=None, excludes=None, **kwargs):
        """``needs``/``excludes``: the option acts only with / not with another option
        (checked by :func:`_refuse_orphans`)."""
        action = super().add_argument(*args, **kwargs)
        action.needs, action.excludes = needs, excludes
        return action


EXAMPLES = {
    "": [
        "vidi simulate --noise 0.01 --out D.csv     a record of the paper's machine",
        "vidi fit --data D.csv --out out/fit       discover its law, check it by simulation",
        "vidi report out/fit                       the LaTeX report, compiled to PDF",
        "vidi COMMAND --help                       each command's options and examples",
    ],
    "simulate": [
        "vidi simulate --scenario paper --periods 20 --noise 0.01 --out D.csv",
        "vidi simulate --law '2e8*z + 1e7*zd; unloading: 4e6*zd' --from-rest "
        "--integrator scipy --out R.csv",
    ],
    "fit": [
        "vidi fit --data D.csv --out out/fit",
        "vidi fit --scenario a.toml --scenario b.toml --data a.csv --data b.csv "
        "--library poly:3+hc --out out/fit2",
    ],
    "verify": ["vidi verify --data D.csv --law '2.06e8*z + 1.28e7*zd' --out out/verify"],
    "explain": [
        "vidi explain --data D.csv --out out/explain",
        "vidi explain --data D.csv --start '2e8*z + 1e7*zd' --effects "
        "unloading_damping,permanent_set --out out/explain2",
    ],
    "steady": ["vidi steady --scenario paper --law '2e8*z + 1e7*zd'"],
    "landscape": [
        "vidi landscape --grid 21x21 --out out/landscape",
        "vidi landscape --data D.csv --range0 1e8:3e8 --out out/landscape2",
    ],
    "identify": ["vidi identify --data D.csv --start '1.5e8*z + 0.9e7*zd' --out out/identify"],
    "advise": [
        "vidi advise --fit out/fit --data D.csv --amplitude 3e5:6e5 --frequency 20:30 "
        "--out out/advise",
        "vidi advise --law '2.06e8*z + 1.28e7*zd' --law '2.06e8*z + 9e6*zd + 1e9*z*zd' "
        "--noise 0.01 --amplitude 3e5:6e5 --frequency 20:30 --max-force 2e7 --out out/advise2",
        "vidi advise --until-settled --data D.csv --amplitude 3e5:6e5 --frequency 20:30 "
        "--acquire 'python rig.py --A {amplitude} --f {frequency} --out {out}' --out out/loop",
    ],
    "study": [
        "vidi study --config examples/study_paper.toml --out out/study",
        "vidi study --config examples/study_paper.toml --out out/study --scheduler local",
        "vidi study --config S.toml --out out/s --max-runs 20   a slice; rerun to go on",
    ],
    "report": [
        "vidi report out/fit                 report.tex and report.pdf in out/fit",
        "vidi report out/verify --snippet criteria",
        "vidi report out/fit --no-pdf        the LaTeX source only",
    ],
    "ueda attractor": ["vidi ueda attractor --model negres --out out/attractor"],
    "ueda chart": ["vidi ueda chart --model negres --nu 0.8:1.2:21 --B 0.2:1.2:21 --out out/chart"],
    "ueda simulate": ["vidi ueda simulate --model negres --noise 0.002 --out U.csv"],
    "ueda discover": ["vidi ueda discover --data U.csv --model negres --out out/ueda"],
    "ueda explain": ["vidi ueda explain --data U.csv --model negres --out out/ueda-explain"],
}


class HelpFormatter(argparse.HelpFormatter):
    """argparse's formatter, but an epilog of examples is printed as written."""

    def _fill_text(self, text, width, indent):
        if text.startswith("examples:"):
            return "".join(indent + line for line in text.splitlines(keepends=True))
        return super()._fill_text(text, width, indent)


def _add_examples(parser, path=()):
    """Every (sub)command's help ends with its examples (``EXAMPLES``)."""
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sp in action.choices.items():
                _add_examples(sp, (*path, name))
    parser.formatter_class = HelpFormatter
    lines = EXAMPLES.get(" ".join(path))
    if lines:
        parser.epilog = (
            "examples:\n"
            + "\n".join(f"  {ln}" for ln in lines)
            + (
                ""
                if path
                else "\n\nexit codes: 0 ok, 2 bad input or failed numerics, 130 "
                "interrupted (Ctrl-C),\n            143 terminated, 1 internal error"
            )
        )


COMMANDS = (
    "simulate",
    "calibrate",
    "fit",
    "verify",
    "explain",
    "steady",
    "landscape",
    "identify",
    "advise",
    "study",
    "report",
    "ueda",
)


def _parser():
    p = VidiArgumentParser(
        prog="vidi",
        description="Discover and verify contact-force laws F(zeta, dzeta) of vibro-impact "
        "machines by simulation.",
    )
    p.add_argument(
        "--version",
        action="version",
        version=f"vidi {_version()}",
        help="print the version and exit",
    )
    sub = p.add_subparsers(
        dest="command", required=True, metavar="COMMAND", parser_class=VidiArgumentParser
    )
    # imported here, inside main()'s handlers: a Ctrl-C while they load is an interrupt too
    from . import (
        advise,
        calibrate,
        explain,
        fit,
        identify,
        landscape,
        report,
        simulate,
        steady,
        study,
        ueda,
        verify,
    )

    modules = {
        "simulate": simulate,
        "calibrate": calibrate,
        "fit": fit,
        "verify": verify,
        "explain": explain,
        "steady": steady,
        "landscape": landscape,
        "identify": identify,
        "advise": advise,
        "study": study,
        "report": report,
        "ueda": ueda,
    }
    for name in COMMANDS:
        modules[name].register(sub)
    _add_overwrite(p)
    _add_quiet(p)
    _add_examples(p)
    return p


LONG = (
    "fit",
    "identify",
    "landscape",
    "explain",
    "advise",
    "study",
    "ueda chart",
)  # they report progress


def _add_quiet(parser, path=()):
    """``--quiet`` on every command that reports progress (``LONG``)."""
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sp in action.choices.items():
                _add_quiet(sp, (*path, name))
    if " ".join(path) in LONG:
        parser.add_argument(
            "--quiet",
            action="store_true",
            help="no progress on stderr (by default a bar with an ETA on a "
            "terminal, one line per stage otherwise)",
        )


def _add_overwrite(parser):
    """``--overwrite`` on every (sub)command that writes ``--out``: replace the results of
    another command (or an ``--out`` file vidi did not write); files the user added to a
    result directory are kept, and a directory holding no vidi result is never replaced."""
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for sp in action.choices.values():
                _add_overwrite(sp)
    if (
        "--out" in parser._option_string_actions
        and "--overwrite" not in parser._option_string_actions
    ):
        parser.add_argument(
            "--overwrite",
            action="store_true",
            help="replace the results of another vidi command in --out, or an --out "
            "file vidi did not write; files you added to a result directory are kept, and "
            "a directory holding no vidi result is never replaced",
        )


def _version():
    from importlib import metadata

    try:
        return metadata.version("vibroimpact-discovery")
    except metadata.PackageNotFoundError:
        return "unknown (not installed)"


def _attach_dash_values(parser, argv):
    """``--law -1e8*z`` -> ``--law=-1e8*z``: a token starting with a single '-' after an
    option that takes one value is that option's value unless it is an option itself."""
    sub = next((a for a in parser._actions if isinstance(a, argparse._SubParsersAction)), None)
    command = next((t for t in argv if not t.startswith("-")), None)
    if sub is None or command not in sub.choices:
        return argv
    parser.command_hint = command
    sp = sub.choices[command]
    rest = argv[argv.index(command) + 1 :]
    while True:  # down to the innermost subcommand named (`ueda attractor`)
        inner = next((a for a in sp._actions if isinstance(a, argparse._SubParsersAction)), None)
        name = next((t for t in rest if not t.startswith("-")), None)
        if inner is None or name not in inner.choices:
            break
        sp = inner.choices[name]
        rest = rest[rest.index(name) + 1 :]
    takes_value = {
        s
        for a in sp._actions
        if a.nargs is None and a.option_strings and not isinstance(a, argparse._StoreConstAction)
        for s in a.option_strings
    }
    known = set(sp._option_string_actions)
    out, i = [], 0
    while i < len(argv):
        tok = argv[i]
        if tok == "--":
            out.extend(argv[i:])
            break
        nxt = argv[i + 1] if i + 1 < len(argv) else None
        if (
            tok in takes_value
            and nxt is not None
            and nxt.startswith("-")
            and not nxt.startswith("--")
            and nxt not in known
            and len(nxt) > 1
        ):
            out.append(f"{tok}={nxt}")
            i += 2
            continue
        out.append(tok)
        i += 1
    return out


def _options_on_line(parser, argv):
    """The (sub)command's parser named on the line, and ``(option, action)`` of every long
    option given on it (up to ``--``)."""
    sp, rest = parser, list(argv)
    while True:  # descend into the (sub)command named on the line
        sub = next((a for a in sp._actions if isinstance(a, argparse._SubParsersAction)), None)
        name = next((t for t in rest if not t.startswith("-")), None)
        if sub is None or name not in sub.choices:
            break
        sp, rest = sub.choices[name], rest[rest.index(name) + 1 :]
    found = []
    for tok in rest:
        if tok == "--":
            break
        if tok.startswith("--"):
            opt = tok.split("=", 1)[0]
            action = sp._option_string_actions.get(opt)
            if action is not None:
                found.append((opt, action))
    return sp, found


def _did_you_mean(word, choices):
    """`` (did you mean 'x'?)`` for the closest of ``choices``, or nothing."""
    import difflib

    close = difflib.get_close_matches(word, list(choices), n=1, cutoff=0.6)
    return f" (did you mean {close[0]!r}?)" if close else ""


def _unknown_command(value, choices, see):
    """The one line for a (sub)command that does not exist, with the closest one."""
    hint = _did_you_mean(value, choices)
    return f"unknown command {value!r}{hint}; choose one of {', '.join(choices)} ({see})"


def _refuse_unknown(parser, argv):
    """A (sub)command that does not exist is named first, whatever options follow it;
    then a long option the (sub)command does not have is named, with the closest one it
    has (argparse would first complain of a missing required option, or name it without
    a hint); an unambiguous prefix of an option is accepted, as argparse does."""
    sp, rest = parser, list(argv)
    while True:
        sub = next((a for a in sp._actions if isinstance(a, argparse._SubParsersAction)), None)
        name = next((t for t in rest if not t.startswith("-")), None)
        if sub is not None and name is not None and name not in sub.choices:
            command = sp.prog.removeprefix("vidi").strip()
            see = f"see vidi {command} --help" if command else "see vidi --help"
            raise UsageError(_unknown_command(name, list(sub.choices), see))
        if sub is None or name not in sub.choices:
            break
        sp, rest = sub.choices[name], rest[rest.index(name) + 1 :]
    options = [o for o in sp._option_string_actions if o.startswith("--")]
    for tok in rest:
        if tok == "--":
            break
        opt = tok.split("=", 1)[0]
        if not opt.startswith("--") or opt in sp._option_string_actions:
            continue
        if len({sp._option_string_actions[o].dest for o in options if o.startswith(opt)}) == 1:
            continue  # an abbreviation argparse takes
        command = sp.prog.removeprefix("vidi").strip()
        see = f"vidi {command} --help" if command else "vidi --help"
        # compared without the dashes every option shares
        hint = _did_you_mean(opt[2:], [o[2:] for o in options]).replace(" '", " '--", 1)
        raise UsageError(f"unknown option {opt!r}{hint}; see {see}")


def _refuse_repeats(parser, argv):
    """A value option given twice (``--law A --law B``) is refused: argparse would keep the
    last one silently.  Options that collect values (``--data`` of ``fit``) may repeat."""
    seen = set()
    for opt, action in _options_on_line(parser, argv)[1]:
        if action.nargs is not None or isinstance(
            action, argparse._AppendAction | argparse._StoreConstAction
        ):
            continue
        if action.dest in seen:
            raise UsageError(f"{opt} is given twice; give it once (the last would silently win)")
        seen.add(action.dest)


def _refuse_orphans(parser, argv):
    """An option that only acts with another one (``needs``) or not with another one
    (``excludes``) is refused when given alone: it would be silently ignored."""
    sp, found = _options_on_line(parser, argv)
    given = {action.option_strings[-1] for _, action in found}
    for action in sp._actions:
        opt = action.option_strings[-1] if action.option_strings else None
        if opt not in given:
            continue
        need = getattr(action, "needs", None)
        if need and need not in given:
            raise UsageError(
                f"{opt} acts only with {need}, which is not given; add {need} or leave out {opt}"
            )
        excl = getattr(action, "excludes", None)
        if excl and excl in given:
            raise UsageError(f"{opt} has no effect with {excl}; leave out one of them")


def _error(message):
    text = " ".join(str(message).split())
    if len(text) > 1200:  # a message echoing a very long path or value: its ends only
        text = f"{text[:597]} ... {text[-597:]}"
    print(f"vidi: error: {text}", file=sys.stderr)


_OUT_OF_MEMORY = (
    b"vidi: error: not enough memory for this run; reduce its size (--fs, --periods, "
    b"--grid) and try again\n"
)


def _interruption(exc):
    """The Ctrl-C or SIGTERM behind ``exc``: compiled code and solvers re-raise an interrupt
    as another error (numba's ``SystemError``), with the interrupt as its cause."""
    seen = set()
    while exc is not None and id(exc) not in seen:
        if isinstance(exc, KeyboardInterrupt | Terminated):
            return exc
        seen.add(id(exc))
        exc = exc.__cause__ or exc.__context__
    return None


def _stopped(exc, outer=None):
    """The one line of an interrupted run: what was kept (a study's finished runs, named by
    the note it attaches to the interrupt) or that the partial outputs were removed."""
    note = getattr(outer, "vidi_note", None) or getattr(exc, "vidi_note", None)
    what = note or "partial outputs were removed, earlier results are unchanged"
    hook = sys.unraisablehook
    if isinstance(hook, _Unraisable):  # what the interrupt left half built is freed quietly
        hook.stopped = True
    if isinstance(exc, Terminated):
        _error(f"terminated (SIGTERM); {what}")
        return 143
    _error(f"interrupted (Ctrl-C); {what}")
    return 130


class _Unraisable:
    """The unraisable-exception hook of a run: gives an interrupt back to the main thread,
    and is quiet once the run has been stopped.

    A signal that arrives while Python runs a callback it cannot propagate from (an
    import lock's weakref callback, during the imports) would be printed as "Exception
    ignored" with a traceback and then lost: the run would go on.  The hook delivers the
    signal to the main thread again, from a timer thread so that it lands once the hook
    has returned (raised inside the hook it would be lost the same way).

    Once the run has stopped on an interrupt (``stopped``), the objects the interrupt left
    half built are freed with the run's frames; their clean-up can fail (llvmlite's
    ``ObjectRef.__del__`` on a compilation cut short, "no attribute '_as_parameter_'").
    The run has said what happened in its one line, so those are dropped.  Anything else
    goes to the previous hook."""

    def __init__(self, hook):
        self.hook = hook
        self.stopped = False

    def __call__(self, u):
        stop = u.exc_value
        if isinstance(stop, KeyboardInterrupt | Terminated):
            if not self.stopped:
                sig = signal.SIGINT if isinstance(stop, KeyboardInterrupt) else signal.SIGTERM
                again = threading.Timer(0.01, _thread.interrupt_main, (sig,))
                again.daemon = True
                again.start()
            return
        if not self.stopped:
            self.hook(u)


def _leave(code):
    """End the process after an interrupt without the C library's exit handlers.

    An interrupt during the imports can leave a compiled extension half initialised
    (matplotlib's font module was seen to), whose static destructors then run after the
    interpreter is gone and abort the process.  The run's own clean-up (staging removed,
    the one line printed) is done by now, so the streams are flushed and the process
    leaves with its code."""
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(Exception):
            stream.flush()
    os._exit(code)


def main(argv=None):
    """Run ``vidi``; returns the exit code (0 ok, 2 bad input or failed numerics, 130
    interrupted, 143 terminated, 1 internal error).  As the process's entry point
    (``argv`` None), an interrupted run ends the process at once with its code."""
    entry = argv is None
    argv = list(sys.argv[1:] if argv is None else argv)
    old_term = None
    old_hook = sys.unraisablehook
    in_main_thread = threading.current_thread() is threading.main_thread()
    if in_main_thread:

        def _terminate(signum, frame):
            raise Terminated()

        try:
            old_term = signal.signal(signal.SIGTERM, _terminate)
        except (ValueError, OSError):
            old_term = None
        sys.unraisablehook = _Unraisable(old_hook)
    try:
        code = _run(argv)
    except MemoryError:  # handled out here, once the frames holding the memory are gone
        code = None
    finally:
        if entry and in_main_thread:  # the run is over: a late signal must not change its exit
            with contextlib.suppress(ValueError, OSError):
                signal.signal(signal.SIGINT, signal.SIG_IGN)
                signal.signal(signal.SIGTERM, signal.SIG_IGN)
        elif old_term is not None:
            signal.signal(signal.SIGTERM, old_term)
        if not entry:  # as the entry point, the hook stays to the end (an interrupted run's)
            sys.unraisablehook = old_hook
    if code is None:
        with contextlib.suppress(OSError):
            os.write(2, _OUT_OF_MEMORY)
        return 2
    if entry and code in (130, 143):
        _leave(code)
    if entry:
        _finish(code)
    return code


def _finish(code):
    """End the process that ran ``vidi`` without the interpreter's teardown.

    Tearing the interpreter down takes longer than many commands' own work: freeing
    numba's loaded kernels took 0.37 s and matplotlib's modules 0.19 s (of ``vidi verify``'s
    2.7 s on a 30-period record).  When the run is over, its files are closed (every
    output is written in ``with`` blocks), so the exit handlers (``atexit``: logging's,
    multiprocessing's) are run, the streams flushed, and the process leaves with its code.
    It ends as usual where a thread the interpreter would wait for still runs, or where a
    profiler, tracer or debugger watches the run (``python -m cProfile -o`` writes its file
    after the script returns)."""
    main_thread = threading.main_thread()
    if any(t is not main_thread and not t.daemon for t in threading.enumerate()):
        return
    if sys.getprofile() is not None or sys.gettrace() is not None:
        return
    atexit._run_exitfuncs()
    _leave(code)


def _run(argv):
    try:
        from .._files._io import set_run, short

        parser = _parser()
        if not argv:  # plain `vidi`: the overview, not an error
            parser.print_help()
            return 0
        try:
            line = _attach_dash_values(parser, argv)
            _refuse_unknown(parser, line)
            _refuse_repeats(parser, line)
            args = parser.parse_args(line)
            _refuse_orphans(parser, line)
        except SystemExit as exc:  # --help, --version
            return exc.code if isinstance(exc.code, int) else 0
        command = " ".join(
            x for x in (getattr(args, "command", None), getattr(args, "ueda_command", None)) if x
        )
        set_run(command or None, getattr(args, "overwrite", False))
        from ..numerics import counts

        counts.reset()  # a run's summary counts its own work
        return args.func(args)
    except (KeyboardInterrupt, Terminated) as exc:
        return _stopped(exc)
    except MemoryError:
        raise
    except BrokenPipeError:  # output piped into e.g. `head`: stop quietly
        with contextlib.suppress(OSError, ValueError):
            sys.stderr.close()
        return 0
    except Exception as exc:
        stop = _interruption(exc)  # an interrupt re-raised by compiled code or a solver
        if stop is not None:
            return _stopped(stop, exc)
        if isinstance(exc, VidiError):  # bad input or failed numerics, by type
            _error(exc)
            return 2
        if isinstance(exc, OSError):  # the environment: disk full, permissions, a vanished file
            where = f" ({short(exc.filename)})" if exc.filename else ""
            _error(
                f"{exc.strerror or exc}{where}; check the path, its permissions and the free space"
            )
            return 2
        if os.environ.get("VIDI_TRACEBACK"):  # a bug: one line, the traceback on request
            traceback.print_exc()
        _error(
            f"internal error {type(exc).__name__}: {exc}; please report it (set "
            "VIDI_TRACEBACK=1 for the traceback)"
        )
        return 1


if __name__ == "__main__":
    sys.exit(main())
