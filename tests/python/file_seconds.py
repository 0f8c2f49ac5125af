"""Writes file_seconds.txt, the seconds each test file took, from the --durations=0 report of a
whole pytest run read on standard input (make pytest-order); conftest.py orders the files by it,
longest first, so that the two workers of make pytest end together.

    python -m pytest -n 2 --dist loadfile --durations=0 | python file_seconds.py
"""
import re
import sys
from collections import defaultdict
from pathlib import Path

ROW = re.compile(r"^\s*([0-9.]+)s\s+(setup|call|teardown)\s+(\S+?\.py)::")
FAILED = re.compile(r"\b\d+ (failed|errors?)\b.*\bin [0-9.]+s")


def main() -> int:
    seconds = defaultdict(float)
    failed = False
    for line in sys.stdin:
        sys.stdout.write(line) if FAILED.search(line) else None
        failed = failed or bool(FAILED.search(line))
        m = ROW.match(line)
        if m:
            seconds[m.group(3).rsplit("/", 1)[-1]] += float(m.group(1))
    if not seconds:
        print("file_seconds.py: no --durations rows on standard input; file_seconds.txt left as it was",
              file=sys.stderr)
        return 1
    rows = sorted(seconds.items(), key=lambda kv: -kv[1])
    out = Path(__file__).with_name("file_seconds.txt")
    out.write_text("# seconds per test file in one whole run (make pytest-order); conftest.py runs the "
                   "longest first\n" + "".join(f"{s:8.2f} {f}\n" for f, s in rows))
    print(f"file_seconds.py: {len(rows)} files, {sum(seconds.values()):.0f} s in all, written to {out}")
    if failed:   # the pipe hides pytest's own exit status from make
        print("file_seconds.py: the run had failures (above)", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
