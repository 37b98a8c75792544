"""lensmith: real camera lenses, from prescription to bokeh, in Python.

A thin layer over lensmith's C++ libraries (the extension ``lensmith._lensmith``): every number
comes from the same code as the ``lensmith`` command, and the reports have the same fields as its
``--json`` output (docs/cli.md). Guide: docs/python.md; walkthrough: examples/python_walkthrough.py.

    >>> import lensmith
    >>> lens = lensmith.Lens.load("angenieux-double-gauss-1953")
    >>> lens.paraxial().efl_mm
    >>> lens.seidel().per_surface()["S1"]
    >>> lens.spot(fields=[0, 1]).plot()

Units are in the names: mm for lens geometry, nm for wavelengths, m for object and scene distances.
"""

import json as _json
import warnings as _warnings

import numpy as _np

from . import _lensmith
from . import _plots
from ._record import Record, dataframe as _dataframe
from ._lensmith import (  # noqa: F401  (the error types are part of the API)
    Error,
    FileError,
    LensFileError,
    GlassError,
    PrescriptionError,
    OptionsError,
    UsageError,
    ComputationError,
    IoError,
    ImageFileError,
    FitError,
    SceneError,
    SceneFileError,
)

__version__ = _lensmith.__version__
__all__ = [
    "Lens", "Surface", "Fit", "Record", "TraceResult", "lenses", "bokeh", "convert_colorspace", "read_image", "read_depth", "read_metadata", "write_image", "RAY_STATUS", "LensWarning",
    "Error", "FileError", "LensFileError", "GlassError", "PrescriptionError", "OptionsError", "UsageError", "ComputationError",
    "IoError", "ImageFileError", "FitError", "SceneError", "SceneFileError",
]

Surface = _lensmith.Surface

#: The name of each ray status code in ``TraceResult.status`` (the command's --json spelling).
RAY_STATUS = tuple(_lensmith.ray_status_names())


class LensWarning(UserWarning):
    """What a lens reader noticed but could read (a glass replaced by its nd/Vd, a crossing edge)."""


def lenses():
    """The lenses shipped with lensmith: a list of records with ``id``, ``name`` and ``source``."""
    return [Record(entry) for entry in _lensmith.lenses()]


def _warn(messages):
    for message in messages:
        _warnings.warn(message, LensWarning, stacklevel=3)


def _m(value):
    return None if value is None else float(value)


# ---- reports ------------------------------------------------------------------------------------


class _Report(Record):
    """A report that can draw itself (``plot()``, matplotlib) and write the command's PNG (``write_png``)."""

    _plot = None

    def __init__(self, data, rerun=None):
        super().__init__(data)
        object.__setattr__(self, "_rerun", rerun)

    def plot(self):
        """A matplotlib Figure of the report, drawn like the command's PNG."""
        return type(self)._plot(self)

    def write_png(self, path):
        """Writes the PNG the command writes for this analysis (the lensmith plot library's picture)."""
        self._rerun(png=str(path))


class Paraxial(Record):
    """First-order data at one wavelength and object distance: the fields of ``lensmith info --json``."""


