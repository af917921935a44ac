"""The argument checks of every public function: one set of rules, in the CLI's words.

Whole numbers (seeds, counts, levels, action components) take Python ints and NumPy integers
(and floats that are whole, ``2.0``); they refuse bools, strings, None, floats with a
fraction and NaN or infinity. Numbers take ints and floats of Python or NumPy and refuse NaN
and infinity. Flags take True or False (Python's or NumPy's). A bad value raises
:class:`~xbandsim.errors.InvalidArgumentError`, a value of the wrong type
:class:`~xbandsim.errors.ArgumentTypeError` (also a ``TypeError``); the message names the
argument and its value and says what is allowed, with inclusive bounds, as the CLI does:

    invalid seed '3': must be a whole number 0 … 2**64 - 1, not a str
    invalid level 4: must be a whole number 0 … 3

``field`` holds the argument's name and ``problem`` the kind: ``"wrong type"``, ``"not
finite"``, ``"not a whole number"``, ``"out of range"``, ``"unknown choice"`` or
``"conflict"``.

Scene values (``Scene.from_dict``, ``Scene.with_settings``) go through :func:`scene_value`:
NumPy scalars and arrays become plain values, and NaN or infinity is refused naming the
field, as the scene loader does for a TOML file (``InvalidFieldError``).
"""

from __future__ import annotations

import math
import os
from typing import Any, Callable, Mapping, Optional, Sequence, TypeVar

import numpy as np

from .errors import ArgumentTypeError, InvalidArgumentError, InvalidFieldError, SceneSyntaxError

#: The largest seed (the library's seeds are unsigned 64-bit numbers).
U64_MAX = 2**64 - 1

T = TypeVar("T")


def _float_text(x: float) -> str:
    """A float as the Rust library writes it (``NaN``, ``inf``, ``-inf``, ``0.5``)."""
    if math.isnan(x):
        return "NaN"
    if math.isinf(x):
        return "inf" if x > 0 else "-inf"
    return repr(x)


def shown(value: Any) -> str:
    """A value as error messages show it: strings quoted, NumPy scalars as plain ones."""
    if isinstance(value, np.ndarray) and value.ndim == 0:
        value = value[()]
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float):
        return _float_text(value)
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(shown(v) for v in value) + "]"
    return repr(value)


def _a_type(value: Any) -> str:
    if value is None:
        return "None"
    name = type(value).__name__
    return f"{'an' if name[:1].lower() in 'aeiou' else 'a'} {name}"


def error(
    name: str, value: Any, reason: str, problem: str, cls: type = InvalidArgumentError
) -> InvalidArgumentError:
    """The exception for argument ``name`` holding ``value``: ``invalid NAME VALUE: REASON``."""
    e = cls(f"invalid {name} {shown(value)}: {reason}")
    e.field = name
    e.problem = problem
    return e


def _range(lo: Optional[int], hi: Optional[int], what: str = "a whole number") -> str:
    def bound(b: int) -> str:
        return "2**64 - 1" if b == U64_MAX else str(b)

    if hi is None:
        return f"{what} of {bound(lo)} or more"
    return f"{what} {bound(lo)} … {bound(hi)}"


def _scalar(value: Any) -> Any:
    """A 0-d array's element; NumPy scalars stay NumPy scalars."""
    if isinstance(value, np.ndarray) and value.ndim == 0:
        return value[()]
    return value


def whole(
    name: str, value: Any, lo: int = 0, hi: Optional[int] = None, what: str = "a whole number"
) -> int:
    """``value`` as an int in ``lo … hi`` (``hi=None``: no upper bound); ``what`` names the
    kind in the message (``must be WHAT LO … HI``)."""
    allowed = _range(lo, hi, what)
    v = _scalar(value)
    if isinstance(v, (bool, np.bool_)):
        raise error(name, value, f"must be {allowed}, not a bool", "wrong type", ArgumentTypeError)
    if isinstance(v, (int, np.integer)):
        n = int(v)
    elif isinstance(v, (float, np.floating)):
        x = float(v)
        if not math.isfinite(x):
            raise error(name, value, f"must be {allowed}", "not finite")
        if not x.is_integer():
            raise error(name, value, f"must be {allowed}", "not a whole number")
        n = int(x)
    else:
        raise error(
            name, value, f"must be {allowed}, not {_a_type(v)}", "wrong type", ArgumentTypeError
        )
    if n < lo or (hi is not None and n > hi):
        raise error(name, value, f"must be {allowed}", "out of range")
    return n


def seed(name: str, value: Any) -> int:
    """A seed: a whole number 0 … 2**64 - 1."""
    return whole(name, value, 0, U64_MAX)


