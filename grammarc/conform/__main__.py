"""``python -m grammarc.conform``: the differential harness against PRT (``fuzz``).

    python -m grammarc.conform --fuzz N [--packages candler,massing] [--classes L,concave] [--seed S]
                               [--out DIR] [--batch B]
    python -m grammarc.conform --fuzz N --footprints LOTS.geojson ...   # real lots (metres) instead
    python -m grammarc.conform --table DIR          # the table of every run into DIR
    python -m grammarc.conform --case FILE          # a saved mismatch, run again on both engines

Exit status: 0 when every case of the run matched, 1 when some did not, 2 on bad usage.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from grammarc.conform.footprints import CLASSES
from grammarc.conform.fuzz import PACKAGES, distributions, fuzz, read_results, rerun_case, table
from grammarc.errors import UsageError, signals_stop, stopped


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m grammarc.conform", description=__doc__.splitlines()[0])
    action = parser.add_mutually_exclusive_group(required=True)
    action.add_argument("--fuzz", type=int, metavar="N", help="N random cases per rule package")
    action.add_argument("--table", type=Path, metavar="DIR", help="tabulate the results saved in DIR")
    action.add_argument("--case", type=Path, metavar="FILE", help="run a saved case file again")
    parser.add_argument("--packages", default=",".join(PACKAGES), help="rule packages of the kit, by name")
    parser.add_argument("--classes", default=",".join(CLASSES), help="footprint classes, taken in turn")
    parser.add_argument("--seed", type=int, default=0, help="seed of the first case (cases use seed, seed+1...)")
    parser.add_argument("--out", type=Path, default=Path("conform-out"), help="results and mismatch cases")
    parser.add_argument("--batch", type=int, default=64, help="lots per PRT call and grammarc derivation")
    parser.add_argument("--footprints", type=Path, metavar="LOTS",
                        help="take the lots of this GeoJSON file (metres) instead of generated footprints")
    args = parser.parse_args(argv)
    try:
        with signals_stop():
            return _run(args)
    except UsageError as error:
        print(f"grammarc conform: {error}", file=sys.stderr)
        return 2
    except KeyboardInterrupt as stop:  # Ctrl-C, SIGTERM, SIGHUP: PRT's process and the temporary files go
        return stopped(stop, "grammarc conform", f"the finished batches' results are in {args.out}"
                       if args.fuzz else "nothing was written")


def _run(args) -> int:
    if args.table:
        results = read_results(args.table)
        print("\n\n".join(filter(None, [table(results), distributions(results)])))
        return 0
    if args.case:
        result = rerun_case(args.case)
        print(json.dumps(result, indent=1, default=float))
        return 1 if result["failed"] else 0
    results = fuzz(args.fuzz, args.out, packages=[p for p in args.packages.split(",") if p],
                   kinds=[k for k in args.classes.split(",") if k], seed=args.seed, batch=args.batch,
                   footprints=args.footprints, progress=lambda line: print(line, file=sys.stderr, flush=True))
    print("\n\n".join(filter(None, [table(results), distributions(results)])))
    return 1 if any(r["failed"] for r in results) else 0


if __name__ == "__main__":
    sys.exit(main())
