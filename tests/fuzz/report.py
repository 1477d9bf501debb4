"""Count the hostile cases per class and their outcomes (docs/robustness.md): the first
fuzz's classes (catalogue.py) and the second's (second_round.py).

    python -m tests.fuzz.report            # fast set (in-process, about a minute)
    python -m tests.fuzz.report --slow     # plus the slow set (subprocesses, minutes)
    python -m tests.fuzz.report --random 40 --markdown
    python -m tests.fuzz.report --no-fallback   # errors naming their file at the root only

Runs every case of :mod:`tests.fuzz.catalogue` (and ``--random N`` seeded garbage
inputs per command with an output) exactly as the test suite does, and prints one row per
class: cases, exit 0, exit 2, exit 130/143, other exits, failed cases whose error line
names no file (``no file``), cases breaking an invariant, and
how many of those belong to a change not yet merged (``owner``). Exit status 1 when a
case without an owner breaks an invariant.
"""

from __future__ import annotations

import argparse
import collections
import random
import sys
import tempfile
import time
from pathlib import Path

from tests.fuzz import catalogue as cat
from tests.fuzz import second_round

#: Every class counted: the first fuzz's, then the second fuzz's.
ALL_CLASSES = {**cat.CLASSES, **second_round.CLASSES}


def _random_cases(n: int, seed: int) -> list[cat.Case]:
    rng = random.Random(seed)
    roles = [r for r, (_s, _b, kind, _src) in cat._recipes().items() if kind is not None]
    out = []
    for i in range(n):
        role = roles[i % len(roles)]
        raw = cat._recipes()[role][3].read_bytes()
        cut = rng.randrange(len(raw) + 1)
        junk = bytes(rng.randrange(256) for _ in range(rng.randrange(1, 64)))
        out.append(cat._input_case("half-written", role, f"random-{i}",
                                   raw[:cut] + junk + raw[cut:]))
    return out


def measure(cases: list[cat.Case], root: Path, log=None) -> tuple[dict, list[str]]:
    rows: dict[str, collections.Counter] = {c: collections.Counter() for c in ALL_CLASSES}
    problems = []
    for i, case in enumerate(cases):
        t0 = time.perf_counter()
        try:
            outcome, bad = cat.run_case(case, root / f"c{i}")
        except cat._Skip as exc:
            rows[case.cls]["skipped"] += 1
            if log:
                log(f"skip {case.id}: {exc}")
            continue
        r = rows[case.cls]
        r["cases"] += 1
        code = outcome.code
        r["exit 0" if code == 0 else "exit 2" if code == 2 else
          "exit 130/143" if code in (130, 143) else "other"] += 1
        if any(b.startswith("error line names no file") for b in bad):
            r["no file"] += 1
        if bad:
            r["violations"] += 1
            if case.owner:
                r["pending"] += 1
            else:
                problems.append(f"{case.id}: {bad}")
        if log:
            log(f"{time.perf_counter() - t0:6.1f} s exit {code:3d} {case.id}"
                + (f"  VIOLATION {bad}" if bad else ""))
    return rows, problems


COLUMNS = ["cases", "exit 0", "exit 2", "exit 130/143", "other", "no file", "violations",
           "pending", "skipped"]


def table(rows: dict) -> str:
    lines = ["| class | " + " | ".join(COLUMNS) + " |",
             "|---" * (len(COLUMNS) + 1) + "|"]
    total = collections.Counter()
    for cls, text in ALL_CLASSES.items():
        r = rows[cls]
        total.update(r)
        lines.append(f"| {text} | " + " | ".join(str(r[c]) for c in COLUMNS) + " |")
    lines.append("| **all** | " + " | ".join(f"**{total[c]}**" for c in COLUMNS) + " |")
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--slow", action="store_true", help="also run the slow set")
    ap.add_argument("--random", type=int, default=20, help="seeded garbage inputs")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--markdown", action="store_true", help="print only the table")
    ap.add_argument("--no-fallback", action="store_true",
                    help="count only files named at the root: turn off the command line's "
                         "last resort of listing every input after a message (in-process "
                         "cases)")
    args = ap.parse_args(argv)
    if args.no_fallback:
        import inertialab.cli.main as cli_main

        cli_main._about = lambda files: ""
    cases = cat.fast_cases() + second_round.fast_cases() + _random_cases(args.random, args.seed)
    if args.slow:
        cases += cat.slow_cases() + second_round.slow_cases()
    log = None if args.markdown else (lambda s: print(s, file=sys.stderr, flush=True))
    with tempfile.TemporaryDirectory(prefix="inertialab-fuzz-") as tmp:
        t0 = time.perf_counter()
        rows, problems = measure(cases, Path(tmp), log)
        wall = time.perf_counter() - t0
    print(table(rows))
    print(f"\n{len(cases)} cases in {wall:.0f} s "
          f"({'fast and slow sets' if args.slow else 'fast set'}, "
          f"{args.random} random inputs, seed {args.seed})")
    for p in problems:
        print(f"VIOLATION {p}", file=sys.stderr)
    return 1 if problems else 0


if __name__ == "__main__":
    raise SystemExit(main())
