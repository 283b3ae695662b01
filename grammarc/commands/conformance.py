"""``grammarc conform``: grammarc against Esri's PRT on the conformance kit's records, a table of verdicts."""

from __future__ import annotations

from grammarc.errors import UsageError


def run_conform(args) -> int:
    from grammarc.backend.attributes import parse_override
    from grammarc.conform import kit_dir, load_reference, run_conformance

    reference = load_reference()
    if args.all:
        runs = [(kit_dir() / "rpk" / f"{r['rpk']}.rpk", r["footprint"], r.get("attrs", {}))
                for r in reference["records"]]
    elif args.rpk is None or args.footprint is None:
        raise UsageError("conform takes RPK FOOTPRINT, or --all")
    else:
        runs = [(args.rpk, args.footprint, dict(parse_override(a) for a in args.attr))]
    print("| rpk | footprint | attrs | verdict |")
    print("|---|---|---|---|")
    passed = 0
    for rpk, footprint, attrs in runs:
        result = run_conformance(rpk, footprint, attrs, seed=args.seed, reference=reference)
        passed += result.passed
        shown = ", ".join(f"{k}={v:g}" if isinstance(v, float) else f"{k}={v}" for k, v in attrs.items())
        print(f"| {result.rpk} | {result.footprint} | {shown or '-'} | {result.summary} |", flush=True)
    print(f"{passed} of {len(runs)} pass")
    return 0 if passed == len(runs) else 1
