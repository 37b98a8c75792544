"""No reference leaks: memory stays flat over many calls, and arguments keep their reference counts."""

import gc
import os
import sys
import weakref

import numpy as np

import lensmith


def resident_mb():
    with open(f"/proc/{os.getpid()}/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE") / 2**20


def test_memory_stays_flat_over_many_calls():
    lens = lensmith.Lens.load("sasian-triplet")
    origins = np.zeros((20000, 3))
    origins[:, 1] = np.linspace(-5, 5, 20000)
    origins[:, 2] = -5.0
    directions = np.zeros_like(origins)
    directions[:, 2] = 1.0
    image = np.ones((32, 48, 3), np.float32)
    depth = np.full((32, 48), 3.0, np.float32)

    def work():
        lens.trace(origins, directions)
        lens.paraxial()
        lens.seidel()
        lens.spot(rings=3)
        lensmith.bokeh(image, depth, lens=lens, focus_m=1, spectral=False)
        try:
            lensmith.Lens.load("no-such-lens")
        except lensmith.Error:
            pass

    for _ in range(20):  # warm up: caches, allocator pools
        work()
    gc.collect()
    before = resident_mb()
    for _ in range(200):
        work()
    gc.collect()
    grown = resident_mb() - before
    # One call's arrays are ~1.5 MB; a leak of any of them per call would grow 300 MB in 200 calls.
    assert grown < 20, f"resident memory grew {grown:.1f} MB over 200 calls"


def test_arguments_keep_their_reference_counts():
    lens = lensmith.Lens.load("sasian-triplet")
    origins = np.zeros((10, 3))
    directions = np.zeros((10, 3))
    directions[:, 2] = 1.0
    counts = sys.getrefcount(origins), sys.getrefcount(directions)
    for _ in range(100):
        result = lens.trace(origins, directions)
    after = sys.getrefcount(origins), sys.getrefcount(directions)
    assert after == counts
    # The results are owned by the caller alone: gone when the caller lets go.
    outputs = [weakref.ref(a) for a in (result.positions_mm, result.directions, result.status, result.surface)]
    del result
    gc.collect()
    assert all(ref() is None for ref in outputs)
