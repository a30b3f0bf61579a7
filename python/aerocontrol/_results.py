"""What the result objects share: equality, the JSON form, and how a notebook shows them.

:class:`Result` is the base of aerocontrol's result classes (frozen dataclasses, and the
core's :class:`~aerocontrol.Placement` through :func:`attach`). It gives them

* ``==`` field by field, arrays compared by shape, dtype kind and value with NaN equal to NaN
  (``numpy.array_equal(..., equal_nan=True)``), floats likewise, nested results, tuples and
  dicts recursively; so a result that went through :mod:`pickle` (multiprocessing, Dask)
  compares equal to the one sent. Results hold arrays, so they are not hashable;
* :meth:`Result.to_dict` and :meth:`Result.from_dict`: a form made of plain Python types that
  :func:`json.dumps` writes as strict JSON (no NaN or Infinity tokens), read back to an equal
  object (the encoding is described under :meth:`Result.to_dict`);
* ``_repr_html_`` and ``_repr_markdown_`` for Jupyter: the tables the class's ``_tables``
  gives, the cells formatted as its text ``table()`` or ``str()`` formats them, every string
  escaped (:func:`html_table`, :func:`markdown_table`).
"""

from __future__ import annotations

import base64
import dataclasses
import html
import math
from collections.abc import Callable, Iterable, Mapping, Sequence
from typing import Any, ClassVar, NamedTuple, TypeVar

import numpy as np

from .exceptions import InvalidArgumentError

__all__ = [
    "Result",
    "Tabular",
    "attach",
    "decode",
    "encode",
    "field_names",
    "format_complex",
    "format_number",
    "from_fields",
    "html_table",
    "markdown_table",
    "register",
    "register_model",
    "same",
    "set_at_once",
]

_NON_FINITE = {"NaN": math.nan, "Infinity": math.inf, "-Infinity": -math.inf}

#: The classes :meth:`Result.from_dict` may build, by name: the results and the records they
#: hold (filled in by :func:`register`), each class's name, and for a class that is not a
#: dataclass its fields and how it is built from them.
_REGISTRY: dict[str, type] = {}
_NAMES: dict[type, str] = {}
_FIELDS: dict[type, tuple[str, ...]] = {}
_BUILDERS: dict[type, Callable[[Mapping[str, Any]], Any]] = {}

T = TypeVar("T")


def register(
    cls: type[T],
    name: str | None = None,
    fields: tuple[str, ...] | None = None,
    build: Callable[[Mapping[str, Any]], T] | None = None,
) -> type[T]:
    """Let :meth:`Result.from_dict` build ``cls`` by ``name`` (its class name by default; a
    record whose class name another class has needs its own). A class that is not a dataclass
    gives its ``fields`` (what ``==`` compares and the JSON form holds) and ``build``, which
    makes an instance from them."""
    name = cls.__name__ if name is None else name
    if _REGISTRY.get(name, cls) is not cls:
        raise RuntimeError(f"two result classes named {name!r}")  # pragma: no cover
    _REGISTRY[name] = cls
    _NAMES[cls] = name
    if fields is not None:
        _FIELDS[cls] = fields
    if build is not None:
        _BUILDERS[cls] = build
    return cls


# ----- formatting -----------------------------------------------------------------------------


def format_number(value: float, digits: int = 4) -> str:
    """``value`` to ``digits`` significant digits; "-" for NaN, "∞" or "-∞" for infinities."""
    if not math.isfinite(value):
        return "-" if math.isnan(value) else ("∞" if value > 0 else "-∞")
    return f"{value:.{digits}g}"


def format_complex(value: complex, digits: int = 5) -> str:
    """``value`` as "a + bj" or "a - bj" to ``digits`` significant digits; a real one as "a"."""
    if value.imag == 0.0:
        return f"{value.real:.{digits}g}"
    sign = "+" if value.imag > 0 else "-"
    return f"{value.real:.{digits}g} {sign} {abs(value.imag):.{digits}g}j"


