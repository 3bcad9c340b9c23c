#!/usr/bin/env python3
"""The README's trade-offs tables and chart from the lab's `trade-offs` runs.

usage: scripts/trade-offs-summary.py docs/results/nvidia-h200/trade-offs [CHART.svg]

Reads inside/bench.json and outside/bench.json (`manylights bench --preset trade-offs`,
scripts/gpu-machine-trade-offs.sh) and prints markdown tables of the median GPU ms a
frame: each pipeline without and with MSAA, on Sponza and on sponza-glass (the blended
banners and embers), inside and outside the castle; with a chart path, draws Forward+
against deferred at 1,000 lights as an SVG bar chart (log scale).
"""
import json
import math
import sys

folder = sys.argv[1]
results = []
for view in ["inside", "outside"]:
    with open(f"{folder}/{view}/bench.json") as file:
        for result in json.load(file)["results"]:
            result["view_name"] = view
            results.append(result)


def setting(config, path, field, default):
    """A configuration's setting: by its path in `settings` (reports since settings are
    data), by its own field in reports written before, else the default."""
    return config.get("settings", {}).get(path, config.get(field, default))


def frame(scene, view, pipeline, lights, msaa=1, transparency="sorted"):
    for r in results:
        c = r["config"]
        chosen = (
            setting(c, "view.msaa", "msaa", 1),
            setting(c, "transparency", "transparency", "sorted"),
        )
        if (c["scene"], r["view_name"], c["pipeline"], c["lights"]) + chosen == (
            scene, view, pipeline, lights, msaa, transparency
        ):
            return r
    return None


def ms(r):
    return r["gpu_total_median_ms"] if r and r.get("gpu_total_median_ms") else None


def blended_ms(r):
    passes = {p["name"]: p["median_ms"] for p in r["passes"]} if r else {}
    # The forward pass (and weighted transparency's composite), or deferred's layers
    # (issue 61: their store and their shading).
    return sum(ms for name, ms in passes.items() if name.startswith("blended"))


def cell(value):
    return "-" if value is None else f"{value:.2f}"


print("| workload | lights | Forward+ | Forward+ MSAA 4x | Forward+ MSAA 8x | deferred | deferred MSAA | naive | Forward+ / deferred |")
print("|---|---:|---:|---:|---:|---:|---|---:|---:|")
for scene in ["sponza", "sponza-glass"]:
    for view in ["inside", "outside"]:
        for lights in [1000, 10000]:
            forward = [ms(frame(scene, view, "forward-plus", lights, m)) for m in (1, 4, 8)]
            deferred = ms(frame(scene, view, "deferred", lights))
            naive = ms(frame(scene, view, "naive", lights))
            coverage = (frame(scene, view, "forward-plus", lights) or {}).get("accuracy", {}).get("blended_coverage")
            label = f"{scene}, {view}" + (f" ({coverage * 100:.0f}% under glass)" if coverage else "")
            ratio = forward[0] / deferred if forward[0] and deferred else None
            print(f"| {label} | {lights:,} | " + " | ".join(cell(v) for v in forward)
                  + f" | {cell(deferred)} | refused | {cell(naive)} | {ratio:.1f}x |")

print()
print("| sponza-glass | lights | pipeline | blended passes sorted | weighted | frame sorted | weighted | mean error sorted | weighted |")
print("|---|---:|---|---:|---:|---:|---:|---:|---:|")
for view in ["inside", "outside"]:
    for lights in [1000, 10000]:
        for pipeline, msaa in [("forward-plus", 1), ("forward-plus", 8), ("deferred", 1), ("naive", 1)]:
            sorted_, weighted = (frame("sponza-glass", view, pipeline, lights, msaa, t) for t in ("sorted", "weighted"))
            if not sorted_ or not weighted:
                continue
            name = pipeline + (f" MSAA {msaa}x" if msaa > 1 else "")
            errors = [r["accuracy"]["f64_mean_relative"] for r in (sorted_, weighted)]
            print(f"| {view} | {lights:,} | {name} | {blended_ms(sorted_):.2f} | {blended_ms(weighted):.2f} | "
                  f"{ms(sorted_):.2f} | {ms(weighted):.2f} | {errors[0]:.4f} | {errors[1]:.4f} |")

if len(sys.argv) > 2:
    groups = []
    for scene in ["sponza", "sponza-glass"]:
        for view in ["inside", "outside"]:
            bars = [("Forward+", ms(frame(scene, view, "forward-plus", 1000, 1)), "#4c78a8"),
                    ("Forward+ 4x", ms(frame(scene, view, "forward-plus", 1000, 4)), "#72b7b2"),
                    ("Forward+ 8x", ms(frame(scene, view, "forward-plus", 1000, 8)), "#9ecae9"),
                    ("deferred", ms(frame(scene, view, "deferred", 1000, 1)), "#f58518")]
            groups.append((f"{scene}, {view}", bars))
    width, height, left, bottom = 760, 330, 60, 60
    top = 40
    low, high = 1.0, 100.0
    def y(v):
        return top + (height - top - bottom) * (1 - (math.log10(v) - math.log10(low)) / (math.log10(high) - math.log10(low)))
    svg = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" font-family="sans-serif" font-size="12">',
           f'<text x="{left}" y="20" font-size="14">GPU ms a frame, 1,000 lights, 1920x1080, NVIDIA H200 (log scale)</text>']
    for tick in [1, 2, 5, 10, 20, 50, 100]:
        svg.append(f'<line x1="{left}" x2="{width - 10}" y1="{y(tick):.1f}" y2="{y(tick):.1f}" stroke="#ddd"/>')
        svg.append(f'<text x="{left - 8}" y="{y(tick) + 4:.1f}" text-anchor="end">{tick}</text>')
    group_width = (width - left - 10) / len(groups)
    for g, (label, bars) in enumerate(groups):
        x0 = left + g * group_width + 12
        bar_width = (group_width - 24) / len(bars)
        for b, (name, value, colour) in enumerate(bars):
            x = x0 + b * bar_width
            svg.append(f'<rect x="{x:.1f}" y="{y(value):.1f}" width="{bar_width - 3:.1f}" height="{y(low) - y(value):.1f}" fill="{colour}"/>')
            svg.append(f'<text x="{x + bar_width / 2 - 1:.1f}" y="{y(value) - 4:.1f}" text-anchor="middle" font-size="10">{value:.1f}</text>')
        svg.append(f'<text x="{x0 + (group_width - 24) / 2:.1f}" y="{height - bottom + 18}" text-anchor="middle">{label}</text>')
    for b, (name, _, colour) in enumerate(groups[0][1]):
        svg.append(f'<rect x="{left + b * 150}" y="{height - 22}" width="12" height="12" fill="{colour}"/>')
        svg.append(f'<text x="{left + b * 150 + 16}" y="{height - 12}">{name}</text>')
    svg.append("</svg>")
    with open(sys.argv[2], "w") as file:
        file.write("\n".join(svg) + "\n")