class SpectralTable(Record):
    """First-order data at many wavelengths (``lensmith info --spectral --json``), as columns."""

    def __init__(self, rows):
        super().__init__({"rows": rows})
        object.__setattr__(self, "_columns", self._make_columns(rows))

    def columns(self):
        """A dict of numpy arrays, one per quantity, one entry per wavelength."""
        return dict(self._columns)

    @staticmethod
    def _make_columns(rows):
        def col(get):
            return _np.array([_np.nan if get(r) is None else get(r) for r in rows], dtype=_np.float64)

        out = {
            key: col(lambda r, k=key: r[k])
            for key in ("wavelength_nm", "efl_mm", "bfl_mm", "ffl_mm", "z_front_principal_mm", "z_rear_principal_mm",
                        "image_distance_mm", "magnification")
        }
        out["z_entrance_pupil_mm"] = col(lambda r: r["entrance_pupil"]["z_mm"])
        out["entrance_pupil_diameter_mm"] = col(lambda r: r["entrance_pupil"]["diameter_mm"])
        out["z_exit_pupil_mm"] = col(lambda r: r["exit_pupil"]["z_mm"])
        out["exit_pupil_diameter_mm"] = col(lambda r: r["exit_pupil"]["diameter_mm"])
        out["extrapolated"] = _np.array([r["extrapolated"] for r in rows], dtype=bool)
        return out

    def __getattr__(self, key):
        if key in ("rows",):
            return super().__getattr__(key)
        columns = object.__getattribute__(self, "_columns")
        if key in columns:
            return columns[key]
        raise AttributeError(f"SpectralTable has no column {key!r}; its columns: {', '.join(columns)}")

    def to_dataframe(self):
        """The columns as a pandas DataFrame (needs pandas)."""
        return _dataframe(self.columns())


class Seidel(_Report):
    """Seidel sums per surface and in total, and every form derived from them (``lensmith seidel --json``)."""

    _plot = _plots.seidel
    SUMS = ("S1", "S2", "S3", "S4", "S5", "C1", "C2")

    def per_surface(self, aspheric=False):
        """Per-surface sums as numpy arrays: ``surface`` (1-based) and S1..S5, C1, C2 (mm).
        ``aspheric=True``: the aspheric parts only."""
        rows = self._data["surfaces"]
        out = {"surface": _np.array([r["surface"] for r in rows], dtype=_np.int64)}
        for name in self.SUMS:
            out[name] = _np.array([(r["aspheric"] if aspheric else r)[name] for r in rows], dtype=_np.float64)
        return out

    def to_dataframe(self, aspheric=False):
        """The per-surface sums as a pandas DataFrame indexed by surface, with a 'sum' row (needs pandas)."""
        columns = self.per_surface(aspheric)
        frame = _dataframe({k: v for k, v in columns.items() if k != "surface"})
        frame.index = list(columns["surface"])
        if not aspheric:
            frame.loc["sum"] = [self._data["sums"][k] for k in self.SUMS]
        frame.index.name = "surface"
        return frame


class SpotDiagram(_Report):
    """Spot diagrams per field and wavelength (``lensmith spot --json``)."""

    _plot = _plots.spot

    def points(self, field=0, wavelength=0):
        """(x_mm, y_mm) arrays of the rays that reached the image plane, for field and wavelength indices."""
        rays = self._data["fields"][field]["spots"][wavelength]["rays"]
        return _np.asarray(rays["x_mm"], dtype=_np.float64), _np.asarray(rays["y_mm"], dtype=_np.float64)


class RayFan(_Report):
    """Tangential and sagittal ray fans (``lensmith fan --json``)."""

    _plot = _plots.fan

    def curve(self, field=0, wavelength=0, section="tangential"):
        """(pupil, error_um) arrays of one fan; NaN where the ray died."""
        samples = self._data["fields"][field]["curves"][wavelength][section]
        pupil_key, error_key = ("py", "ey_um") if section == "tangential" else ("px", "ex_um")
        pupil = _np.array([s[pupil_key] for s in samples], dtype=_np.float64)
        error = _np.array([_np.nan if s[error_key] is None else s[error_key] for s in samples], dtype=_np.float64)
        return pupil, error


class _Curve(_Report):
    """A one-curve analysis of ``lensmith analyze --json``: ``column(name)`` is one quantity over ``points``."""

    def column(self, name):
        return _np.array([_np.nan if p[name] is None else p[name] for p in self._data["points"]], dtype=_np.float64)


class Distortion(_Curve):
    _plot = _plots.distortion


class FocalShift(_Curve):
    _plot = _plots.focal_shift


class Illumination(_Curve):
    _plot = _plots.illumination