class Tabular(NamedTuple):
    """One table of a result as text cells: a title, the column names, the rows, and notes
    printed under it; or, with ``text``, preformatted text instead of the table."""

    title: str
    header: Sequence[str]
    rows: Sequence[Sequence[str]]
    notes: Sequence[str] = ()
    text: str = ""


def html_table(header: Sequence[str], rows: Iterable[Sequence[str]]) -> str:
    """An HTML table of text cells, every cell escaped."""
    escape = html.escape
    head = "".join(f"<th>{escape(cell)}</th>" for cell in header)
    body = "".join(
        "<tr>" + "".join(f"<td>{escape(cell)}</td>" for cell in row) + "</tr>" for row in rows
    )
    return f"<table><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>"


def markdown_table(header: Sequence[str], rows: Iterable[Sequence[str]]) -> str:
    """A Markdown (GitHub) table of text cells; ``|`` in a cell is escaped."""

    def line(cells: Sequence[str]) -> str:
        return "| " + " | ".join(cell.replace("|", "\\|") for cell in cells) + " |"

    lines = [line(header), "|" + "|".join(" --- " for _ in header) + "|"]
    lines += [line(row) for row in rows]
    return "\n".join(lines)


def _longest_run(text: str, character: str) -> int:
    """The length of the longest run of ``character`` in ``text``."""
    longest = run = 0
    for c in text:
        run = run + 1 if c == character else 0
        longest = max(longest, run)
    return longest


def _summary(value: Any) -> str:
    """A field's value in one cell: a short array or a number as text, a long array by its
    shape and dtype."""
    if isinstance(value, np.ndarray):
        if value.size <= 8 and value.dtype.kind in "biufc":
            return "[" + ", ".join(_summary(v) for v in value.ravel().tolist()) + "]"
        return f"{value.dtype.name} array of shape {value.shape}"
    if isinstance(value, (bool, np.bool_)) or value is None:
        return str(value)
    if isinstance(value, (float, np.floating)):
        return format_number(float(value), 6)
    if isinstance(value, (complex, np.complexfloating)):
        return format_complex(complex(value), 6)
    if isinstance(value, (tuple, list)) and len(value) > 8:
        return f"{len(value)} items"
    return str(value)


def default_tables(result: Any) -> list[Tabular]:
    """A result without a table of its own: its text (when it has a ``str`` of its own), else
    one row per field."""
    name = type(result).__name__
    if getattr(type(result), "__str__", None) is not object.__str__:
        return [Tabular(name, (), (), text=str(result))]
    rows = [(field, _summary(getattr(result, field))) for field in field_names(result)]
    return [Tabular(name, ("field", "value"), rows)]


def png_data_uri(png: bytes) -> str:
    """``data:image/png;base64,...`` for embedding a PNG in HTML or Markdown."""
    return "data:image/png;base64," + base64.b64encode(png).decode("ascii")


def tables_html(tables: Sequence[Tabular], png: bytes | None = None) -> str:
    """The tables (and a PNG) as one HTML fragment for a notebook."""
    escape = html.escape
    parts = ['<div class="aerocontrol-result">']
    for table in tables:
        if table.title:
            parts.append(f"<p><strong>{escape(table.title)}</strong></p>")
        if table.text:
            parts.append(f"<pre>{escape(table.text)}</pre>")
        else:
            parts.append(html_table(table.header, table.rows))
        parts += [f"<p>{escape(note)}</p>" for note in table.notes]
    if png is not None:
        parts.append(f'<img alt="plot" src="{png_data_uri(png)}">')
    parts.append("</div>")
    return "\n".join(parts)


def tables_markdown(tables: Sequence[Tabular], png: bytes | None = None) -> str:
    """The tables (and a PNG) as Markdown for a notebook."""
    parts: list[str] = []
    for table in tables:
        if table.title:
            parts.append(f"**{table.title}**")
        if table.text:
            fence = "`" * max(3, _longest_run(table.text, "`") + 1)
            parts.append(f"{fence}\n{table.text}\n{fence}")
        else:
            parts.append(markdown_table(table.header, table.rows))
        parts += list(table.notes)
    if png is not None:
        parts.append(f"![plot]({png_data_uri(png)})")
    return "\n\n".join(parts)


