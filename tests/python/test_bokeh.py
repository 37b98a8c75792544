"""Bokeh on numpy arrays: the same picture as `lensmith bokeh` on the same input, and clear errors."""

import numpy as np
import pytest

import lensmith
from conftest import SOURCE_DIR

SCENE = SOURCE_DIR / "examples" / "scenes" / "occluder.json"


@pytest.fixture(scope="module")
def pinhole(cli, tmp_path_factory):
    """A small all-in-focus render of a shipped scene and its depth, through the command."""
    folder = tmp_path_factory.mktemp("pinhole")
    picture = folder / "pinhole.exr"
    cli("scene", "render", SCENE, "--pinhole", "--width", 96, "--height", 64, "-o", picture, "--depth", folder / "z.exr",
        parse=False)
    return picture, folder / "z.exr"


@pytest.mark.parametrize("method, lens, extra", [
    ("scatter", "canon-35mm-f1.8-1956", []),
    ("gather", "canon-35mm-f1.8-1956", []),
    ("ewa", "zeiss-biotar-1927", ["--blades", "6"]),
    ("lightfield", "zeiss-biotar-1927", ["--views", "8"]),
    ("multiview", "zeiss-biotar-1927", ["--samples", "8", "--model", "paraxial"]),
])
def test_the_picture_equals_the_commands(cli, pinhole, tmp_path, method, lens, extra):
    picture, depth = pinhole
    out = tmp_path / "cli.exr"
    cli("bokeh", "--image", picture, "--depth", depth, "--lens", lens, "--focus", 2, "--fstop", 2, "--method", method, *extra, "-o", out,
        parse=False)
    meta = lensmith.read_metadata(picture)
    options = dict(lens=lens, focus_m=2, fstop=2, method=method, pinhole_focal_length_mm=float(meta["lensmith:focal_length_mm"]),
                   sensor_width_mm=float(meta["lensmith:sensor_width_mm"]))
    for flag, value in zip(extra[::2], extra[1::2]):
        key = flag[2:].replace("-", "_")
        options[key] = value if key == "model" else int(value)
    ours = lensmith.bokeh(lensmith.read_image(picture), lensmith.read_depth(depth), **options)
    theirs = lensmith.read_image(out)
    assert ours.dtype == np.float32 and ours.shape == theirs.shape
    # Same code on the same floats; 1e-5 relative allows for a different summation order across threads.
    assert np.abs(ours - theirs).max() <= 1e-5 * max(1.0, float(theirs.max()))


def test_an_ideal_thin_lens_blurs_a_point_into_a_disc_of_the_thin_lens_size():
    # Thin-lens circle of confusion on the sensor: c = f^2 |z - s| / (N z (s - f)) (mm). The output
    # keeps the focus plane at its input pixels, so a sensor length d is d (s - f) / s on the pinhole
    # image's sensor of the same focal length.
    w, h = 401, 101
    image = np.zeros((h, w, 3), np.float32)
    image[50, 200] = 1000.0
    depth = np.full((h, w), 10.0, np.float32)
    f, n, s, z = 50.0, 1.4, 1000.0, 10000.0  # mm
    out = lensmith.bokeh(image, depth, thin_lens_focal_length_mm=f, fstop=n, focus_m=s / 1000, pinhole_focal_length_mm=f,
                         sensor_width_mm=36.0, spectral=False, vignetting=False)
    c_mm = f * f * abs(z - s) / (n * z * (s - f))
    radius_px = c_mm / 2 * (s - f) / s / (36.0 / w)
    lit = np.argwhere(out[:, :, 1] > 1e-3 * out[:, :, 1].max())
    measured = (lit[:, 1].max() - lit[:, 1].min() + 1) / 2
    assert radius_px > 8
    assert measured == pytest.approx(radius_px, abs=1.0)  # one pixel: the disc's anti-aliased rim
    assert out.sum() == pytest.approx(image.sum(), rel=0.02)  # the light is kept


def test_wrong_dtypes_and_shapes_are_refused_with_a_clear_error():
    image = np.zeros((8, 8, 3), np.float32)
    depth = np.ones((8, 8), np.float32)
    with pytest.raises(TypeError, match="float32"):
        lensmith.bokeh(image.astype(np.float64), depth, thin_lens_focal_length_mm=50, fstop=2, focus_m=1)
    with pytest.raises(ValueError, match=r"\(H, W, 3\)"):
        lensmith.bokeh(np.zeros((8, 8, 4), np.float32), depth, thin_lens_focal_length_mm=50, fstop=2, focus_m=1)
    with pytest.raises(ValueError, match="size"):
        lensmith.bokeh(image, np.ones((8, 9), np.float32), thin_lens_focal_length_mm=50, fstop=2, focus_m=1)


