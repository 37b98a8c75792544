"""matplotlib figures of lensmith's reports, drawn like the PNGs the command writes.

Only presentation lives here: every number drawn comes from the C++ library's report. Figures are
made with ``matplotlib.figure.Figure`` (no pyplot state, no GUI backend), which a notebook shows
and ``fig.savefig()`` writes.
"""

import numpy as np


def _figure(columns, rows=1, width=3.4, height=3.2):
    from matplotlib.figure import Figure

    fig = Figure(figsize=(width * columns, height * rows), layout="constrained")
    axes = fig.subplots(rows, columns, squeeze=False)
    return fig, axes


def wavelength_colour(nm):
    """An sRGB colour for a wavelength (nm): the visible spectrum's hue, grey outside 380-780 nm."""
    if nm < 380 or nm > 780:
        return (0.4, 0.4, 0.4)
    # Piecewise-linear hue after the usual spectrum-to-RGB approximation (Bruton 1996).
    if nm < 440:
        r, g, b = (440 - nm) / 60, 0.0, 1.0
    elif nm < 490:
        r, g, b = 0.0, (nm - 440) / 50, 1.0
    elif nm < 510:
        r, g, b = 0.0, 1.0, (510 - nm) / 20
    elif nm < 580:
        r, g, b = (nm - 510) / 70, 1.0, 0.0
    elif nm < 645:
        r, g, b = 1.0, (645 - nm) / 65, 0.0
    else:
        r, g, b = 1.0, 0.0, 0.0
    # Darker where the eye is less sensitive, so that lines stay visible on white.
    return (0.85 * r, 0.75 * g, 0.85 * b)


def _field_title(field, unit):
    return f"{field.field_value:.4g} {unit}" if unit else f"field {field.relative_field:.3g}"


def spot(diagram):
    fields = diagram.fields
    fig, axes = _figure(len(fields))
    for ax, field in zip(axes[0], fields):
        for spot in field.spots:
            x_mm = np.asarray(spot.rays.x_mm, dtype=np.float64)
            if x_mm.size == 0:  # every ray of this wavelength was lost
                continue
            x_um = (x_mm - field.chief.x_mm) * 1000.0
            y_um = (np.asarray(spot.rays.y_mm, dtype=np.float64) - field.chief.y_mm) * 1000.0
            ax.plot(x_um, y_um, "+", ms=4, color=wavelength_colour(spot.wavelength_nm), label=f"{spot.wavelength_nm:.1f} nm")
        ax.set_aspect("equal", adjustable="datalim")
        rms = field.polychromatic.rms_radius_chief_um
        ax.set_title(f"{_field_title(field, diagram.field_unit)}\nRMS {rms:.3g} µm" if rms is not None else _field_title(field, diagram.field_unit))
        ax.set_xlabel("x − chief (µm)")
        ax.grid(alpha=0.3)
    axes[0][0].set_ylabel("y − chief (µm)")
    axes[0][-1].legend(fontsize="small")
    fig.suptitle(f"Spot diagram: {diagram.lens}")
    return fig


def fan(result):
    fields = result.fields
    fig, axes = _figure(2, rows=len(fields), height=2.6)
    for row, field in enumerate(fields):
        for curve in field.curves:
            colour = wavelength_colour(curve.wavelength_nm)
            t = curve.tangential
            axes[row][0].plot([s.py for s in t], [np.nan if s.ey_um is None else s.ey_um for s in t], color=colour,
                              label=f"{curve.wavelength_nm:.1f} nm")
            sg = curve.sagittal
            axes[row][1].plot([s.px for s in sg], [np.nan if s.ex_um is None else s.ex_um for s in sg], color=colour)
        axes[row][0].set_ylabel(f"{_field_title(field, result.field_unit)}\nerror (µm)")
        for ax in axes[row]:
            ax.axhline(0, color="0.5", lw=0.5)
            ax.axvline(0, color="0.5", lw=0.5)
            ax.grid(alpha=0.3)
    axes[0][0].set_title("tangential: ey against py")
    axes[0][1].set_title("sagittal: ex against px")
    axes[-1][0].set_xlabel("py")
    axes[-1][1].set_xlabel("px")
    axes[0][0].legend(fontsize="small")
    fig.suptitle(f"Ray fans: {result.lens}")
    return fig


