#!/usr/bin/env python3
"""Convert the refractiveindex.info glass catalogues (YAML, CC0) into lensmith's compact JSON.

Input: the vendor folders of the refractiveindex.info database `database/data/specs/<vendor>/`
(github.com/polyanskiy/refractiveindex.info-database; M. N. Polyanskiy, Sci. Data 11, 94 (2024)),
one YAML file per glass. Output: one JSON file per vendor, `lenses/glass/<vendor>.json`, in the
format described in docs/glass.md ("lensmith-glass-catalog", version 1).

Rules (docs/glass.md and lenses/glass/README.md explain them):
  * The glass name is the YAML file name without `.yml` (N-BK7.yml -> "N-BK7"), except that a
    trailing "star" is the database's file-safe spelling of "*" (CDGM H-K9Lstar.yml -> "H-K9L*",
    the name CDGM and Zemax files use).
  * Only the first DATA entry of type `formula 1`, `formula 2` or `formula 3` is kept; tabulated
    k (and tabulated n) are dropped. A file without such an entry is skipped and reported.
  * Numbers are copied as the exact text of the YAML (coefficients, wavelength range, nd, Vd), so
    the JSON holds the catalogue's digits, not a re-rounded float.
  * Sub-folders are read in a fixed order per vendor (VENDORS below). If two files of one vendor
    have the same name ignoring case, the one in the earlier sub-folder wins (and, inside one
    sub-folder, the one whose file name sorts first); the loser is reported.
  * status is the vendor's Zemax AGF status (0 standard, 1 preferred, 2 obsolete, 3 special).
    The database's PROPERTIES.glass_status is that code shifted by one (its "standard" is AGF 1,
    its "preferred" AGF 2, its "special" AGF 3, and AGF 0 is left out); see DATABASE_STATUS.
    Besides, "obsolete" is set for the Schott `obsolete/` folder, for a comment "obsolet(e)" or
    "was replaced by X" (then also "replaced_by": "X"), and for a HOYA comment announcing
    discontinuation. A file that is not from an AGF catalogue and gives no status is
    "unspecified".

Usage: tools/convert_glass_catalogs.py [--source DIR] [--output DIR]
Requires python3 and PyYAML.
"""

import argparse
import json
import math
import re
import sys
from pathlib import Path

import yaml

DATABASE = "refractiveindex.info database (github.com/polyanskiy/refractiveindex.info-database)"
COMMIT = "ff11b5897ef0754b15d939d921eb6c745693cbd1"
COMMIT_DATE = "2026-06-14"
LICENCE = "CC0 1.0"

# (folder, vendor name as lensmith shows it, sub-folders in priority order). A sub-folder that
# exists in the source but is not listed here is an error, so that a newer database cannot lose
# glasses silently.
VENDORS = [
    ("schott", "SCHOTT", ["optical", "obsolete", "misc", "infrared"]),
    ("ohara", "OHARA", ["optical"]),
    ("hoya", "HOYA", ["optical"]),
    ("cdgm", "CDGM", ["optical"]),
    ("hikari", "HIKARI", ["optical", "i-line", "CaF", "SiO2"]),
    ("sumita", "SUMITA", ["optical"]),
]

# A JSON number literal (RFC 8259 section 6). Every number we copy must already be one.
JSON_NUMBER = re.compile(r"-?(0|[1-9][0-9]*)(\.[0-9]+)?([eE][+-]?[0-9]+)?")
# Characters that occur in real catalogue names: N-BK7, K-CaFK95(M), FDS90(P), H-K9Lstar.
GLASS_NAME = re.compile(r"[A-Za-z0-9][A-Za-z0-9+\-().*]*")
# PROPERTIES.glass_status -> the AGF status it stands for. Evidence for the shift: every Schott
# glass commented "was replaced by N-..." (SF15, LASFN9, ...) is labelled "preferred", as are the
# lead-containing glasses that Hikari, CDGM and OHARA have discontinued (SF5, F2, BAH10, ...); HOYA
# glasses commented "Recommended glass type" are labelled "standard"; current glasses (N-BK7 is
# "standard", J-BK7A has no label) would otherwise all be standard or obsolete.
DATABASE_STATUS = {None: "standard", "standard": "preferred", "preferred": "obsolete", "special": "special"}


class ConversionError(Exception):
    pass


def mapping(node, where):
    if not isinstance(node, yaml.MappingNode):
        raise ConversionError(f"{where}: expected a mapping")
    return {key.value: value for key, value in node.value}


def number_tokens(node, where):
    """The whitespace-separated number tokens of a YAML scalar, exactly as written."""
    if not isinstance(node, yaml.ScalarNode):
        raise ConversionError(f"{where}: expected a scalar")
    tokens = node.value.split()
    for token in tokens:
        if not JSON_NUMBER.fullmatch(token) or not math.isfinite(float(token)):
            raise ConversionError(f"{where}: {token!r} is not a finite JSON number")
    return tokens


