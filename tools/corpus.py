"""What ``grammarc check`` says of a folder of rule files, one line per kind of outcome.

Runs ``grammarc check FILE`` on every ``.cga`` under a folder (a corpus of public CityEngine rule files, say)
and sorts each file by its *first* error, so that the table shows what blocks most files first::

    python tools/corpus.py /work/corpus                  # the summary and the names that block most files
    python tools/corpus.py /work/corpus --list syntax     # the files of one category, with their first error
    python tools/corpus.py /work/corpus -k swiss --json out.json
    python tools/corpus.py /work/corpus --build           # and build each checked file with a start rule

With ``--build``, every file that checks and has a start rule (a rule without parameters annotated
``@StartRule``: the others are libraries that files import, or rules a lot cannot start) is also built on one 30 x 20 m lot, the issue's yardstick; a build that
fails, or skips its lot, is sorted by its first message in the same categories, under ``build``.

The categories: ``ok`` (exit 0), ``syntax`` (the parser refused the file), ``unsupported NAME`` (a construct
grammarc knows it does not do), ``unknown-function NAME``, ``import`` (an import could not be read or
resolved), ``encoding`` (the file is not UTF-8: CityEngine's older rule files are often Windows-1250/1252),
``crash`` (a traceback, or an exit code other than 0, 1 and 2), ``timeout``, and ``other SHAPE`` for every other
error, grouped by the shape of its message (names, paths and numbers blanked out). A file's own errors
and those of the files it imports count alike: the first one printed wins, as it is the one a user reads.

The blocking names count, for each unsupported construct and unknown function, the files in which it is *any*
error, not only the first: fixing it unblocks at most that many files.

``grammarc check`` prints no diagnostic code, only ``file:line:col: error: message``, so the categories come
from the messages; ``SYNTAX`` lists the parser's messages.
"""

from __future__ import annotations

import argparse
import json
import re
import subprocess
import sys
import tempfile
from collections import Counter
from concurrent.futures import ThreadPoolExecutor
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path

TIMEOUT = 60  # seconds per file
BUILD_TIMEOUT = 180  # seconds per build (a first build compiles numba kernels)
#: ``@StartRule`` before a rule (maybe after other annotations); group ``params`` is set when it takes some.
START_RULE = re.compile(r"@\s*StartRule\b(?:\s*@\w+(?:\([^)]*\))?)*\s*\w+\s*(?P<params>\()?", re.IGNORECASE)
#: One 30 x 20 m lot, the lot every file is built on.
LOT = {"type": "FeatureCollection", "features": [{"type": "Feature", "properties": {"id": "lot"}, "geometry": {
    "type": "Polygon", "coordinates": [[[0, 0], [30, 0], [30, 20], [0, 20], [0, 0]]]}}]}
SKIPPED = re.compile(r"^grammarc: lot \S+ \(#\d+\) skipped: (?P<message>.*)$", re.MULTILINE)
ERROR = re.compile(r"^(?P<where>.+?:\d+:\d+): error: (?P<message>.*)$", re.MULTILINE)
#: The messages of the parser and of the statement splitter (``frontend/parse.py``, the lowerings).
SYNTAX = re.compile(
    r"^(unexpected |unclosed `|a rule needs an arrow|`\]` without|a stochastic alternative needs"
    r"|nesting too deep|`[^`]+` (needs a body|takes no `\{|takes one part))"
)
#: ``unsupported: NAME (why)``; NAME is what the front end names, an operation with the case it lacks.
UNSUPPORTED = re.compile(r"^unsupported(?::| construct) (?P<name>.+?)(?: \(.*)?$")
UNKNOWN_FUNCTION = re.compile(r"^unknown function `(?P<name>[^`]+)`")
IMPORT = re.compile(r"\bimport")
ENCODING = re.compile(r"codec can't decode")
QUOTED = re.compile(r"`[^`]*`")
BLANKS = re.compile(r"`[^`]*`|\S*[/\\]\S*|\S+\.cga\b|\d+(\.\d+)?")


@dataclass
class Outcome:
    """What ``grammarc check`` said of one file: its category, the first error and every blocking name."""

    file: str
    category: str
    returncode: int | None
    where: str = ""
    message: str = ""
    blocking: list[str] = field(default_factory=list)
    build: Outcome | None = None


def classify(message: str) -> str:
    """The category of one error message: ``syntax``, ``unsupported NAME``, ``import``, ..."""
    if SYNTAX.match(message):
        return "syntax"
    if match := UNSUPPORTED.match(message):
        return f"unsupported {QUOTED.sub('_', match['name'])}"
    if match := UNKNOWN_FUNCTION.match(message):
        return f"unknown-function {match['name']}"
    if ENCODING.search(message):
        return "encoding"
    if IMPORT.search(message):
        return "import"
    return f"other {BLANKS.sub('_', message)[:70]}"


def check(path: Path) -> Outcome:
    """Run ``grammarc check`` on one file in a process of its own and sort its outcome."""
    return run(path, [sys.executable, "-m", "grammarc.cli", "check", str(path)], TIMEOUT)


def build(path: Path, lots: Path, out: Path) -> Outcome:
    """Build one file on the 30 x 20 m lot ``lots`` into ``out`` and sort the outcome: a skipped lot is a
    failure with the reason the build printed."""
    command = [sys.executable, "-m", "grammarc.cli", "build", str(path), "--lots", str(lots), "--emit", str(out),
               "--workers", "1", "--quiet"]
    outcome = run(path, command, BUILD_TIMEOUT)
    if outcome.category == "ok" and (skipped := SKIPPED.search(outcome.message)):
        return Outcome(str(path), classify(skipped["message"]), 0, message=skipped["message"])
    return replace(outcome, message="") if outcome.category == "ok" else outcome


