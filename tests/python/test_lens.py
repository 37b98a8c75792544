"""Lenses from Python: loading, the native JSON both ways, surfaces that change the lens, errors."""

import math

import pytest

import lensmith
from conftest import SOURCE_DIR, ZEMAX_DIR


def test_every_shipped_lens_is_listed_and_loads():
    listed = lensmith.lenses()
    assert len(listed) >= 10
    assert "angenieux-double-gauss-1953" in [entry.id for entry in listed]
    for entry in listed:
        lens = lensmith.Lens.load(entry.id)
        assert lens.name == entry.name
        assert len(lens) == len(lens.surfaces) > 0


def test_a_zemax_file_loads_with_its_surfaces():
    lens = lensmith.Lens.load(ZEMAX_DIR / "sasian_triplet.zmx")
    assert len(lens) >= 6
    assert any(s.is_stop for s in lens.surfaces)
    assert lens.surfaces[0].glass != "air"


def test_to_json_and_from_json_give_back_an_equal_lens():
    lens = lensmith.Lens.load("zeiss-biotar-1927")
    again = lensmith.Lens.from_json(lens.to_json())
    assert again == lens
    assert again.paraxial().efl_mm == lens.paraxial().efl_mm


def test_bending_a_surface_changes_the_lens_and_its_first_order_data(tmp_path, cli):
    lens = lensmith.Lens.load("smith-cooke-triplet")
    before = lens.paraxial().efl_mm
    first = lens.surfaces[0]
    first.radius_mm = first.radius_mm * 1.05
    assert lens.surface(1).radius_mm == pytest.approx(first.radius_mm)
    after = lens.paraxial().efl_mm
    assert after != pytest.approx(before, rel=1e-4)
    # The changed lens, saved, is what the command reads: the same focal length.
    path = tmp_path / "bent.json"
    lens.save(path)
    assert cli("info", path, "--json")["efl_mm"] == pytest.approx(after, rel=1e-12)


def test_changing_the_glass_changes_the_index_and_is_checked_at_once():
    lens = lensmith.Lens.load("smith-cooke-triplet")
    s = lens.surfaces[0]
    s.glass = "N-BK7"
    assert s.index(587.5618) == pytest.approx(1.5168, abs=1e-4)  # Schott datasheet nd of N-BK7
    with pytest.raises(lensmith.GlassError, match="N-BK7"):
        s.glass = "NBK7"  # misspelt: the closest catalogue names are suggested
    s.set_model_glass(1.6, 40.0)
    assert s.index(587.5618) == pytest.approx(1.6, abs=1e-12)


def test_a_plane_has_infinite_radius_and_zero_radius_is_refused():
    lens = lensmith.Lens.load("smith-cooke-triplet")
    lens.surfaces[1].radius_mm = math.inf
    assert lens.surfaces[1].curvature_per_mm == 0.0
    with pytest.raises(lensmith.OptionsError):
        lens.surfaces[1].radius_mm = 0.0


def test_an_invalid_change_is_reported_by_the_next_analysis():
    lens = lensmith.Lens.load("smith-cooke-triplet")
    lens.surfaces[2].semi_diameter_mm = -1.0
    with pytest.raises(lensmith.PrescriptionError, match="surface 3"):
        lens.paraxial()


def test_a_malformed_file_raises_with_its_file_and_line(tmp_path):
    bad = tmp_path / "bad.json"
    bad.write_text('{\n  "format": "lensmith-lens",\n  "version": 1,\n  "name": 3\n}\n')
    with pytest.raises(lensmith.LensFileError) as error:
        lensmith.Lens.load(bad)
    assert error.value.file == str(bad)
    assert error.value.line >= 2
    assert str(bad) in str(error.value)


def test_a_truncated_zemax_file_raises_a_lens_file_error():
    with pytest.raises(lensmith.LensFileError) as error:
        lensmith.Lens.load(ZEMAX_DIR / "truncated.zmx")
    assert error.value.file.endswith("truncated.zmx")


def test_an_unknown_name_suggests_the_closest_shipped_lenses():
    with pytest.raises(lensmith.Error, match="smith-cooke-triplet"):
        lensmith.Lens.load("smith-cooke-triplett")


def test_errors_are_python_exception_types():
    assert issubclass(lensmith.OptionsError, ValueError)
    assert issubclass(lensmith.IoError, OSError)
    assert issubclass(lensmith.LensFileError, lensmith.Error)


def test_a_surface_number_out_of_range_is_an_index_error():
    lens = lensmith.Lens.load("smith-cooke-triplet")
    with pytest.raises(IndexError):
        lens.surface(len(lens) + 1)


def test_save_never_overwrites_the_file_the_lens_came_from(tmp_path):
    path = tmp_path / "lens.json"
    lensmith.Lens.load("smith-cooke-triplet").save(path)
    lens = lensmith.Lens.load(path)
    with pytest.raises(lensmith.UsageError):  # the command's rule for every output (ensure_not_an_input)
        lens.save(path)