def number(
    name: str,
    value: Any,
    *,
    above: Optional[float] = None,
    at_least: Optional[float] = None,
) -> float:
    """``value`` as a finite float, greater than ``above`` or at least ``at_least``."""
    if above is not None:
        allowed = f"a finite number greater than {above:g}"
    elif at_least is not None:
        allowed = f"a finite number of {at_least:g} or more"
    else:
        allowed = "a finite number"
    v = _scalar(value)
    if isinstance(v, (bool, np.bool_)) or not isinstance(v, (int, float, np.integer, np.floating)):
        raise error(
            name, value, f"must be {allowed}, not {_a_type(v)}", "wrong type", ArgumentTypeError
        )
    x = float(v)
    if not math.isfinite(x):
        raise error(name, value, f"must be {allowed}", "not finite")
    if (above is not None and not x > above) or (at_least is not None and x < at_least):
        raise error(name, value, f"must be {allowed}", "out of range")
    return x


def flag(name: str, value: Any) -> bool:
    """``value`` as a bool: True or False only (1 and "yes" are not flags)."""
    v = _scalar(value)
    if isinstance(v, (bool, np.bool_)):
        return bool(v)
    raise error(
        name, value, f"must be True or False, not {_a_type(v)}", "wrong type", ArgumentTypeError
    )


def choice(name: str, value: Any, choices: Sequence[str]) -> str:
    """``value``, one of the strings ``choices``."""
    allowed = "one of " + ", ".join(repr(c) for c in choices)
    v = _scalar(value)
    if not isinstance(v, str):
        raise error(
            name, value, f"must be {allowed}, not {_a_type(v)}", "wrong type", ArgumentTypeError
        )
    if v not in choices:
        raise error(name, value, f"must be {allowed}", "unknown choice")
    return str(v)


def text(name: str, value: Any) -> str:
    """``value``, a str."""
    if not isinstance(value, str):
        raise error(
            name, value, f"must be a str, not {_a_type(value)}", "wrong type", ArgumentTypeError
        )
    return value


def path(name: str, value: Any) -> str:
    """``value`` as a path string (a str or an ``os.PathLike``)."""
    try:
        p = os.fspath(value)
    except TypeError:
        raise error(
            name,
            value,
            f"must be a path (a str or an os.PathLike), not {_a_type(value)}",
            "wrong type",
            ArgumentTypeError,
        ) from None
    if not isinstance(p, str):
        raise error(name, value, "must be a str path, not bytes", "wrong type", ArgumentTypeError)
    return p


def optional(check: Callable[..., T], name: str, value: Any, *args: Any, **kw: Any) -> Optional[T]:
    """None, or ``check(name, value, ...)``."""
    return None if value is None else check(name, value, *args, **kw)


def mapping(name: str, value: Any) -> Mapping[Any, Any]:
    """``value``, a mapping (a dict)."""
    if not isinstance(value, Mapping):
        raise error(
            name, value, f"must be a dict, not {_a_type(value)}", "wrong type", ArgumentTypeError
        )
    return value


def scene_value(value: Any, where: str, field: str) -> Any:
    """A scene value (a ``from_dict`` scene, a ``with_settings`` value) as plain Python values
    for JSON: NumPy scalars and arrays become Python ones, dicts and lists are walked. NaN or
    infinity raises ``InvalidFieldError`` naming the field, in the scene loader's words
    (``where: invalid `field` = NaN: must be a finite number``); a value with no TOML form
    (a set, an object) raises ``SceneSyntaxError``. None is passed on: the binding refuses it
    ("None has no TOML form")."""
    if isinstance(value, np.ndarray):
        value = value.tolist()
    elif isinstance(value, np.generic):
        value = value.item()
    if value is None or isinstance(value, (bool, str)):
        return value
    if isinstance(value, int):
        return int(value)
    if isinstance(value, float):
        if not math.isfinite(value):
            _not_finite(where, field, shown(value), "must be a finite number")
        return float(value)
    if isinstance(value, Mapping):
        out = {}
        for k, v in value.items():
            if isinstance(k, np.str_):
                k = str(k)
            if not isinstance(k, str):
                raise SceneSyntaxError(
                    f"{where}: `{field}`: key {k!r} is not a string (TOML keys are strings)"
                )
            out[k] = scene_value(v, where, f"{field}.{k}" if field else k)
        return out
    if isinstance(value, (list, tuple)):
        items = []
        for i, v in enumerate(value):
            if isinstance(v, (float, np.floating)) and not math.isfinite(float(v)):
                # As the scene loader says it of a vector: the field, the whole value, the
                # component.
                _not_finite(where, field, shown(list(value)), f"component {i} must be a finite number")
            items.append(scene_value(v, where, f"{field}[{i}]"))
        return items
    e = SceneSyntaxError(
        f"{where}: `{field}` = {value!r}: {_a_type(value)} has no TOML form "
        "(numbers, strings, booleans, lists and dicts have)"
    )
    e.field = field
    raise e


def _not_finite(where: str, field: str, value: str, reason: str) -> None:
    e = InvalidFieldError(f"{where}: invalid `{field}` = {value}: {reason}")
    e.field = field
    e.problem = "not finite"
    raise e