# ----- equality -------------------------------------------------------------------------------


def field_names(value: object) -> tuple[str, ...]:
    """The fields that make up a result's or a record's value (those that take part in ``==``)."""
    names = _FIELDS.get(type(value))
    if names is not None:
        return names
    return tuple(f.name for f in dataclasses.fields(value) if f.compare)  # type: ignore[arg-type]


def _all_fields_of(cls: type) -> tuple[str, ...]:
    """Every field a result holds (also those left out of ``==``), for the JSON form."""
    names = _FIELDS.get(cls)
    if names is not None:
        return names
    return tuple(f.name for f in dataclasses.fields(cls))


def _is_record(value: object) -> bool:
    return type(value) in _FIELDS or (
        dataclasses.is_dataclass(value) and not isinstance(value, type)
    )


def same(a: object, b: object) -> bool:
    """Whether two field values are equal: arrays by shape, dtype kind and value (NaN equal to
    NaN), floats and complex numbers with NaN equal to NaN, sequences, dicts and records
    element by element."""
    if a is b:
        return True
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        if not (isinstance(a, np.ndarray) and isinstance(b, np.ndarray)):
            return False
        if a.shape != b.shape or a.dtype.kind != b.dtype.kind:
            return False
        if a.dtype.kind in "fc":
            return bool(np.array_equal(a, b, equal_nan=True))
        if a.dtype.kind == "O":
            return all(same(x, y) for x, y in zip(a.ravel(), b.ravel(), strict=True))
        return bool(np.array_equal(a, b))
    if isinstance(a, (float, complex, np.inexact)) and isinstance(b, (float, complex, np.inexact)):
        x, y = complex(a), complex(b)
        return (x.real == y.real or (math.isnan(x.real) and math.isnan(y.real))) and (
            x.imag == y.imag or (math.isnan(x.imag) and math.isnan(y.imag))
        )
    if isinstance(a, (tuple, list)) and isinstance(b, (tuple, list)):
        return (
            type(a) is type(b)
            and len(a) == len(b)
            and all(same(x, y) for x, y in zip(a, b, strict=True))
        )
    if isinstance(a, Mapping) and isinstance(b, Mapping):
        return a.keys() == b.keys() and all(same(a[key], b[key]) for key in a)
    if _is_record(a) and _is_record(b):
        return type(a) is type(b) and all(
            same(getattr(a, name), getattr(b, name)) for name in field_names(a)
        )
    return bool(a == b)


# ----- the JSON form --------------------------------------------------------------------------


def _encode_float(value: float) -> float | str:
    if math.isfinite(value):
        return float(value)
    return "NaN" if math.isnan(value) else ("Infinity" if value > 0 else "-Infinity")


def _encode_scalar(value: Any) -> Any:
    """An array element."""
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (complex, np.complexfloating)):
        return {"re": _encode_float(float(value.real)), "im": _encode_float(float(value.imag))}
    return _encode_float(float(value))


def encode(value: Any) -> Any:
    """``value`` in the JSON form (see :meth:`Result.to_dict`)."""
    if value is None or isinstance(value, (bool, np.bool_)):
        return None if value is None else bool(value)
    if isinstance(value, str):
        return {"str": value} if value in _NON_FINITE else value
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        return _encode_float(float(value))
    if isinstance(value, (complex, np.complexfloating)):
        return _encode_scalar(value)
    if isinstance(value, np.ndarray):
        if value.dtype.kind not in "biufc":
            raise InvalidArgumentError(f"an array of dtype {value.dtype} has no JSON form")
        return {
            "ndarray": [_encode_scalar(v) for v in value.ravel().tolist()],
            "dtype": value.dtype.name,
            "shape": list(value.shape),
        }
    if isinstance(value, tuple):
        return [encode(v) for v in value]
    if isinstance(value, list):
        return {"list": [encode(v) for v in value]}
    if isinstance(value, Mapping):
        if all(isinstance(key, str) for key in value):
            return {"dict": {key: encode(v) for key, v in value.items()}}
        return {"items": [[encode(key), encode(v)] for key, v in value.items()]}
    if _is_record(value) and type(value) in _NAMES:
        return {
            "type": _NAMES[type(value)],
            "fields": {name: encode(getattr(value, name)) for name in _all_fields_of(type(value))},
        }
    raise InvalidArgumentError(f"a {type(value).__name__} has no JSON form")


