#!/usr/bin/env python3
"""Regenerates the shipped lenses in lenses/ that come from other formats (pbrt, lentil).

Each is read by lensmith's own readers (`lensmith convert`), so the shipped JSON is exactly what
lensmith reads from the source file; this script then sets a readable name, the field where the
source states one, and scales patents normalised to f = 1 mm to a real focal length.
Usage: python3 tools/make_shipped_lenses.py BUILD_DIR   (after building the lensmith binary)
"""
import json
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PBRT = os.path.join(ROOT, "tests", "data", "pbrt")
LENTIL = os.path.join(ROOT, "tests", "data", "lentil", "lenses.json")

# id: (source path, name, field half-angle in degrees or None, scale-to-EFL in mm or None, extra note)
LENSES = {
    "pbrt-dgauss-50mm": (os.path.join(PBRT, "dgauss.50mm.dat"),
                         "Double Gauss f/2, 50 mm (Tronnier, US 2,673,491; pbrt dgauss.50mm)", None, None,
                         "From pbrt-v4-scenes lenses/dgauss.50mm.dat (W. J. Smith, Modern Lens Design, p. 312, scaled from 100 mm). "
                         "pbrt gives one index per element and no dispersion."),
    "pbrt-telephoto-250mm": (os.path.join(PBRT, "telephoto.250mm.dat"),
                             "Sigler super-achromat telephoto f/5.6, 250 mm (pbrt telephoto.250mm)", None, None,
                             "From pbrt-v4-scenes lenses/telephoto.250mm.dat (Modern Lens Design, p. 175, scaled from 100 mm). "
                             "pbrt gives one index per element and no dispersion."),
    "pbrt-fisheye-10mm": (os.path.join(PBRT, "fisheye.10mm.dat"),
                          "Muller fisheye 155.9 deg, 10 mm (pbrt fisheye.10mm)", None, None,
                          "From pbrt-v4-scenes lenses/fisheye.10mm.dat (Modern Lens Design, p. 164, scaled from 100 mm). "
                          "pbrt gives one index per element and no dispersion. Paraxial values of a fisheye describe only the "
                          "centre of its field."),
    "pbrt-wide-22mm": (os.path.join(PBRT, "wide.22mm.dat"),
                       "Nakamura wide angle 38 deg, 22 mm (pbrt wide.22mm)", None, None,
                       "From the pbrt-v3 scenes, lenses/wide.22mm.dat (Modern Lens Design, p. 360, scaled from 100 mm). "
                       "pbrt gives one index per element and no dispersion."),
    "angenieux-double-gauss-1953": (LENTIL + "#0001", "Angenieux double Gauss f/1.1, 100 mm (US 2,701,982, 1953)", None, None,
                                    ""),
    "meyer-primoplan-1936": (LENTIL + "#0002", "Meyer-Optik Goerlitz Primoplan f/1.5, 100 mm (DE 1387593, 1936)", None, None,
                             "A triplet-derived (Ernostar-like) fast portrait lens; the closest to a Tessar-type design in the lentil "
                             "database, which has no Tessar."),
    "petzval-portrait": (LENTIL + "#0003", "Petzval portrait lens f/3.4 (after J. Petzval, 1840)", None, None,
                         "Classical 19th-century Petzval portrait objective (J. Sasian, OPTI 517 lecture notes, Petzval portrait lens)."),
    "nikon-retrofocus-1971": (LENTIL + "#0004", "Nikon retrofocus wide angle f/2.8, 100 mm (US 3,583,791, 1971)", 37.5, None,
                              "Seven-element retrofocus wide angle; the patent states a 75 deg angle of field (half field 37.5 deg)."),
    "kodak-petzval-1948": (LENTIL + "#0006", "Kodak Petzval f/2.2, 100 mm (US 2,500,046, 1948)", None, None,
                           "Kodak's Petzval-type projection/portrait lens; heavy optical vignetting."),
    "cooke-speed-panchro-1920": (LENTIL + "#0007", "Cooke Speed Panchro (Series O) f/2, 25.4 mm (GB 157040, 1920)", None, None,
                                 "Horace W. Lee's Opic design, the origin of the Cooke Speed Panchro cine lenses."),
    "zeiss-biotar-1927": (LENTIL + "#0009", "Zeiss Biotar f/1.4, 100 mm (DE 485798, 1927)", None, None,
                          "Merte's asymmetric double Gauss."),
    "asahi-takumar-1969": (LENTIL + "#0010", "Asahi Takumar f/1.2, 100 mm (US 3,451,745, 1969)", None, None,
                           "A Biotar-derived fast double Gauss."),
    "aspherical-fisheye": (LENTIL + "#0014", "Aspherical fisheye, about 10 mm (lentil entry 0014)", None, None,
                           "Four even-aspheric surfaces; the lentil database lists no patent for it."),
    "minolta-fisheye-1978": (LENTIL + "#0015", "Minolta fisheye f/2.8, scaled to 16 mm (US 4,256,373, 1978)", None, 16.0,
                             "180 deg fisheye; the patent is normalised to f = 1 and is scaled here to f = 16 mm. Paraxial values of a "
                             "fisheye describe only the centre of its field."),
    "canon-35mm-f1.8-1956": (LENTIL + "#0016", "Canon 35 mm f/1.8 (US 2,854,890, 1956)", 30.0, 35.0,
                             "The fastest 35 mm lens of its day; the patent is normalised to f = 1 and is scaled here to f = 35 mm; "
                             "60 deg field of view."),
}


def main():
    build = sys.argv[1] if len(sys.argv) > 1 else os.path.join(ROOT, "build")
    lensmith = os.path.join(build, "lensmith")
    for lens_id, (source, name, half_field_deg, efl_mm, note) in LENSES.items():
        out = os.path.join(ROOT, "lenses", lens_id + ".json")
        cmd = [lensmith, "--quiet", "convert", source, "-o", out]
        if efl_mm:
            cmd += ["--scale-to-efl", str(efl_mm)]
        subprocess.run(cmd, check=True)
        with open(out) as f:
            lens = json.load(f)
        lens["name"] = name
        if "#" in source:  # a lentil entry: say where the numbers came from
            entry = source.rsplit("#", 1)[1]
            via = "lentil lens database entry " + entry + " (github.com/zpelgrims/lentil, MIT)"
            lens["source"] = (lens["source"] + "; via the " + via) if lens.get("source") else via
        lens["notes"] = (note + " " + lens.get("notes", "")).strip() if note else lens.get("notes", "")
        if half_field_deg is not None and "field" not in lens:
            lens["field"] = {"angle_deg": [0.0, half_field_deg * 0.7, half_field_deg]}
        # Keep the key order of lensmith's writer with name first.
        ordered = {k: lens[k] for k in ["format", "version", "name", "source", "notes"] if k in lens}
        ordered.update({k: v for k, v in lens.items() if k not in ordered and k != "surfaces"})
        ordered["surfaces"] = lens["surfaces"]
        with open(out, "w") as f:
            json.dump(ordered, f, indent=2, ensure_ascii=False)
            f.write("\n")
        print("wrote", os.path.relpath(out, ROOT))


if __name__ == "__main__":
    main()
