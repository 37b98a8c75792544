"""Bulk exact tracing from Python: physics identities, reversibility, and clear errors for bad arrays."""

import numpy as np
import pytest

import lensmith


def parallel_beam(heights_mm, z_mm=-5.0):
    origins = np.zeros((len(heights_mm), 3))
    origins[:, 1] = heights_mm
    origins[:, 2] = z_mm
    directions = np.zeros_like(origins)
    directions[:, 2] = 1.0
    return origins, directions


def test_a_near_axis_parallel_ray_leaves_at_the_paraxial_slope():
    # Paraxial optics: a ray parallel to the axis at height h leaves the lens with slope -h / f'
    # (Welford, Aberrations of Optical Systems, ch. 3). At h = 1e-4 of the pupil radius the real ray's
    # third-order departure is ~1e-8 relative; 1e-6 leaves room for rounding.
    lens = lensmith.Lens.load("angenieux-double-gauss-1953")
    p = lens.paraxial()
    h = 1e-4 * p.entrance_pupil.diameter_mm / 2
    origins, directions = parallel_beam([h, -h])
    result = lens.trace(origins, directions)
    assert result.ok.all()
    slope = result.directions[:, 1] / result.directions[:, 2]
    assert slope == pytest.approx([-h / p.efl_mm, h / p.efl_mm], rel=1e-6)


def test_tracing_forward_then_backward_returns_to_the_starting_line():
    lens = lensmith.Lens.load("sasian-triplet")
    rng = np.random.default_rng(3)
    n = 2000
    origins = np.column_stack([rng.uniform(-3, 3, n), rng.uniform(-3, 3, n), np.full(n, -20.0)])
    directions = np.column_stack([rng.uniform(-0.05, 0.05, n), rng.uniform(-0.05, 0.05, n), np.ones(n)])
    directions /= np.linalg.norm(directions, axis=1)[:, None]
    wavelengths = rng.uniform(450.0, 650.0, n)
    forward = lens.trace(origins, directions, wavelengths)
    assert forward.ok.sum() > n // 2
    ok = forward.ok
    back = lens.trace(forward.positions_mm[ok], -forward.directions[ok], wavelengths[ok], direction="backward")
    assert back.ok.all()
    # The reversed ray, continued back to the start plane, meets the original origin: optical
    # reversibility; 1e-9 mm is rounding over the lens.
    d = -back.directions
    t = (origins[ok, 2] - back.positions_mm[:, 2]) / (-d[:, 2])
    start = back.positions_mm + (-d) * t[:, None]
    assert np.abs(start[:, :2] - origins[ok, :2]).max() < 1e-9
    assert np.abs(-back.directions - directions[ok]).max() < 1e-12


def test_a_ray_outside_the_aperture_is_vignetted_at_a_named_surface():
    lens = lensmith.Lens.load("sasian-triplet")
    origins, directions = parallel_beam([0.0, 1000.0])
    result = lens.trace(origins, directions)
    assert lensmith.RAY_STATUS[result.status[0]] == "ok"
    assert lensmith.RAY_STATUS[result.status[1]] in ("vignetted", "missed")
    assert result.surface[1] >= 1 and result.surface[0] == 0
    assert result.counts()["ok"] == 1


def test_one_wavelength_per_ray_gives_colour_dispersion():
    lens = lensmith.Lens.load("smith-cooke-triplet")
    origins, directions = parallel_beam([2.0, 2.0])
    result = lens.trace(origins, directions, np.array([486.1327, 656.2725]))
    assert result.ok.all()
    assert result.directions[0, 1] != pytest.approx(result.directions[1, 1], rel=1e-9)


@pytest.mark.parametrize("bad, error", [
    (np.zeros((4, 3), dtype=np.float32), TypeError),
    (np.zeros((4, 2)), ValueError),
    (np.zeros(12), ValueError),
    (np.zeros((4, 3), dtype=np.int64), TypeError),
])
def test_arrays_of_the_wrong_shape_or_dtype_raise_a_clear_error(bad, error):
    lens = lensmith.Lens.load("sasian-triplet")
    good = np.zeros((4, 3))
    good[:, 2] = 1.0
    with pytest.raises(error, match="origins_mm"):
        lens.trace(bad, good)
    with pytest.raises(error, match="directions"):
        lens.trace(np.zeros((4, 3)), bad)


def test_mismatched_row_counts_and_wavelength_arrays_are_refused():
    lens = lensmith.Lens.load("sasian-triplet")
    with pytest.raises(ValueError, match="rows"):
        lens.trace(np.zeros((4, 3)), np.zeros((5, 3)))
    with pytest.raises(TypeError, match="wavelengths_nm"):
        lens.trace(np.zeros((4, 3)), np.zeros((4, 3)), np.zeros(3))
    with pytest.raises(lensmith.OptionsError, match="direction"):
        lens.trace(np.zeros((4, 3)), np.zeros((4, 3)), direction="sideways")


def test_invalid_rays_are_reported_not_traced():
    lens = lensmith.Lens.load("sasian-triplet")
    origins = np.array([[0.0, 0.0, -5.0], [np.nan, 0.0, -5.0]])
    directions = np.array([[0.0, 0.0, 1.0], [0.0, 0.0, 1.0]])
    result = lens.trace(origins, directions)
    assert [lensmith.RAY_STATUS[s] for s in result.status] == ["ok", "invalid_input"]


def test_out_reuses_the_arrays_of_an_earlier_result_and_gives_the_same_rays():
    lens = lensmith.Lens.load("sasian-triplet")
    origins, directions = parallel_beam(np.linspace(-6, 6, 101))
    fresh = lens.trace(origins, directions)
    reused = lens.trace(origins[::-1].copy(), directions)
    kept = reused.positions_mm
    again = lens.trace(origins, directions, out=reused)
    assert again is reused and again.positions_mm is kept
    assert np.array_equal(again.positions_mm, fresh.positions_mm)
    assert np.array_equal(again.status, fresh.status)
    with pytest.raises(ValueError, match="out"):
        lens.trace(origins[:50], directions[:50], out=reused)  # another number of rays
