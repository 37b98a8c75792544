#!/usr/bin/python3
"""Scores `lensmith bokeh --thin-lens` against Blender's Defocus node on rendered scenes: tone-mapped
PSNR against the path-traced reference over the frame and over the depth-edge band, and time (issue
12's check; bench/blender/README.md).

Run:  /usr/bin/python3 bench/blender/scoreboard.py --shot DIR FSTOP FOCUS [--shot ...]

Each DIR holds make_reference.py's pinhole.exr (R, G, B, Z) and reference.exr rendered at f/FSTOP
focused at FOCUS metres. Per shot: lensmith's whole process (start to exit, the output written) is
timed --runs times and the median kept; the node's compositing alone (defocus_node.py, FULL_FRAME,
the fastest of --node-repeat runs, Blender's start-up and file writing excluded) is timed just
before. Both pictures are scored with lensmith_compare_images (band of --band px either side of the
depth edges). Prints a Markdown table; exits 1 if lensmith loses any comparison, 0 if it wins all.
"""
import argparse
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SCORE = re.compile(r"ImageComparison\(PSNR ([0-9.]+|inf) dB.*edge band [0-9]+ px: PSNR ([0-9.]+|inf) dB")


def parse_args():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--shot", nargs=3, action="append", metavar=("DIR", "FSTOP", "FOCUS"), required=True,
                   help="a scene directory, its reference's f-number and focus distance (m); repeatable")
    p.add_argument("--lensmith", default=os.path.join(ROOT, "build", "lensmith"), help="the lensmith binary")
    p.add_argument("--compare", default=os.path.join(ROOT, "build", "bench", "lensmith_compare_images"),
                   help="the lensmith_compare_images binary (built with -DLENSMITH_BUILD_TESTS=ON)")
    p.add_argument("--blender", default="blender", help="Blender 3.4 executable")
    p.add_argument("--threads", type=int, default=2, help="threads for both (default 2)")
    p.add_argument("--runs", type=int, default=11, help="lensmith runs per shot, median kept (default 11)")
    p.add_argument("--node-repeat", type=int, default=5, help="node compositing runs per shot, fastest kept (default 5)")
    p.add_argument("--band", type=int, default=8, help="depth-edge band half-width, px (default 8)")
    a = p.parse_args()
    for path in (a.lensmith, a.compare):
        if not os.access(path, os.X_OK):
            p.error(f"{path}: not an executable (build lensmith first, with tests for the compare tool)")
    if a.runs < 1 or a.node_repeat < 1 or a.threads < 1 or a.band < 1:
        p.error("--runs, --node-repeat, --threads and --band must be >= 1")
    for d, fstop, focus in a.shot:
        for name in ("pinhole.exr", "reference.exr"):
            if not os.path.isfile(os.path.join(d, name)):
                p.error(f"{os.path.join(d, name)}: missing (render it with make_reference.py)")
        try:
            if not (float(fstop) > 0 and float(focus) > 0):
                raise ValueError
        except ValueError:
            p.error(f"--shot {d} {fstop} {focus}: FSTOP and FOCUS must be numbers > 0")
    return a


def run_tool(command):
    """Runs a program, its output captured; a clear message where it is not there."""
    try:
        return subprocess.run(command, capture_output=True, text=True)
    except FileNotFoundError:
        sys.exit(f"scoreboard.py: {command[0]}: not found (Blender 3.4: apt-get install -y blender; or --blender PATH)")


def score(args, picture, shot_dir):
    out = subprocess.run([args.compare, picture, os.path.join(shot_dir, "reference.exr"),
                          os.path.join(shot_dir, "pinhole.exr"), str(args.band)],
                         check=True, capture_output=True, text=True).stdout
    m = SCORE.search(out)
    if not m:
        sys.exit(f"scoreboard.py: cannot read the scores in: {out.strip()}")
    return float(m.group(1)), float(m.group(2))


def node(args, shot_dir, fstop, focus, out):
    r = run_tool([args.blender, "-b", "--factory-startup", "-t", str(args.threads), "--python",
                        os.path.join(ROOT, "bench", "blender", "defocus_node.py"), "--", "--image",
                        os.path.join(shot_dir, "pinhole.exr"), "--fstop", fstop, "--focus", focus, "--out", out,
                        "--threads", str(args.threads), "--repeat", str(args.node_repeat),
                        "--execution-mode", "FULL_FRAME"])
    m = re.search(r"defocus_seconds=([0-9.]+)", r.stdout + r.stderr)
    if r.returncode != 0 or not m or not os.path.isfile(out):
        sys.exit(f"scoreboard.py: the Defocus node failed on {shot_dir}:\n{(r.stdout + r.stderr)[-2000:]}")
    return float(m.group(1))


def lensmith(args, shot_dir, fstop, focus, out):
    command = [args.lensmith, "bokeh", "--image", os.path.join(shot_dir, "pinhole.exr"), "--thin-lens",
               "--focal-length", "50", "--fstop", fstop, "--focus", focus, "--threads", str(args.threads), "-o", out,
               "--quiet"]
    times = []
    for _ in range(args.runs):
        start = time.perf_counter()
        subprocess.run(command, check=True)
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def main():
    args = parse_args()
    rows, lost = [], []
    with tempfile.TemporaryDirectory(prefix="lensmith-scoreboard-") as tmp:
        for i, (d, fstop, focus) in enumerate(args.shot):
            name = f"{os.path.basename(os.path.normpath(d))}, f/{fstop}, {focus} m"
            if sys.stderr.isatty():
                print(f"[{i + 1}/{len(args.shot)}] {name}", file=sys.stderr, flush=True)
            node_out, ours_out = os.path.join(tmp, f"node{i}.exr"), os.path.join(tmp, f"lensmith{i}.exr")
            node_s = node(args, d, fstop, focus, node_out)
            ours_s = lensmith(args, d, fstop, focus, ours_out)
            node_frame, node_band = score(args, node_out, d)
            ours_frame, ours_band = score(args, ours_out, d)
            rows.append((name, node_frame, node_band, ours_frame, ours_band, node_s, ours_s))
            for what, ours, theirs in (("frame PSNR", -ours_frame, -node_frame), ("band PSNR", -ours_band, -node_band),
                                       ("time", ours_s, node_s)):
                if not ours < theirs:
                    lost.append(f"{name}: {what}")
    print("| shot | node frame / band | lensmith frame / band | node time | lensmith time |")
    print("|---|---|---|---|---|")
    for name, nf, nb, lf, lb, ns, ls in rows:
        print(f"| {name} | {nf:.2f} / {nb:.2f} dB | {lf:.2f} / {lb:.2f} dB | {1e3 * ns:.1f} ms | {1e3 * ls:.1f} ms |")
    print()
    print("lensmith loses: " + "; ".join(lost) if lost else "lensmith wins every comparison")
    return 1 if lost else 0


if __name__ == "__main__":
    sys.exit(main())