def plain_text(node):
    if node is None or not isinstance(node, yaml.ScalarNode):
        return ""
    return re.sub(r"<[^>]*>", "", node.value).strip()


def catalogue_reference(references):
    """The vendor catalogue a file came from, e.g. 'SCHOTT Zemax catalog 2017-01-20b'."""
    match = re.search(r"[A-Z]+ Zemax catalog [0-9-]+[a-z]?", references)
    return match.group(0) if match else references.split("(")[0].strip()


def check_name_in_references(name, references, where):
    """Where a file cites a single-glass data sheet, that sheet must be for this glass."""
    match = re.search(r"(?:SCHOTT\s+(\S+)\s+glass data sheet)|(?:Glasses\s*-\s*(IRG\s*\d+))", references)
    if not match:
        return False
    cited = (match.group(1) or match.group(2)).replace(" ", "")
    if cited.upper() != name.upper():
        raise ConversionError(f"{where}: file name {name!r} but the reference cites {cited!r}")
    return True


def check_glass_code(name, code, nd, vd, where, notes):
    """glass_code NNNVVV is round(1000 (nd - 1)), round(10 Vd): a check that nd and Vd are this file's."""
    if code is None or nd is None or vd is None:
        return
    digits = code.value.split(".")[0]
    if len(digits) != 6 or not digits.isdigit():
        raise ConversionError(f"{where}: glass_code {code.value!r} is not NNNVVV")
        return
    # Vendors truncate or round (a difference of one in the last digit is either); for nd >= 2 the
    # code keeps only three digits of nd - 1 (E-FDS3, nd 2.1042: code 104).
    nd_digits = 1000 * (float(nd) - 1) % 1000
    if abs(int(digits[:3]) - nd_digits) > 1.0 or abs(int(digits[3:]) - 10 * float(vd)) > 1.0:
        notes.append("glass_code mismatch: " + name)


def read_glass(path, group, vendor_folder, notes):
    """One YAML file -> (glass dict with number tokens, reference text) or (None, reason)."""
    where = f"{vendor_folder}/{group}/{path.name}"
    name = re.sub(r"star$", "*", path.stem)
    if not GLASS_NAME.fullmatch(name):
        raise ConversionError(f"{where}: {name!r} does not look like a glass name")
    with path.open(encoding="utf-8") as stream:
        root = mapping(yaml.compose(stream), where)

    data = root.get("DATA")
    if not isinstance(data, yaml.SequenceNode):
        return None, "no DATA list"
    formula_entry = None
    kinds = []
    for item in data.value:
        entry = mapping(item, where + " DATA")
        kind = entry["type"].value
        kinds.append(kind)
        if formula_entry is None and kind in ("formula 1", "formula 2", "formula 3"):
            formula_entry = entry
    if formula_entry is None:
        return None, "no formula 1/2/3 entry (DATA has: " + ", ".join(kinds) + ")"

    formula = int(formula_entry["type"].value.split()[1])
    coefficients = number_tokens(formula_entry["coefficients"], where + " coefficients")
    if len(coefficients) % 2 != 1:
        raise ConversionError(f"{where}: {len(coefficients)} coefficients; formula {formula} needs C1 and pairs")
    range_um = number_tokens(formula_entry["wavelength_range"], where + " wavelength_range")
    if len(range_um) != 2 or not 0 < float(range_um[0]) < float(range_um[1]):
        raise ConversionError(f"{where}: wavelength_range {range_um} is not 'min max' with 0 < min < max")

    properties = mapping(root["PROPERTIES"], where) if "PROPERTIES" in root else {}
    nd = number_tokens(properties["nd"], where + " nd")[0] if "nd" in properties else None
    vd = number_tokens(properties["Vd"], where + " Vd")[0] if "Vd" in properties else None
    if (nd is None) != (vd is None):
        raise ConversionError(f"{where}: has only one of nd and Vd")
    check_glass_code(name, properties.get("glass_code"), nd, vd, where, notes)

    references = plain_text(root.get("REFERENCES"))
    comments = plain_text(root.get("COMMENTS"))
    if check_name_in_references(name, references, where):
        notes.append("name confirmed by its data sheet: " + name)

    label = properties["glass_status"].value if "glass_status" in properties else None
    if label not in DATABASE_STATUS:
        raise ConversionError(f"{where}: unknown glass_status {label!r}")
    from_agf = "Zemax catalog" in references
    status = DATABASE_STATUS[label] if from_agf or label is not None else "unspecified"
    replaced_by = None
    replaced = re.search(r"was replaced by\s+(\S+)", comments)
    if group == "obsolete" or re.search(r"\bobsolete?\b", comments) or replaced:
        status = "obsolete"
        replaced_by = replaced.group(1) if replaced else None
    elif vendor_folder == "hoya" and "discontinuation" in comments:
        status = "obsolete"

    glass = {"name": name, "formula": formula, "coefficients": coefficients, "range_um": range_um}
    if nd is not None:
        glass["nd"] = nd
        glass["vd"] = vd
    glass["status"] = status
    if replaced_by:
        glass["replaced_by"] = replaced_by
    return glass, catalogue_reference(references)


