#!/usr/bin/env python3
"""Turns the JSON of a vsd_benchmarks run into the Markdown tables of benchmarks/README.md.

    ./build-bench/benchmarks/vsd_benchmarks --benchmark_repetitions=9 --benchmark_min_time=0.2 \
        --benchmark_report_aggregates_only=true --benchmark_out=bench.json --benchmark_out_format=json
    python3 benchmarks/report.py bench.json

Every figure is the median of the repetitions (CPU time, ns); every ratio is computed from medians of
the same run.
"""
import json
import sys


def load(path):
    with open(path) as f:
        data = json.load(f)
    med = {}
    for b in data["benchmarks"]:
        if b.get("aggregate_name") != "median":
            continue
        unit = b.get("time_unit", "ns")
        scale = {"ns": 1.0, "us": 1e3, "ms": 1e6}[unit]
        med[b["run_name"]] = b["cpu_time"] * scale
    return data["context"], med


def fmt(x):
    return f"{x:.3g}" if x < 100 else f"{x:.0f}"


def main():
    context, m = load(sys.argv[1])
    g = lambda name: m.get(name)

    print(f"Run on {context.get('date')}, {context.get('num_cpus')} CPUs, "
          f"library build type: {context.get('library_build_type')}.\n")

    print("| operation | vsd (ns) | goal | peers (ns) |")
    print("|---|---|---|---|")
    rows = [
        ("typed get / raw member get", f"{fmt(g('BM_Get_Typed'))} / {fmt(g('BM_Get_Raw'))}", "equal", ""),
        ("typed set / raw member set", f"{fmt(g('BM_Set_Typed'))} / {fmt(g('BM_Set_Raw'))} "
         f"(x{g('BM_Set_Typed') / g('BM_Set_Raw'):.2f})", "≤ 1.5x raw", f"Qt typed setter {fmt(g('BM_Qt_Set_Typed'))}"),
        ("typed set, one listener / while recording",
         f"{fmt(g('BM_Set_Typed_Observed'))} / {fmt(g('BM_Set_Typed_Recording'))}", "", ""),
        ("get by handle (built-in / run-time class)",
         f"{fmt(g('BM_Get_ByHandle_Builtin'))} / {fmt(g('BM_Get_ByHandle_Runtime'))}", "≤ 1.5",
         f"RTTR {fmt(g('BM_Rttr_Get_ByHandle'))}, Qt QMetaProperty {fmt(g('BM_Qt_Get_ByHandle'))}"),
        ("set by handle (built-in / run-time class)",
         f"{fmt(g('BM_Set_ByHandle_Builtin'))} / {fmt(g('BM_Set_ByHandle_Runtime'))}", "≤ 1.5",
         f"RTTR {fmt(g('BM_Rttr_Set_ByHandle'))}, Qt QMetaProperty {fmt(g('BM_Qt_Set_ByHandle'))}"),
        ("find_property (name from data)", fmt(g("BM_FindProperty_Builtin")), "", ""),
        ("get by name: from data / literal (built-in)",
         f"{fmt(g('BM_Get_ByName_Builtin'))} / {fmt(g('BM_Get_ByLiteralName_Builtin'))}", "≤ 6",
         f"RTTR {fmt(g('BM_Rttr_Get_ByName'))}, Qt {fmt(g('BM_Qt_Get_ByName'))}"),
        ("set by name: from data / literal (built-in)",
         f"{fmt(g('BM_Set_ByName_Builtin'))} / {fmt(g('BM_Set_ByLiteralName_Builtin'))}", "≤ 6",
         f"RTTR {fmt(g('BM_Rttr_Set_ByName'))}, Qt {fmt(g('BM_Qt_Set_ByName'))}"),
        ("get / set by name, run-time class",
         f"{fmt(g('BM_Get_ByName_Runtime'))} / {fmt(g('BM_Set_ByName_Runtime'))}", "", ""),
        ("emit, 0 / 1 / 10 listeners",
         f"{fmt(g('BM_Emit_Vsd/listeners:0'))} / {fmt(g('BM_Emit_Vsd/listeners:1'))} / {fmt(g('BM_Emit_Vsd/listeners:10'))}",
         "≤ 0.5 / ≤ 2.5 / +≤ 1.2 each",
         f"Boost.Signals2 {fmt(g('BM_Emit_Boost/listeners:0'))} / {fmt(g('BM_Emit_Boost/listeners:1'))} / {fmt(g('BM_Emit_Boost/listeners:10'))}; "
         f"libsigc++ {fmt(g('BM_Emit_Sigc/listeners:0'))} / {fmt(g('BM_Emit_Sigc/listeners:1'))} / {fmt(g('BM_Emit_Sigc/listeners:10'))}; "
         f"Qt {fmt(g('BM_Emit_Qt/listeners:0'))} / {fmt(g('BM_Emit_Qt/listeners:1'))} / {fmt(g('BM_Emit_Qt/listeners:10'))}"),
        ("create + destroy (built-in / run-time class)",
         f"{fmt(g('BM_CreateDestroy_Builtin'))} / {fmt(g('BM_CreateDestroy_Runtime'))}", "",
         f"new+delete {fmt(g('BM_CreateDestroy_Raw'))}, QObject {fmt(g('BM_CreateDestroy_Qt'))}"),
        ("element index: sum a double over 10 000 instances, per instance",
         f"{fmt(g('BM_Iterate_Index_Typed') / 1e4)} typed, {fmt(g('BM_Iterate_Index_ByHandle_Builtin') / 1e4)} by handle", "",
         f"raw pointers {fmt(g('BM_Iterate_RawPointers') / 1e4)}, contiguous {fmt(g('BM_Iterate_RawContiguous') / 1e4)}"),
        ("transaction: record one set / apply one set (bundles of 10 000)",
         f"{fmt(g('BM_Tx_Record/sets:10000') / 1e4)} / {fmt(g('BM_Tx_Apply/sets:10000') / 1e4)}", "", ""),
    ]
    for r in rows:
        print("| " + " | ".join(r) + " |")

    print("\nRatios from the same run (higher is better for vsd):\n")
    print("| comparison | ratio | goal |")
    print("|---|---|---|")
    ratio = lambda a, b: g(a) / g(b)
    one = g("BM_Emit_Vsd/listeners:1")
    per_more = (g("BM_Emit_Vsd/listeners:10") - one) / 9
    checks = [
        ("RTTR get by handle / vsd get by handle", ratio("BM_Rttr_Get_ByHandle", "BM_Get_ByHandle_Builtin"), "≥ 5"),
        ("RTTR set by handle / vsd set by handle", ratio("BM_Rttr_Set_ByHandle", "BM_Set_ByHandle_Builtin"), "≥ 5"),
        ("Qt QMetaProperty read / vsd get by handle", ratio("BM_Qt_Get_ByHandle", "BM_Get_ByHandle_Builtin"), "≥ 15"),
        ("Qt QMetaProperty write / vsd set by handle", ratio("BM_Qt_Set_ByHandle", "BM_Set_ByHandle_Builtin"), "≥ 15"),
        ("Boost.Signals2 / vsd, one listener", ratio("BM_Emit_Boost/listeners:1", "BM_Emit_Vsd/listeners:1"), "≥ 10"),
        ("Qt signal / vsd, one listener", ratio("BM_Emit_Qt/listeners:1", "BM_Emit_Vsd/listeners:1"), "≥ 10"),
        ("libsigc++ / vsd, one listener", ratio("BM_Emit_Sigc/listeners:1", "BM_Emit_Vsd/listeners:1"), "≥ 5"),
        ("run-time / built-in class, get by handle", ratio("BM_Get_ByHandle_Runtime", "BM_Get_ByHandle_Builtin"), "≤ 1.10"),
        ("run-time / built-in class, set by handle", ratio("BM_Set_ByHandle_Runtime", "BM_Set_ByHandle_Builtin"), "≤ 1.10"),
        ("run-time / built-in class, get by name", ratio("BM_Get_ByName_Runtime", "BM_Get_ByName_Builtin"), "≤ 1.10"),
    ]
    for name, r, goal in checks:
        print(f"| {name} | {r:.2f} | {goal} |")
    print(f"| each further listener (ns): (10 listeners − 1 listener) / 9 | {per_more:.2f} | ≤ 1.2 |")


if __name__ == "__main__":
    main()
