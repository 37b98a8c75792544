"""Records: lensmith's JSON reports as Python reads them.

The C++ library writes one JSON schema for every report (docs/cli.md); the command prints it with
--json, and this module reads the same text. A Record gives its keys as attributes and as items;
lists of numbers come back as numpy arrays (JSON's null, a number that is not finite, as NaN), lists
of objects as lists of Records. ``to_dict()`` gives the report exactly as the command's --json has it.
"""

from collections.abc import Mapping
import copy
import json
import numbers

import numpy as np


def _is_number(v):
    return v is None or (isinstance(v, numbers.Real) and not isinstance(v, bool))


def wrap(value):
    """A JSON value as a Record, a numpy array, a list of Records, or itself."""
    if isinstance(value, dict):
        return Record(value)
    if isinstance(value, list):
        if value and all(_is_number(v) for v in value):
            if all(isinstance(v, numbers.Integral) for v in value):
                return np.asarray(value, dtype=np.int64)
            return np.asarray([np.nan if v is None else v for v in value], dtype=np.float64)
        if value and all(isinstance(v, bool) for v in value):
            return np.asarray(value, dtype=bool)
        if value and all(isinstance(v, list) and v and all(_is_number(x) for x in v) for v in value):
            return np.asarray([[np.nan if x is None else x for x in v] for v in value], dtype=np.float64)
        return [wrap(v) for v in value]
    if value is None:
        return None
    return value


class Record(Mapping):
    """One JSON object of a report: ``r.efl_mm`` and ``r["efl_mm"]`` are the same value."""

    def __init__(self, data):
        object.__setattr__(self, "_data", data)

    @classmethod
    def from_json(cls, text):
        return cls(json.loads(text))

    def __getattr__(self, key):
        data = object.__getattribute__(self, "_data")
        if key.startswith("__") or key not in data:
            raise AttributeError(f"{type(self).__name__} has no field {key!r}; its fields: {', '.join(data)}")
        return wrap(data[key])

    def __setattr__(self, key, value):
        raise AttributeError("a report is read-only; to_dict() gives a copy to change")

    def __getitem__(self, key):
        return wrap(self._data[key])

    def __iter__(self):
        return iter(self._data)

    def __len__(self):
        return len(self._data)

    def __dir__(self):
        return list(super().__dir__()) + list(self._data)

    def to_dict(self):
        """The report as the command's --json has it (a deep copy)."""
        return copy.deepcopy(self._data)

    def __repr__(self):
        shown = []
        for key, value in self._data.items():
            if isinstance(value, (dict, list)):
                shown.append(f"{key}=<{type(value).__name__} of {len(value)}>")
            else:
                shown.append(f"{key}={value!r}")
        return f"{type(self).__name__}({', '.join(shown)})"


def dataframe(columns):
    """A pandas DataFrame of ``columns`` (a dict of equal-length arrays), or an ImportError that says so."""
    try:
        import pandas
    except ImportError as e:  # pandas is optional: lensmith does not require it
        raise ImportError("to_dataframe() needs pandas (Debian: apt install python3-pandas); "
                          "the same columns are available as numpy arrays without it") from e
    return pandas.DataFrame(columns)
