#!/usr/bin/env python3
"""Fits every shipped lens with `lensmith fit --json` and prints the Markdown table of
docs/performance.md ("Polynomial fits"). Usage: bench/lens_fit_table.py BUILD_DIR [lensmith fit options...]
Each fit measures its own timings (median of 5 single-thread runs over the held-out rays)."""
import json
import subprocess
import sys

build = sys.argv[1]
extra = sys.argv[2:]
lenses = [l["id"] for l in json.loads(subprocess.check_output([f"{build}/lensmith", "lenses", "--json"]))]
print("| lens | surfaces | clip surfaces | position RMS / p99 (um) | direction RMS (mrad) | sensor position RMS (um) "
      "| vignetting mismatch | exact ns/ray | poly ns/ray | speed-up | fit s |")
print("|---|---|---|---|---|---|---|---|---|---|---|")
for lens in lenses:
    info = json.loads(subprocess.check_output([f"{build}/lensmith", "info", lens, "--json"]))
    out = subprocess.run([f"{build}/lensmith", "fit", lens, "--json", "--quiet", *extra], capture_output=True, text=True)
    if out.returncode != 0:
        print(f"| {lens} | {len(info['marginal_ray']['surfaces'])} | fit failed: {out.stderr.strip()} |||||||||")
        continue
    j = json.loads(out.stdout)
    print(f"| {lens} | {len(info['marginal_ray']['surfaces'])} | {len(j['clip_surfaces'])} | {j['position_rms_um']:.2f} / "
          f"{j['position_p99_um']:.1f} | {j['direction_rms_mrad']:.3f} | {j['sensor_position_rms_um']:.2f} | "
          f"{100 * j['vignetting_mismatch']:.2f} % | {j['exact_ns_per_ray']:.0f} | {j['poly_ns_per_ray']:.1f} | "
          f"{j['speedup']:.1f}x | {j['fit_seconds']:.1f} |", flush=True)
