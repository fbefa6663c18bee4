#!/usr/bin/env python3
"""Markdown table for docs/post.md from the JSON of tools/bench-tonemap-pfstmo.sh
(run with --with-prism): python3 tools/bench_post_table.py result.json"""

import json
import sys

PEERS = {"reinhard02": "reinhard02", "drago03": "drago03", "durand02": "durand02"}


def main():
    d = json.load(open(sys.argv[1]))
    p = d["prism"]
    copy = p["copy_pass_ms"]
    print(f"Copy pass (read+write 4K float RGB, preallocated, {p['threads']} threads): "
          f"{copy:.1f} ms (median over the run; × copy uses the copy passes interleaved "
          f"with each operator's runs).\n")
    print("| operator | kind | compute ms | × copy | target | tonemap_file EXR→PNG ms "
          "(read / tone / write) | pfstmo whole process s |")
    print("|---|---|---:|---:|---|---:|---:|")
    for name, v in p["operators"].items():
        local = v["local"]
        # bench-post ≥ 2026-11-22 times copy passes interleaved with each operator's runs
        # and divides by their median; older JSON has only the global copy pass.
        own_copy = v.get("copy_pass_ms", copy)
        target = "≤ 300 ms" if local else f"≤ 3× ({3 * own_copy:.0f} ms)"
        ok = v["compute_ms"] <= 300 if local else v["ratio_to_copy"] <= 3
        s = v["file_stages_ms"]
        peer = d["pfstmo"].get(PEERS.get(name, ""), {}).get("whole_process_s")
        print(f"| {name} | {'local' if local else 'global'} | {v['compute_ms']:.0f} | "
              f"{v['ratio_to_copy']:.1f} | {target} {'met' if ok else 'missed'} | "
              f"{v['file_ms']:.0f} ({s['read_ms']:.0f} / {s['tone_ms']:.0f} / "
              f"{s['write_ms']:.0f}) | {'' if peer is None else f'{peer:.1f}'} |")
    cv = d.get("opencv")
    if cv:
        print(f"\nOpenCV {cv['version']} compute (same pixels): "
              + ", ".join(f"{k} {v['compute_s'] * 1e3:.0f} ms" for k, v in cv.items()
                          if isinstance(v, dict)))


if __name__ == "__main__":
    main()
