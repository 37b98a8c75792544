"""Fits from Python (make, save, load, render with them), the pictures (matplotlib and the command's
PNGs), and data frames with and without pandas."""

import sys

import numpy as np
import pytest

import lensmith
from conftest import SOURCE_DIR, assert_same_json


def test_a_fit_saved_and_loaded_reports_the_same_and_matches_the_command(cli, tmp_path):
    lens = lensmith.Lens.load("zeiss-biotar-1927")
    fit = lens.fit(degree=3, training_rays=3000, test_rays=500)
    path = tmp_path / "biotar.fit.json"
    fit.save(path)
    again = lensmith.Fit.load(path)
    ours = fit.report.to_dict()
    theirs = again.report.to_dict()
    for timing in ("fit_seconds", "exact_ns_per_ray", "poly_ns_per_ray", "speedup"):
        ours.pop(timing), theirs.pop(timing)
    assert_same_json(ours, theirs, rel=1e-12)
    again.check_matches(lens)
    # The command makes the same fit from the same options and seed.
    command = cli("fit", "zeiss-biotar-1927", "--degree", 3, "--training-rays", 3000, "--test-rays", 500, "--json")
    assert command["position_rms_um"] == pytest.approx(ours["position_rms_um"], rel=1e-6)
    bent = lens.copy()
    bent.surfaces[0].radius_mm *= 1.01
    with pytest.raises(lensmith.Error):
        again.check_matches(bent)


def test_bokeh_with_the_poly_model_takes_a_fit():
    lens = lensmith.Lens.load("zeiss-biotar-1927")
    fit = lens.fit(degree=3, training_rays=3000, test_rays=500, image_radius_mm=30)
    image = np.ones((24, 32, 3), np.float32)
    depth = np.full((24, 32), 5.0, np.float32)
    out = lensmith.bokeh(image, depth, lens=lens, focus_m=2, model="poly", fit=fit)
    assert np.isfinite(out).all() and out.mean() > 0.3
    with pytest.raises(lensmith.UsageError, match="poly"):
        lensmith.bokeh(image, depth, lens=lens, focus_m=2, model="seidel", fit=fit)


def test_anamorphic_mirror_and_tilt_shift_lenses_are_fitted_and_a_lens_tilted_inside_is_refused():
    anamorphic = lensmith.Lens.load(str(SOURCE_DIR / "tests/data/lentil/lenses.json") + "#2004")
    fit = anamorphic.fit(degree=3, training_rays=3000, test_rays=500)
    assert fit.symmetry == "section mirrors"
    assert fit.report.to_dict()["symmetry"] == "section mirrors"
    assert lensmith.Lens.load("zeiss-biotar-1927").fit(degree=3, training_rays=2000, test_rays=300).symmetry == "rotational"
    mirror = lensmith.Lens.load(str(SOURCE_DIR / "examples/lenses/cassegrain-500mm.json")).fit(degree=3, training_rays=2000, test_rays=300)
    assert mirror.symmetry == "rotational"
    # A tilt-shift lens: its elements are fitted, the coordinate breaks at its ends applied where the fit is used.
    shifted = lensmith.Lens.load(str(SOURCE_DIR / "examples/lenses/tilt-shift-50mm.json")).fit(degree=3, training_rays=2000, test_rays=300)
    assert shifted.symmetry == "rotational"
    folded = SOURCE_DIR / "tests/data/lensmith/tilted-rear-element.json"  # a break between elements
    with pytest.raises(lensmith.Error, match="between elements"):
        lensmith.Lens.load(str(folded)).fit(degree=3, training_rays=2000, test_rays=300)


@pytest.mark.parametrize("analysis", ["spot", "fan", "distortion", "field_curves", "focal_shift", "illumination", "pupil", "seidel"])
def test_every_report_draws_a_figure_with_data(analysis):
    from matplotlib.figure import Figure

    lens = lensmith.Lens.load("sasian-triplet")
    figure = getattr(lens, analysis)().plot()
    assert isinstance(figure, Figure)
    drawn = sum(len(ax.lines) + len(ax.patches) + len(ax.images) for ax in figure.axes)
    assert drawn > 0


@pytest.mark.parametrize("analysis, command", [
    ("spot", ["spot"]), ("fan", ["fan"]), ("distortion", ["analyze", "--what", "distortion"]), ("seidel", ["seidel"]),
])
def test_write_png_writes_the_commands_picture(cli, tmp_path, analysis, command):
    ours, theirs = tmp_path / "ours.png", tmp_path / "theirs.png"
    getattr(lensmith.Lens.load("sasian-triplet"), analysis)().write_png(ours)
    cli(command[0], "sasian-triplet", *command[1:], "--png", theirs, parse=False)
    assert ours.read_bytes() == theirs.read_bytes()


def test_seidel_sums_as_a_data_frame_with_pandas():
    pandas = pytest.importorskip("pandas")
    frame = lensmith.Lens.load("sasian-triplet").seidel().to_dataframe()
    assert isinstance(frame, pandas.DataFrame)
    assert list(frame.columns) == ["S1", "S2", "S3", "S4", "S5", "C1", "C2"]
    assert frame.loc["sum", "S1"] == pytest.approx(frame["S1"].iloc[:-1].sum(), rel=1e-9, abs=1e-12)


def test_without_pandas_the_arrays_remain_and_to_dataframe_says_what_is_missing(monkeypatch):
    monkeypatch.setitem(sys.modules, "pandas", None)  # import pandas now fails
    seidel = lensmith.Lens.load("sasian-triplet").seidel()
    assert seidel.per_surface()["S1"].shape == (len(lensmith.Lens.load("sasian-triplet")),)
    with pytest.raises(ImportError, match="pandas"):
        seidel.to_dataframe()
