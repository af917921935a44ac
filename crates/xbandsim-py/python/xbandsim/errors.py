"""Exceptions raised by xbandsim: one class per kind of error.

Every class derives from :class:`XbandsimError`. Field and argument errors also derive from
:class:`ValueError` (an argument of the wrong type also from :class:`TypeError`), file errors
from :class:`OSError`. Where the error is about a scene or dataset-spec field, ``field`` holds
its dotted path (``"radar.pulse_width_us"``), for a function's argument its name (``"seed"``,
``"action.gain"``), and ``problem`` its kind (``"out of range"``, ``"unknown choice"``,
``"not finite"``, ``"not a whole number"``, ``"wrong type"``, ...); both are ``None``
otherwise. The message names the scene file (and line and column where known), the field or
argument and its value.

:class:`IncompleteDatasetWarning` is a warning, not an error: ``RadarDataset`` gives it for a
dataset whose samples or index files are not all there yet.
"""

from typing import Optional


class XbandsimError(Exception):
    """Base class of every xbandsim error."""

    field: Optional[str] = None
    problem: Optional[str] = None


class SceneSyntaxError(XbandsimError, ValueError):
    """The scene is not valid TOML, a value has the wrong type or a field is unknown."""


class InvalidFieldError(XbandsimError, ValueError):
    """A field holds a value that is not allowed (negative size, NaN, unknown name...)."""


class MissingFieldError(XbandsimError, ValueError):
    """A field that an object or the radar needs is absent."""


class MeshError(XbandsimError, ValueError):
    """A mesh file could not be read or is not a usable triangle mesh."""


class EncodeError(XbandsimError):
    """Encoding an output (PNG, JSON) failed."""


class XbandsimIOError(XbandsimError, OSError):
    """Reading or writing a file failed."""


class DatasetSpecError(XbandsimError, ValueError):
    """A dataset spec is not valid; ``field`` names the entry."""


class DatasetMismatchError(XbandsimError):
    """The output folder holds a different dataset (other spec, seed or count)."""


class InvalidArgumentError(XbandsimError, ValueError):
    """An argument of a function or method is not allowed: out of range, not finite, not a
    whole number, not one of the choices, or in conflict with another (``field`` names the
    argument, ``problem`` the kind). The message says what is allowed, as the CLI does:
    ``invalid seed -1: must be a whole number of 0 or more``."""


class ArgumentTypeError(InvalidArgumentError, TypeError):
    """An argument has a type the function does not take: a str, None or bool where a whole
    number goes, ... (``problem`` is ``"wrong type"``). Also an :class:`InvalidArgumentError`,
    so one ``except`` catches every bad argument."""


class IncompleteDatasetWarning(UserWarning):
    """A dataset folder is unfinished: samples are missing or its index files are not written
    (a run stopped part-way, or shard runs not all done). Running the same generate command
    again finishes it."""


__all__ = [
    "XbandsimError",
    "SceneSyntaxError",
    "InvalidFieldError",
    "MissingFieldError",
    "MeshError",
    "EncodeError",
    "XbandsimIOError",
    "DatasetSpecError",
    "DatasetMismatchError",
    "InvalidArgumentError",
    "ArgumentTypeError",
    "IncompleteDatasetWarning",
]