def distortion(curve):
    fig, axes = _figure(1, width=4.5, height=4.0)
    ax = axes[0][0]
    ax.plot([p.distortion_percent for p in curve.points], [p.field_value for p in curve.points], color="k")
    ax.axvline(0, color="0.5", lw=0.5)
    ax.set_xlabel("distortion (%)")
    ax.set_ylabel(f"field ({curve.field_unit})")
    ax.set_title(f"Distortion, {curve.wavelength_nm:.1f} nm\n{curve.lens}")
    ax.grid(alpha=0.3)
    return fig


def field_curves(result):
    fig, axes = _figure(1, width=4.5, height=4.0)
    ax = axes[0][0]
    for c in result.curves:
        colour = wavelength_colour(c.wavelength_nm)
        field = np.array([p.field_value for p in c.points])
        tan = np.array([np.nan if p.tangential_mm is None else p.tangential_mm for p in c.points])
        sag = np.array([np.nan if p.sagittal_mm is None else p.sagittal_mm for p in c.points])
        ax.plot(tan, field, "--", color=colour, label=f"T {c.wavelength_nm:.1f} nm")
        ax.plot(sag, field, "-", color=colour, label=f"S {c.wavelength_nm:.1f} nm")
    ax.axvline(0, color="0.5", lw=0.5)
    ax.set_xlabel("focus − image plane (mm)")
    ax.set_ylabel(f"field ({result.field_unit})")
    ax.set_title(f"Field curves\n{result.lens}")
    ax.legend(fontsize="small")
    ax.grid(alpha=0.3)
    return fig


def focal_shift(result):
    fig, axes = _figure(1, width=4.5, height=4.0)
    ax = axes[0][0]
    ax.plot([p.shift_mm for p in result.points], [p.wavelength_nm for p in result.points], color="k")
    ax.axvline(0, color="0.5", lw=0.5)
    ax.set_xlabel("focal shift (mm)")
    ax.set_ylabel("wavelength (nm)")
    ax.set_title(f"Chromatic focal shift\n{result.lens}")
    ax.grid(alpha=0.3)
    return fig


def illumination(result):
    fig, axes = _figure(1, width=4.5, height=4.0)
    ax = axes[0][0]
    field = [p.field_value for p in result.points]
    ax.plot(field, [p.relative_illumination for p in result.points], color="k", label="relative illumination")
    ax.plot(field, [p.cos4_estimate for p in result.points], ":", color="0.4", label="cos⁴ estimate")
    ax.set_ylim(0, 1.05)
    ax.set_xlabel(f"field ({result.field_unit})")
    ax.set_ylabel("relative illumination")
    ax.set_title(f"Relative illumination, {result.wavelength_nm:.1f} nm\n{result.lens}")
    ax.legend(fontsize="small")
    ax.grid(alpha=0.3)
    return fig


def pupil(result):
    fields = result.fields
    fig, axes = _figure(len(fields))
    for ax, f in zip(axes[0], fields):
        mask = np.array([[{"#": 1.0, "x": 0.4, ".": 0.0}[c] for c in row] for row in f.mask])
        ax.imshow(mask, cmap="Greys", vmin=0, vmax=1.2, extent=(-1, 1, -1, 1))
        ax.set_title(f"{_field_title(f, result.field_unit)}\n{100 * f.area_fraction:.1f} % passes")
        ax.set_xlabel("px")
    axes[0][0].set_ylabel("py")
    fig.suptitle(f"Unvignetted pupil: {result.lens}")
    return fig


def seidel(result):
    table = result.per_surface()
    names = ["S1", "S2", "S3", "S4", "S5", "C1", "C2"]
    fig, axes = _figure(1, width=max(6.0, 0.45 * (len(table["surface"]) + 1) * len(names) / 3), height=4.0)
    ax = axes[0][0]
    n = len(table["surface"])
    positions = np.arange(n + 1)
    width = 0.8 / len(names)
    colours = ["#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2"]
    for k, name in enumerate(names):
        values = np.append(table[name], result.sums[name])
        ax.bar(positions + (k - len(names) / 2 + 0.5) * width, values, width, label=name, color=colours[k])
    ax.set_xticks(positions, [str(s) for s in table["surface"]] + ["sum"])
    ax.axhline(0, color="0.3", lw=0.5)
    ax.set_xlabel("surface")
    ax.set_ylabel("Seidel sum (mm)")
    ax.set_title(f"Seidel sums, {result.wavelength_nm:.1f} nm: {result.name}")
    ax.legend(ncol=len(names), fontsize="small")
    return fig