def test_options_are_checked_like_the_commands():
    image = np.zeros((8, 8, 3), np.float32)
    depth = np.ones((8, 8), np.float32)
    with pytest.raises(lensmith.UsageError, match="method='multiview'"):
        lensmith.bokeh(image, depth, thin_lens_focal_length_mm=50, fstop=2, focus_m=1, samples=8)
    with pytest.raises(lensmith.UsageError, match="focus"):
        lensmith.bokeh(image, depth, thin_lens_focal_length_mm=50, fstop=2)
    with pytest.raises(lensmith.OptionsError, match="method"):
        lensmith.bokeh(image, depth, thin_lens_focal_length_mm=50, fstop=2, focus_m=1, method="blur")
    with pytest.raises(TypeError):
        lensmith.bokeh(image, depth, thin_lens_focal_length_mm=50, fstop=2, focus_m=1, blur=3)  # no such keyword


def test_an_invalid_depth_names_the_pixel_and_can_be_treated_as_far():
    image = np.zeros((8, 8, 3), np.float32)
    depth = np.ones((8, 8), np.float32)
    depth[3, 5] = -1.0
    with pytest.raises(lensmith.ImageFileError, match=r"\(5, 3\)"):
        lensmith.bokeh(image, depth, thin_lens_focal_length_mm=50, fstop=2, focus_m=1)
    out = lensmith.bokeh(image, depth, thin_lens_focal_length_mm=50, fstop=2, focus_m=1, invalid_depth="far")
    assert np.isfinite(out).all()


OCIO_CONFIG = SOURCE_DIR / "tests" / "data" / "ocio" / "config.ocio"
# Academy S-2014-004: ACES2065-1 (AP0) from ACEScg (AP1), and MaterialX's linear Rec.709 -> AP0.
AP1_TO_AP0 = np.array([[0.6954522414, 0.1406786965, 0.1638690622], [0.0447945634, 0.8596711185, 0.0955343182],
                       [-0.0055258826, 0.0040252103, 1.0015006723]])
REC709_TO_AP0 = np.array([[0.43963298, 0.38298870, 0.17737832], [0.08977644, 0.81343943, 0.09678413],
                          [0.01754117, 0.11154655, 0.87091228]])


def test_convert_colorspace_takes_acescg_to_linear_rec709_by_the_published_matrices():
    rng = np.random.default_rng(7)
    acescg = rng.uniform(0.0, 4.0, (5, 7, 3)).astype(np.float32)
    rec709 = lensmith.convert_colorspace(acescg, "ACEScg", None, ocio=OCIO_CONFIG)
    expected = acescg.astype(np.float64) @ (np.linalg.inv(REC709_TO_AP0) @ AP1_TO_AP0).T
    np.testing.assert_allclose(rec709, expected, rtol=2e-6, atol=2e-6)  # float pixels, 8-decimal matrices
    back = lensmith.convert_colorspace(rec709, None, "ACEScg", ocio=OCIO_CONFIG)
    np.testing.assert_allclose(back, acescg, rtol=2e-6, atol=2e-6)


def test_bokeh_of_an_acescg_picture_is_the_acescg_of_the_rec709_bokeh(pinhole):
    picture, depth = pinhole
    rgb, z = lensmith.read_image(picture), lensmith.read_depth(depth)
    meta = lensmith.read_metadata(picture)
    camera = dict(lens="canon-35mm-f1.8-1956", focus_m=2, pinhole_focal_length_mm=float(meta["lensmith:focal_length_mm"]),
                  sensor_width_mm=float(meta["lensmith:sensor_width_mm"]))
    acescg = lensmith.convert_colorspace(rgb, None, "ACEScg", ocio=OCIO_CONFIG)
    ours = lensmith.bokeh(acescg, z, input_colorspace="ACEScg", ocio=OCIO_CONFIG, **camera)
    reference = lensmith.convert_colorspace(lensmith.bokeh(rgb, z, **camera), None, "ACEScg", ocio=OCIO_CONFIG)
    np.testing.assert_allclose(ours, reference, rtol=2e-5, atol=2e-5)  # the renderer is linear in RGB
    with pytest.raises(lensmith.OptionsError, match="ACEScct"):
        lensmith.convert_colorspace(rgb, "ACEScct", None, ocio=OCIO_CONFIG)
    with pytest.raises(lensmith.OptionsError):
        lensmith.bokeh(rgb, z, ocio=OCIO_CONFIG, **camera)
