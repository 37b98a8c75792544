"""The module's reports equal the command's --json for the shipped lenses (docs/python.md).

Tolerance 1e-9 relative (assert_same_json): both run the same library code; a larger difference
means an option reached the library differently."""

import pytest

import lensmith
from conftest import ZEMAX_DIR, assert_same_json

SHIPPED = [entry.id for entry in lensmith.lenses()]


@pytest.mark.parametrize("lens_id", SHIPPED)
def test_first_order_data_equals_info_json(cli, lens_id):
    lens = lensmith.Lens.load(lens_id)
    assert_same_json(lens.paraxial().to_dict(), cli("info", lens_id, "--json"))


def test_first_order_data_at_another_wavelength_and_distance_equals_info_json(cli):
    lens = lensmith.Lens.load("zeiss-biotar-1927")
    ours = lens.paraxial(wavelength_nm=486.1327, object_distance_m=2.0).to_dict()
    assert_same_json(ours, cli("info", "zeiss-biotar-1927", "--wavelength", 486.1327, "--object-distance", 2, "--json"))


def test_the_64_wavelength_table_equals_info_spectral(cli):
    lens = lensmith.Lens.load("canon-35mm-f1.8-1956")
    theirs = cli("info", "canon-35mm-f1.8-1956", "--spectral", "--json")["spectral"]
    table = lens.spectral_table()
    assert_same_json(table.to_dict()["rows"], theirs)
    assert table.wavelength_nm.shape == (64,)
    assert table.efl_mm[10] == pytest.approx(theirs[10]["efl_mm"], rel=1e-15)


@pytest.mark.parametrize("lens_id", SHIPPED)
def test_seidel_sums_equal_seidel_json(cli, lens_id):
    lens = lensmith.Lens.load(lens_id)
    extra = [] if lens.max_field else ["--field-angle", 10]
    theirs = cli("seidel", lens_id, *extra, "--json")
    seidel = lens.seidel(field_angle_deg=None if lens.max_field else 10)
    assert_same_json(seidel.to_dict(), theirs)
    per_surface = seidel.per_surface()
    assert list(per_surface["surface"]) == [row["surface"] for row in theirs["surfaces"]]
    assert per_surface["S1"].sum() == pytest.approx(theirs["sums"]["S1"], rel=1e-9, abs=1e-12)


def test_a_zemax_file_gives_the_same_seidel_sums_as_the_command(cli):
    path = ZEMAX_DIR / "sasian_triplet.zmx"
    assert_same_json(lensmith.Lens.load(path).seidel().to_dict(), cli("seidel", path, "--json"))


@pytest.mark.parametrize("lens_id", ["smith-cooke-triplet", "angenieux-double-gauss-1953", "aspherical-fisheye"])
def test_spot_diagrams_equal_spot_json(cli, lens_id):
    lens = lensmith.Lens.load(lens_id)
    extra = [] if lens.max_field else ["--field-angle", 15]
    angle = None if lens.max_field else 15
    assert_same_json(lens.spot(field_angle_deg=angle, rings=4).to_dict(), cli("spot", lens_id, *extra, "--rings", 4, "--json"))
    assert_same_json(lens.spot(field_angle_deg=angle, random_rays=300, seed=7, aim="real").to_dict(),
                     cli("spot", lens_id, *extra, "--random", 300, "--seed", 7, "--aim", "real", "--json"))


def test_ray_fans_equal_fan_json(cli):
    lens = lensmith.Lens.load("sasian-triplet")
    assert_same_json(lens.fan(fields=[0, 1], samples=21).to_dict(), cli("fan", "sasian-triplet", "--fields", "0,1", "--samples", 21, "--json"))


@pytest.mark.parametrize("what", ["distortion", "field-curves", "focal-shift", "illumination", "pupil"])
def test_the_one_curve_analyses_equal_analyze_json(cli, what):
    lens = lensmith.Lens.load("nikon-retrofocus-1971")
    method = {"distortion": lens.distortion, "field-curves": lens.field_curves, "focal-shift": lens.focal_shift,
              "illumination": lens.illumination, "pupil": lens.pupil}[what]
    assert_same_json(method().to_dict(), cli("analyze", "nikon-retrofocus-1971", "--what", what, "--json"))


def test_report_fields_are_attributes_and_lists_of_numbers_are_arrays():
    p = lensmith.Lens.load("sasian-triplet").paraxial()
    assert p.entrance_pupil.diameter_mm == p["entrance_pupil"]["diameter_mm"]
    assert p.marginal_ray.surfaces[0].surface == 1
    d = lensmith.Lens.load("sasian-triplet").distortion()
    assert d.column("distortion_percent").dtype.kind == "f"
    with pytest.raises(AttributeError, match="efl_mm"):
        p.efl  # the message lists the fields there are