class FieldCurves(_Report):
    _plot = _plots.field_curves

    def curve(self, wavelength=0):
        """(field_value, tangential_mm, sagittal_mm) arrays for one wavelength index; NaN where not traced."""
        points = self._data["curves"][wavelength]["points"]

        def col(k):
            return _np.array([_np.nan if p[k] is None else p[k] for p in points], dtype=_np.float64)

        return col("field_value"), col("tangential_mm"), col("sagittal_mm")


class PupilShape(_Report):
    _plot = _plots.pupil


class TraceResult:
    """Rays after the lens: ``positions_mm`` (N, 3), ``directions`` (N, 3) unit vectors, ``status`` (N,)
    codes (``RAY_STATUS`` names them; 0 = ok) and ``surface`` (N,) where a ray died (1-based, 0 = ok)."""

    def __init__(self, positions_mm, directions, status, surface):
        self.positions_mm = positions_mm
        self.directions = directions
        self.status = status
        self.surface = surface

    @property
    def ok(self):
        """Boolean mask of the rays that passed the lens."""
        return self.status == 0

    def counts(self):
        """How many rays ended each way: {'ok': ..., 'vignetted': ...}."""
        values, counts = _np.unique(self.status, return_counts=True)
        return {RAY_STATUS[v]: int(c) for v, c in zip(values, counts)}

    def __len__(self):
        return len(self.status)

    def __repr__(self):
        return f"TraceResult({len(self)} rays: {self.counts()})"


# ---- lenses -------------------------------------------------------------------------------------


_REAL_RAY_DOC = """
        fields: relative fields (0 = axis, 1 = the lens's maximum field); wavelengths_nm: default the
        lens's; field_angle_deg: what relative field 1 means, when the lens has no field or to override;
        image: 'prescribed' or 'paraxial' (the image plane); aim: 'paraxial' (entrance pupil), 'real' (real stop) or None (as the lens file says)."""