def _decode_float(value: Any) -> float:
    if isinstance(value, str) and value in _NON_FINITE:
        return _NON_FINITE[value]
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        return float(value)
    raise InvalidArgumentError(f"data: expected a number, got {value!r}")


def _decode_element(value: Any, kind: str) -> Any:
    if kind == "c":
        if not isinstance(value, Mapping) or set(value) != {"re", "im"}:
            raise InvalidArgumentError(f"data: expected {{'re': ..., 'im': ...}}, got {value!r}")
        return complex(_decode_float(value["re"]), _decode_float(value["im"]))
    if kind == "f":
        return _decode_float(value)
    return value


def decode(value: Any) -> Any:
    """The value whose JSON form (see :meth:`Result.to_dict`) is ``value``."""
    if value is None or isinstance(value, (bool, int, float)):
        return value
    if isinstance(value, str):
        return _NON_FINITE.get(value, value)
    if isinstance(value, list):
        return tuple(decode(v) for v in value)
    if not isinstance(value, Mapping):
        raise InvalidArgumentError(f"data: {type(value).__name__} is not part of the JSON form")
    keys = set(value)
    if keys == {"str"}:
        return str(value["str"])
    if keys == {"re", "im"}:
        return _decode_element(value, "c")
    if keys == {"ndarray", "dtype", "shape"}:
        dtype = np.dtype(value["dtype"])
        if dtype.kind not in "biufc":
            raise InvalidArgumentError(f"data: an array of dtype {dtype} has no JSON form")
        elements = [_decode_element(v, dtype.kind) for v in value["ndarray"]]
        return np.array(elements, dtype=dtype).reshape(tuple(value["shape"]))
    if keys == {"list"}:
        return [decode(v) for v in value["list"]]
    if keys == {"dict"}:
        return {key: decode(v) for key, v in value["dict"].items()}
    if keys == {"items"}:
        return {decode(key): decode(v) for key, v in value["items"]}
    if keys == {"type", "fields"}:
        name = value["type"]
        cls = _REGISTRY.get(name) if isinstance(name, str) else None
        if cls is None:
            raise InvalidArgumentError(f"data: {name!r} is not an aerocontrol result or record")
        return build(cls, {key: decode(v) for key, v in value["fields"].items()})
    raise InvalidArgumentError(f"data: a dict with the keys {sorted(keys)} is not a JSON form")


def build(cls: type[T], fields: Mapping[str, Any]) -> T:
    """An instance of ``cls`` holding exactly ``fields`` (its values as they were stored)."""
    expected = set(_all_fields_of(cls))
    if set(fields) != expected:
        raise InvalidArgumentError(
            f"data: a {cls.__name__} has the fields {sorted(expected)}, got {sorted(fields)}"
        )
    builder = _BUILDERS.get(cls)
    if builder is not None:
        built: T = builder(fields)
        return built
    instance = object.__new__(cls)
    for name, field_value in fields.items():
        object.__setattr__(instance, name, field_value)
    return instance


# ----- the base class -------------------------------------------------------------------------


