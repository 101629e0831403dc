"""The report's results as the sections read them: the tree of ``results.json``, strictly.

The sections (:mod:`ptoverify.report.sections`) render exactly what ``results.json``
holds, so every number the report prints traces to a field of that file.  They
read it through :class:`Results`, a read-only view that has no ``get``: a field
that is not there raises :class:`MissingField` naming its full path, so a section
that asks for a misspelt or renamed field fails every test that renders the
report, and never prints "never" or a blank in its place.  A field that may be
undefined is present with the value ``None`` (JSON ``null``); a stage left out
(``--skip``) is present as ``None`` too.

Catalogue
---------
Results       strict read-only view of a JSON tree (attribute or item access)
MissingField  the error a missing field raises (a KeyError and an AttributeError)
TOP_LEVEL     the keys every ``results.json`` has, in order
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from typing import Any

__all__ = ["Results", "MissingField", "TOP_LEVEL", "wrap"]

#: The keys of every ``results.json`` (a stage left out is ``null``, never absent).
TOP_LEVEL = (
    "meta",
    "summary",
    "checks",
    "derivations",
    "ground_truth",
    "zone",
    "poles",
    "properties",
    "claims",
    "responses",
    "sweep",
    "robust",
    "proofs",
    "tuning",
    "charts",
    "skipped",
    "environment",
)


class MissingField(KeyError, AttributeError):
    """A field the report asked for is not in the results (a bug of the report)."""

    def __str__(self) -> str:
        return str(self.args[0]) if self.args else "missing field"


def wrap(value: Any, path: str = "results") -> Any:
    """Return ``value`` as the sections read it: objects as :class:`Results`, lists as tuples.

    Parameters
    ----------
    value : Any
        A JSON value (dict, list, str, number, bool or None).
    path : str
        Where it sits in the tree (for error messages).

    Returns
    -------
    Any
        :class:`Results` for an object, a tuple of wrapped items for a list, else the value.

    Examples
    --------
    >>> r = wrap({"sweep": {"grid": [2, 2]}})
    >>> r.sweep.grid
    (2, 2)
    """
    if isinstance(value, dict):
        return Results(value, path)
    if isinstance(value, (list, tuple)):
        return tuple(wrap(v, f"{path}[{i}]") for i, v in enumerate(value))
    return value


class Results:
    """A read-only, strict view of one JSON object of ``results.json``.

    ``r.name`` and ``r["name"]`` return the field (objects wrapped again, lists
    as tuples); a missing field raises :class:`MissingField` with its path.
    There is deliberately no ``get``: a default would hide a renamed field.

    Parameters
    ----------
    data : dict
        The JSON object.
    path : str
        Its place in the tree, e.g. ``results.sweep.laws``.

    Examples
    --------
    >>> r = Results({"a": {"b": 1.5}})
    >>> r.a.b, r["a"]["b"]
    (1.5, 1.5)
    >>> r.a.c
    Traceback (most recent call last):
    ...
    ptoverify.report.results.MissingField: results.a has no field 'c' (it has: b)
    """

    __slots__ = ("_data", "_path")
    _data: dict[str, Any]
    _path: str

    def __init__(self, data: dict[str, Any], path: str = "results") -> None:
        object.__setattr__(self, "_data", dict(data))
        object.__setattr__(self, "_path", path)

    def __getitem__(self, key: str) -> Any:
        try:
            value = self._data[key]
        except KeyError:
            have = ", ".join(sorted(map(str, self._data))) or "nothing"
            raise MissingField(f"{self._path} has no field {key!r} (it has: {have})") from None
        return wrap(value, f"{self._path}.{key}")

    def __getattr__(self, key: str) -> Any:
        if key.startswith("__"):
            raise AttributeError(key)
        return self[key]

    def __setattr__(self, key: str, value: Any) -> None:
        raise AttributeError(f"{self._path} is read-only")

    def __contains__(self, key: object) -> bool:
        return key in self._data

    def __iter__(self) -> Iterator[str]:
        return iter(self._data)

    def __len__(self) -> int:
        return len(self._data)

    def __bool__(self) -> bool:
        return bool(self._data)

    def __repr__(self) -> str:
        return f"Results({self._path}: {', '.join(map(str, self._data))})"

    def keys(self) -> list[str]:
        """Return the field names, in order.

        Returns
        -------
        list of str
        """
        return list(self._data)

    def items(self) -> list[tuple[str, Any]]:
        """Return (name, wrapped value) pairs, in order.

        Returns
        -------
        list of tuple
        """
        return [(k, self[k]) for k in self._data]

    def values(self) -> list[Any]:
        """Return the wrapped values, in order.

        Returns
        -------
        list
        """
        return [self[k] for k in self._data]

    @property
    def path(self) -> str:
        """Place of this object in the tree (e.g. ``results.sweep``)."""
        return self._path

    def to_json(self) -> dict[str, Any]:
        """Return a copy of the underlying JSON object.

        Returns
        -------
        dict
        """
        import copy

        return copy.deepcopy(self._data)


# A Mapping for isinstance checks (formatters print it as "k = v; ..."), without
# inheriting Mapping's ``get``: a default would hide a renamed field.
Mapping.register(Results)
