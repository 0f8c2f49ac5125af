"""The ``lptv`` command line.

    lptv demo [--out DIR] [--monte-carlo R] [--quick]     the paper's simulation example
    lptv demo lecture [--out DIR] [--quick]               the lecture's cases
    lptv inspect FILE [--input NAME --output NAME]        a record's period, transient, excited lines
    lptv identify FILE --na 2 --nb 1 ...                  a model from your own measurements
    lptv identify FILES... [--workers N | --scheduler ADDRESS]   many files, one row each
    lptv identify FILES... --joint --na 2 --nb 1 ...       records of one system, one model
    lptv select FILE --na 1-3 --nb 0-2 [--k 0-4]          choose the orders and harmonic count
    lptv validate MODEL.json FILE                         a saved model against a fresh record
    lptv simulate MODEL.json FILE --input NAME            a saved model's output for a file's input
    lptv montecarlo --runs R --periods P --method wgtls,sml [--scheduler ADDRESS]
                                                          a Monte Carlo study of the estimators
"""
from __future__ import annotations

import argparse
import sys


_DEMO_HELP = """\
Runs a demonstration end to end and writes a report (report.html, its figures as PNG,
summary.json) into --out.
  paper    the paper's simulation example: an LPTV system (na = 2, nb = 1, 3 harmonics) under a
           24-line multisine, simulated by the FDS and by CVODE, measured over P noisy periods,
           identified by TLS, WGTLS and SML and validated (frozen poles, Floquet, residues)
  lecture  the lecture's cases: least squares, a spring-mass-damper, a time-varying stiffness k(t)
Every random number comes from --seed. The figures need matplotlib (pip install 'lptv[plots]')."""


def _demo_parser(sub):
    p = sub.add_parser("demo", help="reproduce the paper's simulation example (or the lecture's cases)",
                       description=_DEMO_HELP, formatter_class=argparse.RawDescriptionHelpFormatter,
                       epilog="examples:\n"
                              "  lptv demo                               the paper's example -> lptv-demo/\n"
                              "  lptv demo --monte-carlo 100 --out mc    with bias and RMS over 100 realisations\n"
                              "  lptv demo lecture --quick               the lecture's cases, small sizes")
    p.add_argument("case", nargs="?", default="paper", choices=["paper", "lecture"],
                   help="which demonstration (default: paper)")
    p.add_argument("--out", default=None, help="output folder (default: lptv-demo/ or lptv-lecture/)")
    p.add_argument("--monte-carlo", type=int, default=0, metavar="R",
                   help="repeat the identification over R noise realisations (bias and RMS of TLS, WGTLS)")
    p.add_argument("--periods", type=int, default=8, help="measured periods P (default 8)")
    p.add_argument("--seed", type=int, default=2024, help="seed of every random number (default 2024)")
    p.add_argument("--quick", action="store_true",
                   help="smaller Monte Carlo sizes for a fast check (same code path)")
    return p


PLOTS_EXTRA = "pip install 'lptv[plots]'"


def _plots_missing(command: str):
    """A one-line message when matplotlib (the 'plots' extra) cannot be imported, else None."""
    try:
        import matplotlib.figure  # noqa: F401
    except ImportError:
        return (f"lptv {command}: error: the report's figures need matplotlib, an optional extra: "
                f"{PLOTS_EXTRA}")
    return None


def _version() -> str:
    """The installed distribution's version (the package metadata, as pip reports it)."""
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("lptv")
    except PackageNotFoundError:
        return "(not installed: running from a source tree)"


class _ClosedPipeSafe:
    """A standard stream that survives its reader going away (``lptv inspect ... | head``): the
    first write or flush that meets a closed pipe sends the stream to /dev/null, so that the
    command finishes its work (its files on disk, its exit status) with no traceback, as it would
    with nobody reading its output."""

    def __init__(self, stream):
        self._stream = stream

    def _closed(self):
        import os

        try:
            devnull = os.open(os.devnull, os.O_WRONLY)
            os.dup2(devnull, self._stream.fileno())   # the buffer's flush at exit goes there too
            os.close(devnull)
        except (OSError, ValueError, AttributeError):
            pass

    def write(self, text):
        try:
            return self._stream.write(text)
        except BrokenPipeError:
            self._closed()
            return len(text)

    def flush(self):
        try:
            self._stream.flush()
        except BrokenPipeError:
            self._closed()

    def __getattr__(self, name):
        return getattr(self._stream, name)