def glass_line(glass):
    """One glass as a single-line JSON object, numbers written with their catalogue digits."""
    parts = [f'"name":{json.dumps(glass["name"])}', f'"formula":{glass["formula"]}',
             '"coefficients":[' + ",".join(glass["coefficients"]) + "]",
             '"range_um":[' + ",".join(glass["range_um"]) + "]"]
    if "nd" in glass:
        parts += [f'"nd":{glass["nd"]}', f'"vd":{glass["vd"]}']
    parts.append(f'"status":{json.dumps(glass["status"])}')
    if "replaced_by" in glass:
        parts.append(f'"replaced_by":{json.dumps(glass["replaced_by"])}')
    return "{" + ",".join(parts) + "}"


def convert_vendor(source, folder, vendor, groups, output):
    vendor_dir = source / folder
    present = sorted(p.name for p in vendor_dir.iterdir() if p.is_dir())
    unknown = [g for g in present if g not in groups]
    if unknown:
        raise ConversionError(f"{folder}: sub-folders {unknown} are not in VENDORS; decide whether to include them")

    notes = []
    glasses = []
    seen = {}  # upper-case name -> where it came from
    references = {}
    skipped = []
    for group in groups:
        group_dir = vendor_dir / group
        if not group_dir.is_dir():
            continue
        for path in sorted(group_dir.glob("*.yml")):
            glass, detail = read_glass(path, group, folder, notes)
            if glass is None:
                skipped.append(f"{folder}/{group}/{path.name}: {detail}")
                continue
            key = glass["name"].upper()
            if key in seen:
                skipped.append(f"{folder}/{group}/{path.name}: name clash with {seen[key]} (the earlier one is kept)")
                continue
            seen[key] = f"{folder}/{group}/{path.name}"
            references[detail] = references.get(detail, 0) + 1
            glasses.append(glass)

    sources = ", ".join(sorted(references, key=lambda r: -references[r]))
    header = {
        "format": "lensmith-glass-catalog",
        "version": 1,
        "vendor": vendor,
        "source": f"{DATABASE}, commit {COMMIT} ({COMMIT_DATE}), database/data/specs/{folder}/ "
                  f"({', '.join(g for g in groups if (vendor_dir / g).is_dir())}); from {sources}",
        "licence": LICENCE,
    }
    head = ",".join(f"{json.dumps(k)}:{json.dumps(v)}" for k, v in header.items())
    text = "{" + head + ',"glasses":[\n' + ",\n".join(glass_line(g) for g in glasses) + "\n]}\n"

    # The file must read back as JSON with exactly the numbers of the YAML.
    parsed = json.loads(text)
    for written, glass in zip(parsed["glasses"], glasses):
        assert written["name"] == glass["name"]
        assert [float(x) for x in written["coefficients"]] == [float(t) for t in glass["coefficients"]]
        assert [float(x) for x in written["range_um"]] == [float(t) for t in glass["range_um"]]

    out = output / f"{folder}.json"
    out.write_text(text, encoding="utf-8")
    counts = {}
    for g in glasses:
        counts[g["status"]] = counts.get(g["status"], 0) + 1
    status_text = ", ".join(f"{n} {s}" for s, n in sorted(counts.items()))
    print(f"{vendor:7s} {len(glasses):4d} glasses -> {out} ({status_text})")
    for line in skipped:
        print(f"        skipped {line}")
    for kind in ("name confirmed by its data sheet", "glass_code mismatch"):
        names = [n.split(": ", 1)[1] for n in notes if n.startswith(kind)]
        if names:
            # Mould-glass variants (OHARA ...P, SUMITA ...(M)) carry the code of their parent glass.
            print(f"        note: {kind} ({len(names)}): {' '.join(names)}")
    return len(glasses)


def main():
    repo = Path(__file__).resolve().parent.parent
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--source", type=Path, default=Path("/work/shared/lens-data/glass"),
                        help="folder holding schott/, ohara/, ... from database/data/specs/")
    parser.add_argument("--output", type=Path, default=repo / "lenses" / "glass",
                        help="where <vendor>.json are written (default: lenses/glass)")
    args = parser.parse_args()
    args.output.mkdir(parents=True, exist_ok=True)
    try:
        total = sum(convert_vendor(args.source, folder, vendor, groups, args.output)
                    for folder, vendor, groups in VENDORS)
    except ConversionError as error:
        print(f"convert_glass_catalogs: {error}", file=sys.stderr)
        return 1
    print(f"total   {total:4d} glasses")
    return 0


if __name__ == "__main__":
    sys.exit(main())
