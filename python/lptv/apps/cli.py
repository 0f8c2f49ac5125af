"""The ``lptv`` command line.

    lptv demo [--out DIR] [--monte-carlo R] [--quick]     the paper's simulation example
    lptv demo lecture [--out DIR] [--quick]               the lecture's cases
    lptv identify FILE --na 2 --nb 1 ...                  a model from your own measurements
    lptv identify FILES... [--workers N | --scheduler ADDRESS]   many files, one row each
    lptv select FILE --na 1-3 --nb 0-2 [--k 0-4]          choose the orders and harmonic count
    lptv montecarlo --runs R --periods P --method wgtls,sml [--scheduler ADDRESS]
                                                          a Monte Carlo study of the estimators
"""
from __future__ import annotations

import argparse
import sys


def _demo_parser(sub):
    p = sub.add_parser("demo", help="reproduce the paper's simulation example (or the lecture's cases)",
                       description="Runs the paper's simulation example end to end and writes a report.")
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


def _version() -> str:
    """The installed distribution's version (the package metadata, as pip reports it)."""
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("lptv")
    except PackageNotFoundError:
        return "(not installed: running from a source tree)"


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(
        prog="lptv", description="lptv: identification of linear periodically time-varying systems")
    parser.add_argument("--version", action="version", version=f"lptv {_version()}")
    sub = parser.add_subparsers(dest="command", required=True)
    _demo_parser(sub)
    from lptv.apps import fileid

    fileid.add_parser(sub)
    from lptv.apps import montecarlo

    montecarlo.add_parser(sub)
    from lptv.apps import choose

    choose.add_parser(sub)
    if not (sys.argv[1:] if argv is None else argv):
        parser.print_help()
        return 0
    args = parser.parse_args(argv)
    if args.command == "demo":
        if args.monte_carlo < 0:
            parser.error("--monte-carlo must be >= 0")
        if args.periods < 2:
            parser.error("--periods must be >= 2")
        if args.case == "lecture":
            from lptv.apps import lecture

            return lecture.run(args)
        from lptv.apps import demo

        return demo.run(args)
    if args.command == "identify":
        return fileid.run(args)
    if args.command == "montecarlo":
        return montecarlo.run(args)
    if args.command == "select":
        return choose.run(args)
    parser.error(f"unknown command {args.command}")
    return 2


if __name__ == "__main__":
    sys.exit(main())