def main(argv=None) -> int:
    """The ``lptv`` command; its exit status. Its output may go to a reader that stops early
    (``| head``): what is left is not printed, the rest of the work is done."""
    streams = sys.stdout, sys.stderr
    sys.stdout, sys.stderr = (_ClosedPipeSafe(s) if s is not None else s for s in streams)
    try:
        return _main(argv)
    finally:     # --help's SystemExit included: what is buffered meets the closed pipe here
        for s in (sys.stdout, sys.stderr):
            if isinstance(s, _ClosedPipeSafe):
                s.flush()
        sys.stdout, sys.stderr = streams


def _main(argv=None) -> int:
    from lptv.apps.options import Parser

    parser = Parser(
        prog="lptv", description="lptv: identification of linear periodically time-varying systems")
    parser.add_argument("--version", action="version", version=f"lptv {_version()}")
    sub = parser.add_subparsers(dest="command", required=True)
    _demo_parser(sub)
    from lptv.apps import fileid

    fileid.add_parser(sub)
    from lptv.apps import inspectrec

    inspectrec.add_parser(sub)
    from lptv.apps import montecarlo

    montecarlo.add_parser(sub)
    from lptv.apps import choose

    choose.add_parser(sub)
    from lptv.apps import simulatefile, validatefile

    validatefile.add_parser(sub)
    simulatefile.add_parser(sub)
    if not (sys.argv[1:] if argv is None else argv):
        parser.print_help()
        return 0
    args = parser.parse_args(argv)
    from lptv.apps.options import Interrupted, interruptible

    try:
        # SIGINT (Ctrl-C) or SIGTERM: one line and the status a shell gives a process killed by it
        # (130, 143); a batch or a study says itself what it keeps for --resume
        with interruptible():
            try:
                return _run(parser, args)
            except Interrupted as e:
                import signal

                kept = " (a fit's files are written together or not at all)" if args.command == "identify" else ""
                print(f"lptv {args.command}: interrupted by {signal.Signals(e.signum).name}: stopped before it "
                      f"finished{kept}", file=sys.stderr)
                return e.status
    except ModuleNotFoundError as e:
        # an optional extra that is not installed: one line naming it, not a traceback
        if (e.name or "").split(".")[0] != "matplotlib":
            raise
        print(_plots_missing(args.command) or f"lptv {args.command}: error: {e}", file=sys.stderr)
        return 2
    except (MemoryError, OverflowError) as e:
        # sizes the options allow but the machine cannot hold: one line, not a traceback
        what = "out of memory" if isinstance(e, MemoryError) else "a number too large"
        print(f"lptv {args.command}: error: {what}" + (f": {e}" if str(e) else "")
              + " (reduce the sizes given in the options)", file=sys.stderr)
        return 2


def _run(parser, args) -> int:
    if args.command == "demo":
        if args.monte_carlo < 0:
            parser.error("--monte-carlo must be >= 0")
        if args.periods < 2:
            parser.error("--periods must be >= 2")
        from lptv.apps.options import INT_MAX, output_folder

        for opt, v in (("--monte-carlo", args.monte_carlo), ("--periods", args.periods)):
            if v > INT_MAX:
                parser.error(f"{opt} must be at most {INT_MAX}, got {v}")
        if args.seed < 0:
            parser.error(f"--seed must be >= 0, got {args.seed}")
        msg = _plots_missing("demo")
        if msg:  # the demo's product is its report: say so before computing anything
            print(msg, file=sys.stderr)
            return 2
        try:
            output_folder(args.out)
        except OSError as e:
            parser.error(f"--out {e.filename or args.out}: {e.strerror or e}")
        if args.case == "lecture":
            from lptv.apps import lecture

            return lecture.run(args)
        from lptv.apps import demo

        return demo.run(args)
    from lptv.apps import choose, fileid, inspectrec, montecarlo

    if args.command == "identify":
        return fileid.run(args)
    if args.command == "inspect":
        return inspectrec.run(args)
    if args.command == "montecarlo":
        return montecarlo.run(args)
    if args.command == "select":
        return choose.run(args)
    if args.command in ("validate", "simulate"):
        from lptv.apps import simulatefile, validatefile

        return (validatefile if args.command == "validate" else simulatefile).run(args)
    parser.error(f"unknown command {args.command}")
    return 2


if __name__ == "__main__":
    sys.exit(main())