class Lens:
    """A lens prescription: surfaces you can read and change, and every analysis lensmith has.

    ``Lens.load("my-lens.zmx")``, ``Lens.load("sasian-triplet")`` (a shipped lens) or
    ``Lens.from_json(dict)``; ``lens.surfaces[k]`` is surface k + 1 (``lens.surface(n)`` by number).
    """

    def __init__(self, handle):
        self._handle = handle

    @classmethod
    def load(cls, path_or_name):
        """A lens file (.json, .zmx, .seq, .dat, a lentil 'lenses.json#id') or the id of a shipped lens
        (``lensmith.lenses()``). Readers' warnings are issued as ``LensWarning``. Raises
        ``LensFileError`` (with ``file``, ``line``, ``column``), ``GlassError``, ``IoError``."""
        handle, warnings = _lensmith.Lens.load(str(path_or_name))
        _warn(warnings)
        return cls(handle)

    @classmethod
    def from_json(cls, data, name="<dict>"):
        """A lens from lensmith's native JSON (docs/lens-format.md), as a dict or as text."""
        text = data if isinstance(data, str) else _json.dumps(data, indent=2)
        handle, warnings = _lensmith.Lens.from_json_text(text, name)
        _warn(warnings)
        return cls(handle)

    def to_json(self):
        """The lens in lensmith's native JSON, as a dict (``from_json`` reads it back to an equal lens)."""
        return _json.loads(self._handle.to_json_text())

    def save(self, path):
        """Writes the native JSON file (atomically; never over the file the lens was read from: UsageError)."""
        self._handle.save(str(path))

    def copy(self):
        return Lens(self._handle.copy())

    def scaled(self, factor):
        """Every length times ``factor``."""
        return Lens(self._handle.scaled(float(factor)))

    def check(self):
        """Raises PrescriptionError / GlassError if the lens (as changed) is not a valid system."""
        self._handle.check()

    # -- what the prescription says
    name = property(lambda self: self._handle.name, lambda self, v: setattr(self._handle, "name", v))
    source = property(lambda self: self._handle.source)
    origin = property(lambda self: self._handle.origin, doc="The path or shipped name it was loaded from.")
    object_distance_mm = property(lambda self: self._handle.object_distance_mm,
                                  lambda self, v: setattr(self._handle, "object_distance_mm", float(v)))
    wavelengths_nm = property(lambda self: list(self._handle.wavelengths_nm))
    primary_wavelength_nm = property(lambda self: self._handle.primary_wavelength_nm)
    aperture = property(lambda self: self._handle.aperture, doc="(kind, value) of the aperture specification.")
    max_field = property(lambda self: self._handle.max_field, doc="(value, unit) of the maximum field, or None.")

    @property
    def surfaces(self):
        """The surfaces, object side first; each is a view: changing it changes the lens."""
        return [_lensmith.Lens.surface(self._handle, n) for n in range(1, self._handle.surface_count() + 1)]

    def surface(self, number):
        """Surface ``number`` (1-based, as in the command's listings)."""
        return _lensmith.Lens.surface(self._handle, number)

    def __len__(self):
        return self._handle.surface_count()

    def __eq__(self, other):
        return isinstance(other, Lens) and self._handle == other._handle

    def __str__(self):
        return str(self._handle)

    def __repr__(self):
        return f"<lensmith.Lens {self.name!r}, {len(self)} surfaces>"

    # -- first and third order
    def paraxial(self, wavelength_nm=None, object_distance_m=None):
        """First-order data (``lensmith info --json``): efl_mm, bfl_mm, pupils, f_number, ray tables...
        object_distance_m: from the object to surface 1 (inf = infinity); default the lens's."""
        return Paraxial.from_json(self._handle.paraxial_json(_m(wavelength_nm), _m(object_distance_m)))

    def spectral_table(self, object_distance_m=None, samples=64, min_wavelength_nm=380.0, max_wavelength_nm=780.0):
        """First-order data at ``samples`` wavelengths (``lensmith info --spectral``) as numpy columns."""
        text = self._handle.spectral_json(_m(object_distance_m), int(samples), float(min_wavelength_nm), float(max_wavelength_nm))
        return SpectralTable(_json.loads(text))

    def seidel(self, wavelength_nm=None, object_distance_m=None, field_angle_deg=None, epd_mm=None, f_number=None):
        """Seidel sums (``lensmith seidel --json``); ``per_surface()`` as numpy arrays, ``to_dataframe()``."""
        handle = self._handle.copy()
        args = dict(wavelength_nm=_m(wavelength_nm), object_distance_m=_m(object_distance_m), field_angle_deg=_m(field_angle_deg),
                    epd_mm=_m(epd_mm), f_number=_m(f_number))
        return Seidel(_json.loads(handle.seidel_json(**args)), lambda png: handle.seidel_json(**args, png=png))

    # -- real rays
    def trace(self, origins_mm, directions, wavelengths_nm=None, direction="forward", image="prescribed",
              image_distance_mm=None, clip_apertures=True, out=None):
        """Exact rays through the lens, many at once (the batch tracer, on every core, GIL released).

        origins_mm, directions: float64 arrays (N, 3) in the lens frame (z = 0 at surface 1, +z toward
        the image; directions unit vectors); wavelengths_nm: a number or a float64 array (N,), default
        the primary wavelength. direction 'forward' (object side to the image plane) or 'backward'
        (from the image side, travelling -z, to surface 1). out: a TraceResult of as many rays whose
        arrays are reused (written over and returned): in a loop, it saves allocating the outputs."""
        if wavelengths_nm is None:
            wavelengths_nm = self.primary_wavelength_nm
        elif isinstance(wavelengths_nm, (int, float, _np.floating, _np.integer)):
            wavelengths_nm = float(wavelengths_nm)
        reuse = None if out is None else (out.positions_mm, out.directions, out.status, out.surface)
        arrays = _lensmith.trace(self._handle, origins_mm, directions, wavelengths_nm, direction, image, _m(image_distance_mm),
                                 bool(clip_apertures), reuse)
        if out is not None:
            return out
        return TraceResult(*arrays)

    def _real(self, fields, wavelengths_nm, field_angle_deg, image, aim):
        return dict(fields=[float(f) for f in fields], wavelengths_nm=[float(w) for w in (wavelengths_nm or [])],
                    field_angle_deg=_m(field_angle_deg), image=image, aim=aim or "")

    def spot(self, fields=(0.0, 0.7, 1.0), wavelengths_nm=None, field_angle_deg=None, image="prescribed", aim=None,
             rings=6, random_rays=None, seed=1):
        """Spot diagrams (``lensmith spot --json``): hexapolar ``rings``, or ``random_rays`` uniform pupil points."""
        handle = self._handle.copy()
        args = dict(self._real(fields, wavelengths_nm, field_angle_deg, image, aim), rings=int(rings),
                    random_rays=None if random_rays is None else int(random_rays), seed=int(seed))
        return SpotDiagram(_json.loads(_lensmith.spot_json(handle, **args)), lambda png: _lensmith.spot_json(handle, **args, png=png))

    def fan(self, fields=(0.0, 0.7, 1.0), wavelengths_nm=None, field_angle_deg=None, image="prescribed", aim=None, samples=41):
        """Tangential and sagittal ray fans (``lensmith fan --json``), ``samples`` pupil points each (odd)."""
        handle = self._handle.copy()
        args = dict(self._real(fields, wavelengths_nm, field_angle_deg, image, aim), samples=int(samples))
        return RayFan(_json.loads(_lensmith.fan_json(handle, **args)), lambda png: _lensmith.fan_json(handle, **args, png=png))

    def _analyze(self, cls, what, fields=(0.0, 0.7, 1.0), wavelengths_nm=None, field_angle_deg=None, image="prescribed",
                 aim=None, samples=None, grid=None):
        handle = self._handle.copy()
        args = dict(self._real(fields, wavelengths_nm, field_angle_deg, image, aim), samples=None if samples is None else int(samples),
                    grid=None if grid is None else int(grid))
        return cls(_json.loads(_lensmith.analyze_json(handle, what, **args)),
                   lambda png: _lensmith.analyze_json(handle, what, **args, png=png))

    def distortion(self, wavelengths_nm=None, field_angle_deg=None, image="prescribed", aim=None, samples=None):
        """Distortion against field (``lensmith analyze --what distortion --json``), ``samples`` fields."""
        return self._analyze(Distortion, "distortion", wavelengths_nm=wavelengths_nm, field_angle_deg=field_angle_deg, image=image,
                             aim=aim, samples=samples)

    def field_curves(self, wavelengths_nm=None, field_angle_deg=None, image="prescribed", aim=None, samples=None):
        """Tangential and sagittal field curves (``lensmith analyze --what field-curves --json``)."""
        return self._analyze(FieldCurves, "field-curves", wavelengths_nm=wavelengths_nm, field_angle_deg=field_angle_deg,
                             image=image, aim=aim, samples=samples)

    def focal_shift(self, wavelengths_nm=None, samples=None):
        """Chromatic focal shift (``lensmith analyze --what focal-shift --json``)."""
        return self._analyze(FocalShift, "focal-shift", wavelengths_nm=wavelengths_nm, samples=samples)

    def illumination(self, wavelengths_nm=None, field_angle_deg=None, image="prescribed", aim=None, samples=None, grid=None):
        """Relative illumination against field (``lensmith analyze --what illumination --json``)."""
        return self._analyze(Illumination, "illumination", wavelengths_nm=wavelengths_nm, field_angle_deg=field_angle_deg,
                             image=image, aim=aim, samples=samples, grid=grid)

    def pupil(self, fields=(0.0, 0.7, 1.0), wavelengths_nm=None, field_angle_deg=None, image="prescribed", aim=None, grid=None):
        """The unvignetted pupil per field (``lensmith analyze --what pupil --json``)."""
        return self._analyze(PupilShape, "pupil", fields, wavelengths_nm, field_angle_deg, image, aim, grid=grid)

    for _method in (spot, fan, distortion, field_curves, illumination, pupil):
        _method.__doc__ += _REAL_RAY_DOC
    del _method

    # -- fits
    def fit(self, degree=7, terms=0, training_rays=30000, test_rays=10000, seed=2016, image_radius_mm=None, f_number=None):
        """A polynomial fit of the lens's ray mapping (``lensmith fit``), for ``bokeh(model='poly', fit=...)``."""
        return Fit(_lensmith.Fit.fit(self._handle, int(degree), int(terms), int(training_rays), int(test_rays), int(seed),
                                     _m(image_radius_mm), _m(f_number)))


