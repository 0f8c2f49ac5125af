"""``lptv inspect FILE --input f1,f2 --output x1,x2``: a record of several channels before a
model is fitted.

Each input is inspected with the first output (its period: the shortest lag at which it
repeats) and each further output with the first input (whether it repeats with the inputs),
by :func:`lptv.inspect` on one pair at a time. The summary prints every pair's findings, the
period common to all channels (the longest of the pairs' periods when the others divide it),
and the ``lptv identify`` command for all channels together. ``summary.json`` holds every pair's
findings and the common ones; ``report.html`` the common findings, with each pair's own report
(its figure) in ``pair<k>/``. Exit status 0 when the record was inspected, 2 for a file or
options that cannot be read.
"""
from __future__ import annotations

import shlex
from pathlib import Path

from lptv import inspect
from lptv.apps.options import count
from lptv.apps.report import PLOTS_EXTRA, Report, write_json
from lptv.records.channels import distinct_channels


def _names(text, default):
    if text is None:
        return [default]
    names = [n.strip() for n in text.split(",")]
    if any(not n for n in names):
        raise ValueError(f"an empty channel name in the comma list '{text}'")
    return names


def common_period(insps):
    """(samples, sentence): the period all channels repeat at, or (None, why not)."""
    bad = [i for i in insps if not i.repeats]
    if bad:
        who = ", ".join(f"input '{i.input}' with output '{i.output}'" for i in bad)
        return None, (f"the record does not repeat for {who}: a record that does not repeat is fitted by the "
                      "one-record route, which is for one input and one output")
    lengths = sorted({int(i.period_samples) for i in insps})
    top = lengths[-1]
    if any(top % n for n in lengths):
        return None, (f"the channels repeat at periods of {', '.join(map(str, lengths))} samples, none a "
                      "multiple of all the others: no period common to the channels")
    if len(lengths) > 1:
        return top, (f"the channels repeat every {', '.join(map(str, lengths))} samples: the common period is "
                     f"{top} samples")
    return top, f"every channel repeats every {top} samples"


def command(insps, period, src, inputs, outputs):
    """The lptv identify command for all channels (the pair with the common period decides the
    sampling, the whole periods and the transient)."""
    ref = next(i for i in insps if int(i.period_samples) == period)
    cmd = ["lptv", "identify", shlex.quote(src), "--input", shlex.quote(",".join(inputs)),
           "--output", shlex.quote(",".join(outputs))]
    if ref.fs is not None:
        if ref.fs_given:
            cmd += ["--fs", f"{ref.fs:.12g}"]
        cmd += ["--period", f"{period / ref.fs:.12g}"]
    else:
        cmd += ["--periods", str(ref.periods)]
    if ref.leftover:
        cmd += ["--trim"]
    skip = max(int(i.transient_periods) for i in insps)
    if skip:
        cmd += ["--skip-periods", str(skip)]
    cmd += ["--lines", "excited", "--na", "NA", "--nb", "NB", "--ka", "KA", "--kb", "KB"]
    return " ".join(cmd)


def run(args, summary_of, report_of, fail) -> int:
    """The several-channel route of ``lptv inspect`` (``summary_of`` and ``report_of``: the
    one-pair summary.json and report of :mod:`lptv.apps.inspectrec`; ``fail`` its error)."""
    src = args.file
    try:
        inputs = _names(args.input, "u")
        outputs = _names(args.output, "y")
        pairs = [(u, outputs[0]) for u in inputs] + [(inputs[0], y) for y in outputs[1:]]
        insps = [inspect(src, u=u, y=y, time=args.time, fs=args.fs, dt=args.dt, reach=args.reach) for u, y in pairs]
        # each channel read once: 'f1' and 'F1 [N]' find one column, as the reader of lptv identify refuses
        found = [i.input for i in insps[:len(inputs)]] + [insps[0].output] + [i.output for i in insps[len(inputs):]]
        roles = ["u"] * len(inputs) + ["y"] * len(outputs)
        distinct_channels(list(zip(roles, found)), list(zip(roles, inputs + outputs)),
                          "column" if insps[0].format == "CSV" else "variable")
    except ValueError as e:
        return fail(src, e)
    period, finding = common_period(insps)
    cmd = command(insps, period, src, [i.input for i in insps[:len(inputs)]],
                  [insps[0].output] + [i.output for i in insps[len(inputs):]]) if period else None
    lines = [f"lptv inspect: {src}: {count(len(inputs), 'input')}, {count(len(outputs), 'output')}, inspected in "
             f"{count(len(pairs), 'pair')}"]
    for k, insp in enumerate(insps):
        lines.append("")
        lines.append(f"== pair {k}: input '{insp.input}', output '{insp.output}' ==")
        own = insp.summary().splitlines()
        # the pair's own suggestion is a command for one input and one output: the common one follows
        cut = next((j for j, t in enumerate(own) if t.startswith("suggested:")), len(own))
        lines.extend(own[:cut])
    lines.append("")
    lines.append(f"all channels: {finding}")
    if cmd:
        lines.append("suggested:   " + cmd)
        lines.append("             (NA, NB: the orders; KA, KB: a harmonic count per order, e.g. 1,0,0; one file per "
                     "experiment: the other experiments' files after this one)")
    text = "\n".join(lines)
    print(text)
    out = Path(args.out) if args.out else Path(Path(src).stem + "-inspect")
    try:
        out.mkdir(parents=True, exist_ok=True)
        write_json(out / "summary.json", {"file": str(src), "inputs": [i.input for i in insps[:len(inputs)]],
                                          "outputs": [insps[0].output] + [i.output for i in insps[len(inputs):]],
                                          "period_samples": period, "finding": finding, "command": cmd,
                                          "pairs": [summary_of(i) for i in insps]})
        rep = Report(f"lptv inspect: {Path(src).name} ({count(len(inputs), 'input')}, "
                     f"{count(len(outputs), 'output')})")
        rep.paragraph(f"All channels: {finding}." + (f" Suggested: {cmd}" if cmd else ""))
        rep.paragraph("Each input was inspected with the first output, each further output with the first "
                      "input; each pair's report, with its figure, is in pair<k>/report.html.")
        rep.preformatted(text)
        for k, insp in enumerate(insps):
            report_of(insp).write(out / f"pair{k}")
        rep.write(out)
    except OSError as e:
        return fail(e.filename or out, e.strerror or e)
    except ImportError:
        print(f"lptv inspect: {PLOTS_EXTRA}", file=__import__("sys").stderr)
        return 0
    print(f"wrote {out / 'report.html'}, {out / 'summary.json'}")
    return 0