def run(path: Path, command: list[str], timeout: int) -> Outcome:
    """Run a grammarc command on one file in a process of its own and sort its outcome (an ``ok`` keeps
    the command's output as its message)."""
    try:
        done = subprocess.run(command, check=False, capture_output=True, text=True, errors="replace",
                              timeout=timeout)
    except subprocess.TimeoutExpired:
        return Outcome(str(path), "timeout", None, message=f"no answer in {timeout} s")
    output = done.stderr + done.stdout
    if "Traceback (most recent call last)" in output or done.returncode not in (0, 1, 2):
        last = output.strip().splitlines()[-1] if output.strip() else f"exit code {done.returncode}"
        return Outcome(str(path), "crash", done.returncode, message=last)
    if done.returncode == 0:
        return Outcome(str(path), "ok", 0, message=done.stderr)
    errors = list(ERROR.finditer(done.stderr))
    if not errors:  # a GrammarcError: `grammarc: error: ...`, with no place in a file
        message = done.stderr.strip().splitlines()[0] if done.stderr.strip() else f"exit code {done.returncode}"
        return Outcome(str(path), classify(message.removeprefix("grammarc: error: ")), done.returncode,
                       message=message)
    categories = [classify(e["message"]) for e in errors]
    blocking = sorted({c for c in categories if c.startswith(("unsupported ", "unknown-function "))})
    first = errors[0]
    return Outcome(str(path), categories[0], done.returncode, first["where"], first["message"], blocking)


def has_start_rule(path: Path) -> bool:
    """Whether a rule file annotates a start rule without parameters (read as Latin-1: any byte decodes, the
    annotation is ASCII)."""
    return any(m["params"] is None for m in START_RULE.finditer(path.read_text(encoding="latin-1")))


def table(counts: Counter, title: str, limit: int | None = None) -> str:
    """``count  name`` lines, most first, under a title."""
    rows = counts.most_common(limit)
    width = max((len(str(n)) for _, n in rows), default=1)
    return "\n".join([title, *(f"  {n:>{width}}  {name}" for name, n in rows)])


def summary(outcomes: list[Outcome]) -> str:
    """The categories by number of files (``unsupported``, ``unknown-function`` and ``other`` as one line
    each), then the 30 blocking names and the other messages that stop most files; then the builds."""
    broad = Counter(o.category.split(" ", 1)[0] for o in outcomes)
    names = Counter(name for o in outcomes for name in o.blocking)
    others = Counter(o.category.split(" ", 1)[1] for o in outcomes if o.category.startswith("other "))
    ok = broad["ok"]
    parts = [
        f"{len(outcomes)} files, {ok} ok ({100 * ok / max(len(outcomes), 1):.0f} %)",
        table(broad, "first error, by category:"),
        table(names, "blocking names (files where each is an error):", 30),
        table(others, "other first errors (names and numbers blanked):", 30),
    ]
    builds = [o.build for o in outcomes if o.build is not None]
    if builds:
        built = sum(b.category == "ok" for b in builds)
        parts += [(f"{len(builds)} checked files with a start rule, {built} build on a 30 x 20 m lot "
                  f"({100 * built / len(builds):.0f} %)"),
                  table(Counter(b.category for b in builds if b.category != "ok"), "build failures:", 30)]
    return "\n\n".join(parts)


def listing(outcomes: list[Outcome], category: str) -> str:
    """The files whose category starts with ``category``, each with its first error."""
    if category == "build":
        chosen = [o.build for o in outcomes if o.build is not None and o.build.category != "ok"]
    else:
        chosen = [o for o in outcomes if o.category == category or o.category.startswith(category + " ")]
    return "\n".join(f"{o.file}  [{o.category}]\n    {o.where}: {o.message}" if o.where else
                     f"{o.file}  [{o.category}]\n    {o.message}" for o in chosen)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("folder", type=Path, help="checks every .cga below it")
    parser.add_argument("-k", default="", help="only the files whose path contains this")
    parser.add_argument("--list", metavar="CATEGORY", help="list the files of a category with their first error")
    parser.add_argument("--json", type=Path, help="write every file's outcome to this file")
    parser.add_argument("-j", "--jobs", type=int, default=2, help="files checked at once (default 2)")
    parser.add_argument("--build", action="store_true",
                        help="also build every checked file with a start rule on a 30 x 20 m lot")
    args = parser.parse_args()
    files = sorted(p for p in args.folder.rglob("*.cga") if args.k in str(p))
    with ThreadPoolExecutor(max_workers=args.jobs) as pool, tempfile.TemporaryDirectory() as scratch:
        outcomes = list(pool.map(check, files))
        if args.build:
            lots = Path(scratch, "lot.geojson")
            lots.write_text(json.dumps(LOT))
            starts = [o for o in outcomes if o.category == "ok" and has_start_rule(Path(o.file))]
            results = pool.map(lambda k: build(Path(starts[k].file), lots, Path(scratch, f"{k}.npz")),
                               range(len(starts)))
            for outcome, result in zip(starts, results, strict=True):
                outcome.build = result
        for outcome in outcomes:
            outcome.message = "" if outcome.category == "ok" else outcome.message
    print(summary(outcomes))
    if args.list:
        print(f"\nfiles with first error `{args.list}`:")
        print(listing(outcomes, args.list))
    if args.json:
        args.json.write_text(json.dumps([asdict(o) for o in outcomes], indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