class Fit:
    """A polynomial fit of a lens (``lensmith fit``): ``report`` has the fields of ``lensmith fit --json``."""

    def __init__(self, native):
        self._native = native

    @classmethod
    def load(cls, path):
        """Reads a lensmith-fit JSON file (``lensmith fit -o`` or ``Fit.save``)."""
        return cls(_lensmith.Fit.load(str(path)))

    def save(self, path):
        """Writes the fit file (atomically)."""
        self._native.save(str(path))

    @property
    def report(self):
        return Record.from_json(self._native.report_json())

    def check_matches(self, lens):
        """Raises if ``lens`` is not the lens this fit was made of (its hash of radii, glasses, apertures)."""
        self._native.check_matches(lens._handle)

    lens_name = property(lambda self: self._native.lens_name)
    symmetry = property(lambda self: self._native.symmetry,
                        doc="'rotational', or 'section mirrors' for an anamorphic lens (its x and y fitted apart)")

    def __repr__(self):
        return repr(self._native)


# ---- bokeh --------------------------------------------------------------------------------------


def bokeh(image, depth, lens=None, *, thin_lens_focal_length_mm=None, fstop=None, focus_m=None, focus_pixel=None, model=None,
          method=None, seidel_coefficients=None, fit=None, sensor_width_mm=None, pinhole_focal_length_mm=None, hfov_deg=None,
          depth_kind=None, depth_unit=None, invalid_depth=None, blades=None, blade_rotation_deg=None, aperture_mask=None,
          vignetting=None, spectral=None, spectral_samples=None, threads=None,
          hidden=None, edge_pixels=None, layer_spacing_px=None, subrows=None, max_blur_px=None,
          samples=None, layers=None, ray_grid_px=None, cone_tracing=None,
          views=None, mip_filter=None,
          circular_splats=None, level_of_detail=None,
          rings=None, median=None, scene=None, trace_rays=None,
          input_colorspace=None, output_colorspace=None, ocio=None, working_colorspace=None):
    """Photographs an all-in-focus picture with its depth through a lens (``lensmith bokeh``).

    image: float32 (H, W, 3), linear scene-referred RGB (Rec.709 primaries); depth: float32 (H, W),
    planar depth in metres by default (``depth_kind`` 'z' | 'distance' | 'inverse', ``depth_unit``
    'm' | 'cm' | 'mm', ``invalid_depth`` 'error' | 'far' | 'near'). Returns float32 (H, W, 3).

    lens: a Lens, a file or a shipped lens name; or ``thin_lens_focal_length_mm`` for an ideal thin
    lens. fstop (default the lens's own), focus_m (metres from the entrance pupil) or focus_pixel
    (x, y). model: 'thin' | 'paraxial' | 'seidel' (default) | 'poly' | 'exact'; fit: a Fit or fit
    file for 'poly'. method: 'scatter' (default) | 'multiview' | 'lightfield' | 'ewa' | 'gather'.
    Every other keyword is the command's option of the same name (docs/cli.md, docs/python.md);
    options of another method than the one chosen are an error, as on the command line.

    input_colorspace / output_colorspace: the picture's colour space and the result's in an
    OpenColorIO config (``ocio``, default $OCIO), as ``--input-colorspace``/``--output-colorspace``
    (docs/color-management.md); the result is in the input's colour space unless output_colorspace
    says otherwise.
    """
    options = {k: v for k, v in dict(
        thin_lens_focal_length_mm=thin_lens_focal_length_mm, fstop=fstop, focus_m=focus_m, model=model, method=method,
        seidel_coefficients=seidel_coefficients, sensor_width_mm=sensor_width_mm, pinhole_focal_length_mm=pinhole_focal_length_mm,
        hfov_deg=hfov_deg, depth_kind=depth_kind, depth_unit=depth_unit, invalid_depth=invalid_depth, blades=blades,
        blade_rotation_deg=blade_rotation_deg, aperture_mask=aperture_mask, vignetting=vignetting, spectral=spectral,
        spectral_samples=spectral_samples, threads=threads, hidden=hidden, edge_pixels=edge_pixels, layer_spacing_px=layer_spacing_px,
        subrows=subrows, max_blur_px=max_blur_px, samples=samples, layers=layers, ray_grid_px=ray_grid_px, cone_tracing=cone_tracing,
        views=views, mip_filter=mip_filter, circular_splats=circular_splats, level_of_detail=level_of_detail, rings=rings,
        median=median, trace_rays=trace_rays).items() if v is not None}
    if focus_pixel is not None:
        options["focus_pixel"] = tuple(int(v) for v in focus_pixel)
    if scene is not None:
        options["scene"] = str(scene)
    if lens is not None:
        options["lens"] = lens._handle if isinstance(lens, Lens) else str(lens)
    if fit is not None:
        options["fit"] = fit._native if isinstance(fit, Fit) else str(fit)
    if input_colorspace is None and output_colorspace is None:
        if ocio is not None or working_colorspace is not None:
            raise OptionsError("ocio / working_colorspace convert nothing without input_colorspace or output_colorspace")
        return _lensmith.bokeh(image, depth, options)
    if output_colorspace is None:
        output_colorspace = input_colorspace
    if input_colorspace is not None:
        image = convert_colorspace(image, input_colorspace, None, ocio=ocio, working_colorspace=working_colorspace)
    out = _lensmith.bokeh(image, depth, options)
    return convert_colorspace(out, None, output_colorspace, ocio=ocio, working_colorspace=working_colorspace)


