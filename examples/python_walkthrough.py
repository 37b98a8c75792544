#!/usr/bin/python3
# %% [markdown]
# # lensmith in a notebook
#
# A walkthrough of the Python module (docs/python.md), cell by cell: open it in Jupyter or VS Code
# (the `# %%` markers are cells), or run it whole:
#
#     PYTHONPATH=build/python /usr/bin/python3 examples/python_walkthrough.py [OUTPUT_FOLDER]
#
# It writes its figures and pictures to OUTPUT_FOLDER (default `walkthrough/`).

# %%
import pathlib
import sys
import time

import numpy as np

import lensmith

HERE = pathlib.Path(__file__).resolve().parent
OUT = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else "walkthrough")
OUT.mkdir(parents=True, exist_ok=True)

# %% [markdown]
# ## A lens from a Zemax file, and its first-order data
# `Lens.load` takes a lens file (.zmx, .json, .dat) or the id of a shipped lens (`lensmith.lenses()`).
# `paraxial()` has the fields of `lensmith info --json`: distances in mm, z = 0 at surface 1.

# %%
lens = lensmith.Lens.load(HERE / "sasian-triplet.zmx")
print(lens)
first = lens.paraxial()
print(f"EFL {first.efl_mm:.4f} mm, BFL {first.bfl_mm:.4f} mm, f/{first.f_number:.3f}, "
      f"entrance pupil {first.entrance_pupil.diameter_mm:.3f} mm at z = {first.entrance_pupil.z_mm:.3f} mm")

# %% [markdown]
# ## Seidel sums per surface, as arrays (and a DataFrame with pandas)

# %%
seidel = lens.seidel()
table = seidel.per_surface()
print("surface", table["surface"])
print("S1 (spherical) per surface, mm:", np.round(table["S1"], 6))
print("sums:", {k: round(v, 6) for k, v in seidel.sums.items()})
try:
    print(seidel.to_dataframe())
except ImportError as e:  # pandas is optional
    print(e)
seidel.plot().savefig(OUT / "seidel.png", dpi=100)

# %% [markdown]
# ## Bend the lens and see the change
# Surfaces are views into the lens: changing one changes the lens.

# %%
bent = lens.copy()
bent.surfaces[0].radius_mm *= 1.02
print(f"front radius {lens.surfaces[0].radius_mm:.3f} -> {bent.surfaces[0].radius_mm:.3f} mm: "
      f"EFL {lens.paraxial().efl_mm:.4f} -> {bent.paraxial().efl_mm:.4f} mm, "
      f"S1 {seidel.sums.S1:.6f} -> {bent.seidel().sums.S1:.6f}")

# %% [markdown]
# ## First order across the spectrum: the 64-wavelength table as numpy columns

# %%
spectral = lens.spectral_table()
shift = spectral.image_distance_mm - first.image_distance_mm
print(f"paraxial image distance from {spectral.wavelength_nm[0]:.0f} to {spectral.wavelength_nm[-1]:.0f} nm: "
      f"{shift.min() * 1000:.1f} to {shift.max() * 1000:.1f} um about the primary's")

# %% [markdown]
# ## A million exact rays
# Beams at 0 to 20 degrees through the entrance pupil, traced by the C++ batch tracer on every core.

# %%
n = 1_000_000
rng = np.random.default_rng(1)
r = 0.5 * first.entrance_pupil.diameter_mm * np.sqrt(rng.random(n))
phi = 2 * np.pi * rng.random(n)
angle = np.radians(20.0 * rng.random(n))
directions = np.column_stack([np.zeros(n), np.sin(angle), np.cos(angle)])
t = (first.entrance_pupil.z_mm + 10.0) / directions[:, 2]
origins = np.column_stack([r * np.cos(phi), r * np.sin(phi) - directions[:, 1] * t, np.full(n, -10.0)])
start = time.perf_counter()
rays = lens.trace(origins, directions)
seconds = time.perf_counter() - start
print(f"{n} rays in {seconds:.3f} s ({n / seconds / 1e6:.1f} M rays/s): {rays.counts()}")

# %% [markdown]
# ## Spot diagrams, ray fans and field curves: numbers and figures

# %%
spot = lens.spot(fields=[0, 0.7, 1])
for field in spot.fields:
    print(f"field {field.field_value:.2f} {spot.field_unit}: RMS radius {field.polychromatic.rms_radius_chief_um:.2f} um")
spot.plot().savefig(OUT / "spot.png", dpi=100)
spot.write_png(OUT / "spot-lensmith.png")  # the picture `lensmith spot --png` draws
lens.fan().plot().savefig(OUT / "fan.png", dpi=100)
lens.field_curves().plot().savefig(OUT / "field-curves.png", dpi=100)
distortion = lens.distortion()
print(f"distortion at full field: {distortion.column('distortion_percent')[-1]:.3f} %")

# %% [markdown]
# ## Bokeh on a numpy image
# The bundled all-in-focus scene and its depth, through the Canon 35 mm f/1.8 of 1956, focused on
# the foreground post. The framing of the render is in its attributes.

# %%
image = lensmith.read_image(HERE / "bokeh-scene.exr")
depth = lensmith.read_depth(HERE / "bokeh-scene.exr")
meta = lensmith.read_metadata(HERE / "bokeh-scene.exr")
start = time.perf_counter()
photo = lensmith.bokeh(image, depth, lens="canon-35mm-f1.8-1956", focus_m=1.2,
                       pinhole_focal_length_mm=float(meta["lensmith:focal_length_mm"]),
                       sensor_width_mm=float(meta["lensmith:sensor_width_mm"]))
print(f"bokeh {photo.shape} in {time.perf_counter() - start:.2f} s")
lensmith.write_image(OUT / "bokeh.png", photo)

# %% [markdown]
# ## A polynomial fit, saved and used for rendering

# %%
biotar = lensmith.Lens.load("zeiss-biotar-1927")
fit = biotar.fit(degree=5, training_rays=8000, test_rays=2000, image_radius_mm=50)  # mm on the sensor: the frame rendered below
print(f"fit: position RMS {fit.report.position_rms_um:.2f} um on held-out rays, {fit.report.speedup:.1f}x faster than tracing")
fit.save(OUT / "biotar.fit.json")
# At a quarter of the size (the same framing): the poly model aims every pixel's rays through the
# fit, which takes about a minute for the whole 640 x 360 picture on two cores.
poly = lensmith.bokeh(image[::4, ::4], depth[::4, ::4], lens=biotar, focus_m=1.2, model="poly",
                      fit=lensmith.Fit.load(OUT / "biotar.fit.json"), pinhole_focal_length_mm=50, spectral=False)
lensmith.write_image(OUT / "bokeh-poly.png", poly)

# %% [markdown]
# ## Errors carry the place
# A malformed lens file raises `LensFileError` with its file and line.

# %%
broken = OUT / "broken.json"
broken.write_text('{\n  "format": "lensmith-lens",\n  "version": 1,\n  "name": "broken",\n  "surfaces": 3\n}\n')
try:
    lensmith.Lens.load(broken)
except lensmith.LensFileError as e:
    print(f"{e.file}:{e.line}: {e.detail}")
print(f"wrote {OUT}/")