def _from_dict(cls: type[T], data: Mapping[str, Any]) -> T:
    """The result of class ``cls`` whose JSON form is ``data`` (``Result.from_dict``)."""
    if not isinstance(data, Mapping) or set(data) != {"type", "fields"}:
        raise InvalidArgumentError(
            "data must be a dict with the keys 'type' and 'fields', as to_dict() gives"
        )
    if data["type"] != _NAMES.get(cls):
        raise InvalidArgumentError(f"data holds a {data['type']!r}, not a {cls.__name__}")
    result: T = decode(data)
    return result


class Result:
    """The base of the result classes (see the module's documentation)."""

    __slots__ = ()
    __hash__: ClassVar[None] = None  # type: ignore[assignment]

    def __eq__(self, other: object) -> bool:
        """Field by field (see the module's documentation); results of other classes differ."""
        if type(other) is not type(self):
            return NotImplemented
        return all(same(getattr(self, n), getattr(other, n)) for n in field_names(self))

    def __init_subclass__(cls, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        register(cls)

    def _tables(self) -> list[Tabular]:
        """The tables a notebook shows (the text ``table()``'s cells)."""
        return default_tables(self)

    def _png(self) -> bytes | None:
        """A small plot shown under the tables, or None."""
        return None

    def _repr_html_(self) -> str:
        """The result as HTML tables, for Jupyter."""
        return tables_html(self._tables(), self._png())

    def _repr_markdown_(self) -> str:
        """The result as Markdown tables, for Jupyter."""
        return tables_markdown(self._tables(), self._png())

    def to_dict(self) -> dict[str, Any]:
        """The result as plain Python types for JSON.

        ``json.dumps(result.to_dict())`` is strict JSON (no NaN or Infinity tokens), and
        ``type(result).from_dict`` reads it back to an equal result.

        Returns
        -------
        dict
            ``{"type": class name, "fields": {field: value}}``, every field of the result
            (also those ``==`` leaves out, such as the run a MonteCarlo drew from).

        Raises
        ------
        InvalidArgumentError
            A field holds a value that has no JSON form.

        Notes
        -----
        Each value is written as follows:

        ======================  ==============================================================
        None, bool, int, str    themselves (a str that reads "NaN", "Infinity" or "-Infinity"
                                as ``{"str": text}``)
        float                   a number; NaN, inf and -inf as the strings "NaN",
                                "Infinity", "-Infinity"
        complex                 ``{"re": float, "im": float}``, in arrays too
        numpy array             ``{"ndarray": [...], "dtype": "float64", "shape": [n, m]}``:
                                the elements in row-major (C) order, each written as above
        tuple                   a list
        list                    ``{"list": [...]}``
        dict                    ``{"dict": {key: value}}`` with str keys, else
                                ``{"items": [[key, value], ...]}``
        a result or a record    ``{"type": "Modes", "fields": {name: value, ...}}``; records
                                are the objects results hold (a Requirement, an Aircraft,
                                a StateSpace, ...)
        ======================  ==============================================================

        Examples
        --------
        >>> import json, aerocontrol
        >>> A, _ = aerocontrol.chapter.boeing747_lateral()
        >>> m = aerocontrol.modes(A)
        >>> text = json.dumps(m.to_dict())
        >>> aerocontrol.Modes.from_dict(json.loads(text)) == m
        True
        """
        encoded: dict[str, Any] = encode(self)
        return encoded

    @classmethod
    def from_dict(cls: type[T], data: Mapping[str, Any]) -> T:
        """The result whose :meth:`to_dict` is ``data``.

        Parameters
        ----------
        data : dict
            As :meth:`to_dict` gives it (or read back from its JSON).

        Returns
        -------
        Result
            A result of this class, equal to the one ``data`` was made from.

        Raises
        ------
        InvalidArgumentError
            ``data`` is not the JSON form of a result of this class.

        Examples
        --------
        >>> import aerocontrol
        >>> m = aerocontrol.modes([[0.0, 1.0], [-2.0, -3.0]])
        >>> aerocontrol.Modes.from_dict(m.to_dict()).natural_frequency
        array([1., 2.])
        """
        return _from_dict(cls, data)


def set_at_once(cls: type[T]) -> type[T]:
    """The frozen dataclass ``cls`` with its generated ``__init__`` replaced by one that fills
    the instance's ``__dict__`` in one step, for a result built on every call of a fast
    function: the generated one sets each field through ``object.__setattr__`` (about 2.5 µs
    for eighteen fields, more than the Python around a core call). The parameters are the
    same (the fields, positional in their order or by name, none with a default), and so are
    the errors: a TypeError naming a missing, unknown or repeated field. The instances stay
    frozen (assigning a field raises ``FrozenInstanceError``)."""
    fields = dataclasses.fields(cls)  # type: ignore[arg-type]
    if any(
        f.default is not dataclasses.MISSING or f.default_factory is not dataclasses.MISSING
        for f in fields
    ):
        raise TypeError(f"set_at_once: {cls.__name__} has a field with a default")
    names = tuple(f.name for f in fields)
    known = frozenset(names)

    def __init__(self: object, *args: Any, **kwargs: Any) -> None:
        if not args and kwargs.keys() == known:  # every field by name, as results are built
            self.__dict__.update(kwargs)
            return
        if len(args) > len(names):
            raise TypeError(
                f"{cls.__name__}() takes {len(names)} fields, got {len(args)} positional ones"
            )
        values = dict(zip(names, args, strict=False))  # the first len(args) fields
        if kwargs:
            unknown = kwargs.keys() - known
            repeated = kwargs.keys() & values.keys()
            if unknown or repeated:
                raise TypeError(
                    f"{cls.__name__}() got unknown fields {sorted(unknown)} or fields given "
                    f"twice {sorted(repeated)}"
                )
            values.update(kwargs)
        if len(values) != len(names):
            missing = [n for n in names if n not in values]
            raise TypeError(f"{cls.__name__}() is missing the fields {missing}")
        self.__dict__.update(values)

    __init__.__qualname__ = f"{cls.__qualname__}.__init__"
    __init__.__doc__ = cls.__init__.__doc__
    cls.__init__ = __init__  # type: ignore[method-assign]
    return cls


def from_fields(cls: type[T], fields: dict[str, Any]) -> T:
    """An instance of the :func:`set_at_once` dataclass ``cls`` whose ``__dict__`` is the
    dict ``fields`` itself, which must hold every field by name and nothing else (not
    checked here: each caller's tests compare its keys with the fields). For a result built
    on every call of a fast function from a dict literal: what ``cls(**fields)`` does by the
    generated ``__init__``, without packing and comparing the keyword arguments (about 1 µs
    of 2 for eighteen fields)."""
    instance = object.__new__(cls)
    object.__setattr__(instance, "__dict__", fields)
    return instance


def attach(cls: type, names: tuple[str, ...]) -> None:
    """Give a class that cannot derive from :class:`Result` (the core's Placement) the same
    equality, JSON form and notebook display; ``names`` are its fields, in the order its
    constructor takes them, and ``cls._tables`` must be set."""
    register(cls, fields=names, build=lambda fields: cls(*(fields[name] for name in names)))
    shared = ("__eq__", "__hash__", "_png", "_repr_html_", "_repr_markdown_", "to_dict")
    methods = {name: getattr(Result, name) for name in shared}
    methods["from_dict"] = classmethod(vars(Result)["from_dict"].__func__)
    for attribute, method in methods.items():
        setattr(cls, attribute, method)


def register_model(model: type) -> None:
    """Let results hold a :class:`~aerocontrol.StateSpace` (a damper's loop, an LQG design's
    compensator): compared by its matrices, names and ``dt``, rebuilt by its constructor.
    Called by the modules of those results with the class (which this module does not import,
    so that the model's own module may use any other)."""
    names = ("A", "B", "C", "D", "state_names", "input_names", "output_names", "dt")

    def build(fields: Mapping[str, Any]) -> Any:
        return model(
            *(fields[name] for name in names[:4]),
            **{name: fields[name] for name in names[4:]},
        )

    register(model, fields=names, build=build)