def convert_colorspace(image, from_colorspace, to_colorspace, *, ocio=None, working_colorspace=None):
    """float32 (H, W, 3) from one colour space of an OpenColorIO config to another, as ``lensmith bokeh``
    converts its input and output (docs/color-management.md). None for either side is lensmith's
    working space, linear Rec.709. ocio: the config file (default $OCIO); working_colorspace: the
    config's linear Rec.709 when it has no aces_interchange role."""
    return _lensmith.convert_colorspace(image, from_colorspace or "", to_colorspace or "", str(ocio) if ocio else "",
                                        working_colorspace or "")


# ---- pictures -----------------------------------------------------------------------------------


def read_image(path):
    """A picture file as linear Rec.709 RGB, float32 (H, W, 3), as ``lensmith bokeh --image`` reads it
    (EXR, TIFF, PNG, JPEG, HDR, PFM, ...; 8/16-bit files are sRGB-decoded)."""
    return _lensmith.read_image(str(path))


def read_depth(path):
    """A depth channel as planar depth in metres, float32 (H, W), as ``--depth FILE[:CHANNEL]`` reads it
    (default channel Z, depth.Z or a layer's Depth.Z; +inf = infinitely far)."""
    return _lensmith.read_depth(str(path))


def read_metadata(path):
    """A picture file's attributes as strings ({'lensmith:focal_length_mm': '50', ...}). lensmith's own
    renders record their pinhole framing there; ``bokeh`` needs it as ``pinhole_focal_length_mm`` and
    ``sensor_width_mm`` (the command reads it from the file itself)."""
    return _lensmith.read_metadata(str(path))


def write_image(path, image):
    """Writes float32 (H, W, 3) linear RGB: .exr as float, .png/.jpg/.tif as sRGB (atomically)."""
    _lensmith.write_image(str(path), image)
