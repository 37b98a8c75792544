#!/usr/bin/python3
"""Rays per second through the Python module against the C++ batch tracer, in the same run.

Traces the work of BM_TraceBatchBeams in bench/trace_bench.cpp (a million rays, five beams of 0 to
20 degrees through 95 % of the Angenieux double Gauss's paraxial entrance pupil) with
``Lens.trace`` (numpy in, numpy out: copying in and out is part of the Python figure), runs the C++
benchmark for the same rays, and prints the medians of five runs and their ratio, in rounds that alternate the two
(docs/performance.md, "Python"). A benchmark, not a test: it asserts nothing.

    PYTHONPATH=build/python /usr/bin/python3 bench/python_trace_bench.py [--build build]
"""

import argparse
import json
import os
import pathlib
import statistics
import subprocess
import time

import numpy as np

import lensmith

LENS = "angenieux-double-gauss-1953"
RAYS = 1_000_000
RUNS = 5


def beams(lens):
    """The rays of BM_TraceBatchBeams, by the same formula."""
    pupil = lens.paraxial().entrance_pupil
    radius = 0.95 * pupil.diameter_mm / 2
    i = np.arange(RAYS, dtype=np.float64)
    angle = np.radians(20.0 * (np.arange(RAYS) % 5) / 4.0)
    r = radius * np.sqrt((i + 0.5) / RAYS)
    golden = 2.39996322972865332
    px, py = r * np.cos(golden * i), r * np.sin(golden * i)
    m, n = np.sin(angle), np.cos(angle)
    t = (pupil.z_mm + 10.0) / n
    origins = np.column_stack([px, py - m * t, np.full(RAYS, -10.0)])
    directions = np.column_stack([np.zeros(RAYS), m, n])
    return origins, directions


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=3, help="alternating rounds of both measurements")
    parser.add_argument("--build", default=str(pathlib.Path(__file__).resolve().parents[1] / "build"), help="the build folder")
    args = parser.parse_args()

    lens = lensmith.Lens.load(LENS)
    origins, directions = beams(lens)
    lens.trace(origins[:1000], directions[:1000])  # warm up: index tables, thread pool
    bench = pathlib.Path(args.build) / "bench" / "lensmith_bench_trace"
    surfaces = len(lens)
    # Rounds alternate the two, so that what else the machine does falls on both alike.
    ratios = []
    for round_ in range(args.rounds):
        seconds = []
        for _ in range(RUNS):
            start = time.perf_counter()
            result = lens.trace(origins, directions)
            seconds.append(time.perf_counter() - start)
            del result
        python_s = statistics.median(seconds)
        reused = lens.trace(origins, directions)
        seconds = []
        for _ in range(RUNS):
            start = time.perf_counter()
            lens.trace(origins, directions, out=reused)
            seconds.append(time.perf_counter() - start)
        reuse_s = statistics.median(seconds)
        done = subprocess.run([str(bench), "--benchmark_filter=BM_TraceBatchBeams", "--benchmark_format=json"], capture_output=True,
                              text=True, check=True)
        median = next(b for b in json.loads(done.stdout)["benchmarks"] if b.get("aggregate_name") == "median")
        cpp_s = median["real_time"] / 1000.0  # ms
        ratios.append((python_s / cpp_s, reuse_s / cpp_s))
        print(f"round {round_ + 1}: Python Lens.trace {python_s * 1000:.1f} ms ({RAYS / python_s / 1e6:.2f} M rays/s, "
              f"{RAYS * surfaces / python_s / 1e6:.1f} M ray-surfaces/s); C++ trace_batch {cpp_s * 1000:.1f} ms "
              f"({RAYS / cpp_s / 1e6:.2f} M rays/s); Python / C++ {python_s / cpp_s:.3f}; with out= (arrays reused) "
              f"{reuse_s * 1000:.1f} ms, {reuse_s / cpp_s:.3f}")
    result = lens.trace(origins, directions)
    print(f"lens {LENS}: {surfaces} surfaces, {RAYS} rays, {result.counts().get('ok', 0)} pass "
          f"(C++: {int(median.get('passed', 0))}); {os.cpu_count()} cores, medians of {RUNS}")
    print(f"Python / C++ time, median of {args.rounds} rounds: {statistics.median(r[0] for r in ratios):.3f} "
          f"(new output arrays), {statistics.median(r[1] for r in ratios):.3f} (out=, arrays reused)")


if __name__ == "__main__":
    main()
